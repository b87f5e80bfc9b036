// The `cie` glare model on the default display (veiling_glare.h): one light on
// the optical axis, its veil L/E at the angles the frame holds against the CIE
// glare spread function it convolves with (CIE 135/1-1999, cie_glare.h), and the
// frame convolution's time.
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "atonlab/stimuli/cie_glare.h"
#include "atonlab/stimuli/veiling_glare.h"
#include "bench_common.h"

namespace atonlab::bench {

using namespace atonlab::stimuli;
using namespace atonlab::display;

void bench_cie_veil(Bench& b) {
    const DisplayGeometry d = b.quick() ? DisplayGeometry{480, 270, 0.598 / 4, 0.9} : default_display();
    const int w = d.width_px, h = d.height_px;
    const double f = d.focal_px();
    const CieObserver observer{25.0, 0.5};  // the CIE's young reference observer, brown eyes
    // One light of 1 lx on the pixel (w/2, h/2), whose centre is (0.5, 0.5) px off the axis.
    const int ci = w / 2, cj = h / 2;
    const double e_lux = 1.0;
    std::vector<float> light(static_cast<std::size_t>(w) * h * 4, 0.0f);
    const double omega0 = frame_pixel_solid_angle_sr(ci, cj, w, h, f);
    for (int c = 0; c < 3; ++c)
        light[(static_cast<std::size_t>(cj) * w + ci) * 4 + static_cast<std::size_t>(c)] =
            static_cast<float>(e_lux / omega0);
    VeilingGlare veil;
    std::vector<float> frame;
    glm::dvec3 outside{0.0};
    const auto t0 = std::chrono::steady_clock::now();
    frame = light;
    outside = veil.apply(frame, w, h, f, observer);  // builds the kernel
    const double first_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const Timing t = measure_void(
        [&] {
            frame = light;
            outside = veil.apply(frame, w, h, f, observer);
        },
        TimeSpec{0, b.quick() ? 1 : 3, false});

    const glm::dvec3 source(ci + 0.5 - 0.5 * w, cj + 0.5 - 0.5 * h, f);  // the light's direction (px)
    const double half_width_deg = std::atan(0.5 * w / f) * 180.0 / std::numbers::pi;
    for (double want_deg : {1.0, 2.0, 5.0, 10.0, 15.0, 20.0}) {
        // The pixel whose direction is nearest want_deg from the light, along +x.
        const double x = std::tan(std::atan(source.x / f) + want_deg * std::numbers::pi / 180.0) * f;
        const int i = static_cast<int>(std::lround(x + 0.5 * w - 0.5));
        if (i >= w) continue;  // beyond the frame: no row (the notes say how far it reaches)
        Row r;
        r.bench = "cie_veil";
        r.setting = fmt::format("θ = {}°", want_deg);
        r.metric = "|L/E ÷ CIE GSF − 1| at the pixel nearest θ to the right of the light (age 25, p = 0.5)";
        r.time = t;
        const glm::dvec3 pixel(i + 0.5 - 0.5 * w, source.y, f);
        const double theta =
            std::acos(glm::dot(pixel, source) / (glm::length(pixel) * glm::length(source))) * 180.0 / std::numbers::pi;
        const double l = frame[(static_cast<std::size_t>(cj) * w + i) * 4 + 1];
        const double ratio = l / e_lux / cie_gsf_veil_per_lux(theta, observer);
        r.error = std::abs(ratio - 1.0);
        r.note = fmt::format(
            "θ = {:.3f}°: L/E = {:.5g} sr⁻¹, CIE GSF {:.5g} sr⁻¹; {}×{} px frame (reaching {:.1f}° to the right), "
            "{:.1f}% of the light outside it; first frame {:.0f} ms (kernel built once per display and observer)",
            theta, l / e_lux, cie_gsf_veil_per_lux(theta, observer), w, h, half_width_deg, 100.0 * outside.g, first_ms);
        b.add(r);
    }
}

}  // namespace atonlab::bench
