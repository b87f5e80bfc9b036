#include "atonlab/stimuli/display_threshold.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "atonlab/display/colour.h"

namespace atonlab::stimuli {

glm::dvec3 continuous_codes(const display::DisplayModel& display, glm::dvec3 relative_rgb, int bits) {
    const double max_code = static_cast<double>((1 << std::clamp(bits, 1, 16)) - 1);
    glm::dvec3 out(0.0);
    for (int c = 0; c < 3; ++c) {
        const auto& ch = display.channels[static_cast<std::size_t>(c)];
        double d = relative_rgb[c];
        if (std::isnan(d)) d = 0.0;
        out[c] = ch.drive_for(d * ch.max_cd_m2()) * max_code;
    }
    return out;
}

double invisible_luminance_cd_m2(const OutputSettings& out, double adaptation_cd_m2, double floor_cd_m2,
                                 glm::dvec3 rgb_per_cd, double light_s_p, double background_s_p, double codes) {
    constexpr double kSmallest = 1e-12, kLargest = 1e12;
    const double y = display::luminance_of_linear_rgb(rgb_per_cd);
    if (!(y > 0) || !(codes > 0)) return 0.0;
    const glm::dvec3 colour = rgb_per_cd / y;
    const int bits = out.encode.bits;

    // Backgrounds: the floor itself, then a log grid from max(floor, 1e-7) up.
    std::vector<double> backgrounds;
    const double floor_l = std::max(0.0, floor_cd_m2);
    backgrounds.push_back(floor_l);
    const double start = std::log10(std::max(floor_l, 1e-7));
    for (double e = start; e <= 10.0; e += 1.0 / 16.0) backgrounds.push_back(std::pow(10.0, e));
    std::vector<glm::dvec3> base(backgrounds.size());
    for (std::size_t i = 0; i < backgrounds.size(); ++i)
        base[i] = continuous_codes(out.display,
                                   display::tonemap_pixel(glm::dvec3(backgrounds[i]), background_s_p * backgrounds[i],
                                                          adaptation_cd_m2, out.tonemap),
                                   bits);

    // Checks the worst background first: where the last failure happened.
    std::size_t worst = 0;
    auto moves_too_far = [&](double dy) {
        auto check = [&](std::size_t i) {
            const glm::dvec3 c = continuous_codes(
                out.display,
                display::tonemap_pixel(glm::dvec3(backgrounds[i]) + dy * colour,
                                       background_s_p * backgrounds[i] + light_s_p * dy, adaptation_cd_m2, out.tonemap),
                bits);
            const glm::dvec3 d = glm::abs(c - base[i]);
            return std::max({d.r, d.g, d.b}) > codes;
        };
        if (check(worst)) return true;
        for (std::size_t i = 0; i < backgrounds.size(); ++i)
            if (i != worst && check(i)) {
                worst = i;
                return true;
            }
        return false;
    };

    if (moves_too_far(kSmallest)) return 0.0;
    double lo = kSmallest, hi = kSmallest * 10.0;
    while (!moves_too_far(hi)) {
        lo = hi;
        hi *= 10.0;
        if (hi > kLargest) return kLargest;
    }
    while (hi / lo > 1.01) {
        const double mid = std::sqrt(lo * hi);
        (moves_too_far(mid) ? hi : lo) = mid;
    }
    return lo;
}

}  // namespace atonlab::stimuli
