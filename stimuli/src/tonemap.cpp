// Tone mapping of whole images: display::tonemap_pixel and display::log_average_luminance
// (the CPU reference, atonlab/display/tonemap.h) applied to an ImageRGBA32F.
#include "atonlab/stimuli/tonemap.h"

#include <algorithm>
#include <cstddef>

namespace atonlab::stimuli {
namespace {

std::size_t pixel_count(const ImageRGBA32F& image) {
    return static_cast<std::size_t>(std::max(image.width, 0)) * static_cast<std::size_t>(std::max(image.height, 0));
}

}  // namespace

double log_average_luminance(const ImageRGBA32F& image, double epsilon_cd_m2) {
    return display::log_average_luminance(image.rgba, pixel_count(image), epsilon_cd_m2);
}

ImageRGBA32F tonemap_image(const ImageRGBA32F& hdr, double adaptation_cd_m2, const display::ToneMapSettings& s,
                           bool scotopic_alpha) {
    display::validate_tonemap_settings(s);
    ImageRGBA32F out = hdr;
    const std::size_t n = pixel_count(hdr);
    for (std::size_t i = 0; i < n && i * 4 + 3 < out.rgba.size(); ++i) {
        float* p = &out.rgba[i * 4];
        const glm::dvec3 rgb(p[0], p[1], p[2]);
        const glm::dvec3 d = scotopic_alpha ? display::tonemap_pixel(rgb, p[3], adaptation_cd_m2, s)
                                            : display::tonemap_pixel(rgb, adaptation_cd_m2, s);
        p[0] = static_cast<float>(d.r);
        p[1] = static_cast<float>(d.g);
        p[2] = static_cast<float>(d.b);
    }
    return out;
}

}  // namespace atonlab::stimuli
