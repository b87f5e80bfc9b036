// `aperture`: the FFT of an obstacle image in the pupil plane (Kakimoto et al.
// 2005): aperture_image's luminance is the transmittance over a plane
// aperture_width_mm wide, optionally clipped by the eye's pupil.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "atonlab/common/toml_reader.h"
#include "atonlab/display/colour.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/fft.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/psf_generator.h"
#include "atonlab/stimuli/scene.h"
#include "fft_radius.h"

namespace atonlab::stimuli {
namespace {

constexpr std::string_view kImage = "aperture_image", kWidth = "aperture_width_mm", kWithPupil = "aperture_with_pupil";

const GlareSetting kSettings[] = {
    // No default: the model is unavailable without an image (available()).
    {.key = kImage,
     .type = "string",
     .unit = "path",
     .default_text = "—",
     .doc = "`aperture`: PNG (sRGB-decoded) or EXR; transmittance = luminance, white = clear; relative to the scene "
            "file",
     .example = "\"aperture.png\""},
    {.key = kWidth,
     .type = "number",
     .unit = "mm",
     .default_text = "18",
     .doc = "`aperture`: the plane side the image spans; the PSF texel is λ0/width rad",
     .example = "12",
     .default_value = 18.0,
     .check =
         [](const GlareSettingValue& v) {
             const double w = std::get<double>(v);
             return w > 0
                        ? std::string()
                        : fmt::format("aperture_width_mm must be greater than 0, got {}.", toml_reader::number_text(w));
         }},
    {.key = kWithPupil,
     .type = "bool",
     .unit = "—",
     .default_text = "false",
     .doc = "`aperture`: also clip by the pupil disc",
     .example = "true",
     .default_value = false},
};

std::string image_of(const GlareSettings& g) {
    const auto it = g.values.find(kImage);
    return it == g.values.end() ? std::string() : std::get<std::string>(it->second);
}

// The obstacle image as a pupil-plane field at λ0: transmittance = the image's
// linear luminance, resampled bilinearly over the plane (image row 0 at the top).
ComplexImage<double> aperture_field(const GlareSettings& g, int n, double pupil_mm) {
    const std::filesystem::path path = image_of(g);
    int w = 0, h = 0;
    std::vector<double> lum;
    try {
        const auto ext = path.extension().string();
        if (ext == ".exr" || ext == ".EXR") {
            const ExrImage img = read_exr(path);
            w = img.image.width;
            h = img.image.height;
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    const float* p = img.image.pixel(x, y);
                    lum.push_back(display::luminance_of_linear_rgb({p[0], p[1], p[2]}));
                }
        } else {
            const std::vector<float> rgb = read_png_rgb(path, w, h);
            for (std::size_t i = 0; i + 2 < rgb.size(); i += 3)
                lum.push_back(
                    display::luminance_of_linear_rgb({display::srgb_decode(rgb[i]), display::srgb_decode(rgb[i + 1]),
                                                      display::srgb_decode(rgb[i + 2])}));
        }
    } catch (const InputError& e) {
        throw InputError(SourceLocation{"", 0, 0, "aperture_image"},
                         fmt::format("cannot read the aperture image: {}", e.what()));
    }
    if (w < 2 || h < 2)
        throw InputError(SourceLocation{"", 0, 0, "aperture_image"},
                         fmt::format("the aperture image {} must be at least 2×2 pixels.", path.string()));
    ComplexImage<double> field(n);
    const double texel_mm = glare_number(g, kWidth) / n;
    const bool with_pupil = glare_flag(g, kWithPupil);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            // Plane texel centre → image coordinates (the image spans the whole plane).
            const double u = (i + 0.5) / n * w - 0.5, v = (1.0 - (j + 0.5) / n) * h - 0.5;
            const int x0 = std::clamp(static_cast<int>(std::floor(u)), 0, w - 1);
            const int y0 = std::clamp(static_cast<int>(std::floor(v)), 0, h - 1);
            const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
            const double tx = std::clamp(u - x0, 0.0, 1.0), ty = std::clamp(v - y0, 0.0, 1.0);
            auto L = [&](int x, int y) { return std::clamp(lum[static_cast<std::size_t>(y) * w + x], 0.0, 1.0); };
            double t =
                (1 - ty) * ((1 - tx) * L(x0, y0) + tx * L(x1, y0)) + ty * ((1 - tx) * L(x0, y1) + tx * L(x1, y1));
            if (with_pupil) {
                const double x = (i + 0.5 - n / 2.0) * texel_mm, y = (j + 0.5 - n / 2.0) * texel_mm;
                if (std::hypot(x, y) > 0.5 * pupil_mm) t = 0;
            }
            field.at(i, j) = t;
        }
    return field;
}

class Aperture final : public GlareModelType {
public:
    Aperture() : GlareModelType(GlareModel::aperture) {}
    std::string_view summary() const override {
        return "the FFT of an obstacle image in the pupil plane (aperture_image; Kakimoto et al. 2005)";
    }
    std::span<const GlareSetting> settings() const override { return kSettings; }
    void read_glare_keys(const toml_reader::Document& doc, const toml_reader::Section& s, GlareSettings& g,
                         double pupil_mm) const override {
        GlareModelType::read_glare_keys(doc, s, g, pupil_mm);
        if (auto it = g.values.find(kImage); it != g.values.end()) {
            // Relative to the scene file, like every path in it.
            std::filesystem::path p(std::get<std::string>(it->second));
            if (p.is_relative() && !doc.file().empty()) p = std::filesystem::path(doc.file()).parent_path() / p;
            if (!std::filesystem::is_regular_file(p))
                s.fail(s.get(kImage), std::string(kImage),
                       fmt::format("the aperture image {} does not exist or is not a file.", p.string()));
            it->second = p.string();
        }
    }
    bool available(const GlareSettings& g) const override { return !image_of(g).empty(); }
    /// λ0 over the aperture's width (the FFT's angular texel, K2012 eq 4.9 at λ0).
    double psf_degrees_per_texel(const GlareSettings& g) const override {
        return kReferenceWavelengthNm * 1e-6 / glare_number(g, kWidth) * 180.0 / std::numbers::pi;
    }
    double default_radius_deg(const GlareSettings& g, double dpt) const override {
        return fft_glare_radius_deg(g, dpt);
    }

    /// One FFT of the aperture's plane, in the glare stage's PSF generator.
    std::optional<ComputePlacement> psf_fft_placement(const GlareSettings& g) const override {
        return resolve_placement(g.placement);
    }

    GlareModelKernel billboard_kernel(const GlareKernelRequest& r) const override {
        const GlareSettings& gs = r.glare;
        if (!is_power_of_two(gs.psf_size))
            throw InputError(SourceLocation{"", 0, 0, "psf_size"},
                             fmt::format("the PSF size must be a power of two, not {}.", gs.psf_size));
        GpuPsfGenerator& gen = r.gpu(gs.psf_size);
        gen.generate(aperture_field(gs, gs.psf_size, r.pupil_mm), glare_psf_degrees_per_texel(gs), r.samples);
        GlareModelKernel k;
        k.psf = gen.read_rgb();
        k.radius_deg = default_glare_radius_deg(gs, k.psf->degrees_per_texel);
        k.kernel = glare_kernel_from_psf(*k.psf, r.pixels_per_degree, k.radius_deg, gs.window);
        return k;
    }
};

}  // namespace

const GlareModelType& glare_model_aperture() {
    static const Aperture model;
    return model;
}

}  // namespace atonlab::stimuli
