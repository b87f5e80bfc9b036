#include "bench_common.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/display_threshold.h"
#include "atonlab/stimuli/footprint.h"
#include "atonlab/stimuli/rhythm.h"
#include "atonlab/display/tonemap.h"

namespace atonlab::bench {

using namespace atonlab::stimuli;
using namespace atonlab::display;

void Bench::add(Row r) {
    if (options.verbose) {
        const Stats& t = r.time.primary();
        std::printf("  %-18s %-34s %10.3f ms (IQR %.3g, %s)  error %.3g%s\n", r.bench.c_str(), r.setting.c_str(),
                    t.median, t.iqr(), r.time.clock(), r.error, r.is_default ? "  [default]" : "");
        std::fflush(stdout);
    }
    rows.push_back(std::move(r));
}

void Bench::add(ScalePoint p) {
    if (options.verbose) {
        const Stats& t = p.time.primary();
        std::printf("  %-18s %-26s %6d lights, %6d drawn: %10.3f ms (IQR %.3g, %s)\n", "lights", p.series.c_str(),
                    p.lights, p.drawn, t.median, t.iqr(), p.time.clock());
        std::fflush(stdout);
    }
    points.push_back(std::move(p));
}

DisplayGeometry default_display() {
    return DisplayGeometry{};
}

std::string layout_name(Layout l) {
    switch (l) {
        case Layout::overlapping:
            return "visible, overlapping";
        case Layout::apart:
            return "visible, apart";
        case Layout::behind:
            return "culled: behind the eye";
        case Layout::dark:
            return "culled: dark in rhythm";
        case Layout::dim:
            return "culled: too dim";
    }
    return "";
}

Scene k2012_scene(int lights, Layout layout, unsigned seed, int width_px) {
    Scene s;
    const int height_px = width_px * 9 / 16;
    // 45° vertical field of view at 0.9 m (K2012 §6.2): the display subtends it.
    const double d = 0.9, height_m = 2.0 * d * std::tan(22.5 * std::numbers::pi / 180.0);
    s.display = {width_px, height_px, height_m * width_px / height_px, d};
    s.camera.position_m = {0.0, 10.0, 0.0};
    s.environment.background = Background::sky_sea;
    s.environment.luminance_cd_m2 = 0.01;
    s.adaptation_cd_m2 = 0.01;
    s.glare.model = GlareModel::wave_optics;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Rhythm flash = parse_rhythm("Fl 10s");
    const double deg = std::numbers::pi / 180.0;
    for (int i = 0; i < lights; ++i) {
        Light L;
        L.name = fmt::format("L{}", i);
        L.radius_m = 0.1;
        double bearing = 0, elevation = 0, distance = 1000, intensity = 100;
        switch (layout) {
            case Layout::overlapping:
                bearing = (u(rng) - 0.5) * 4.0;
                elevation = 0.5 + (u(rng) - 0.5) * 2.0;
                break;
            case Layout::apart:
            case Layout::dark:
            case Layout::dim:
                bearing = (u(rng) - 0.5) * 70.0;
                elevation = 0.3 + u(rng) * 15.0;
                distance = 500.0 * std::pow(20.0, u(rng));
                intensity = std::pow(10.0, -2.0 + 6.0 * u(rng));
                break;
            case Layout::behind:
                bearing = 180.0 + (u(rng) - 0.5) * 70.0;
                elevation = 0.3 + u(rng) * 15.0;
                break;
        }
        if (layout == Layout::dim) {
            distance = 5000.0;
            intensity = 1e-4;
        }
        const double b = bearing * deg, e = elevation * deg;
        L.position_m = s.camera.position_m + distance * glm::dvec3(std::sin(b) * std::cos(e), std::sin(e),
                                                                    -std::cos(b) * std::cos(e));
        L.intensity_cd = intensity;
        if (layout == Layout::dark) {
            L.rhythm = flash.channels[0].knots;
            L.rhythm_period_s = flash.period_s;
        }
        s.lights.push_back(L);
    }
    return s;
}

double frame_illuminance_lux(const ImageRGBA32F& img, double focal_px) {
    double sum = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const float* p = img.pixel(x, y);
            const double Y = luminance_of_linear_rgb(glm::dvec3(p[0], p[1], p[2]));
            if (Y == 0) continue;
            const double x0 = x - 0.5 * img.width, y0 = (img.height - 1 - y) - 0.5 * img.height;
            sum += Y * pixel_solid_angle_sr(x0, y0, focal_px);
        }
    return sum;
}

double max_code_change(const ImageRGBA32F& a, double adaptation_a, const ImageRGBA32F& b, double adaptation_b,
                       const OutputSettings& out) {
    double worst = 0;
    const bool same_adaptation = adaptation_a == adaptation_b;
    for (std::size_t i = 0; i + 3 < a.rgba.size() && i + 3 < b.rgba.size(); i += 4) {
        const glm::dvec3 pa{a.rgba[i], a.rgba[i + 1], a.rgba[i + 2]}, pb{b.rgba[i], b.rgba[i + 1], b.rgba[i + 2]};
        if (same_adaptation && pa == pb) continue;
        const glm::dvec3 ca = continuous_codes(out.display, tonemap_pixel(pa, adaptation_a, out.tonemap), out.encode.bits);
        const glm::dvec3 cb = continuous_codes(out.display, tonemap_pixel(pb, adaptation_b, out.tonemap), out.encode.bits);
        const glm::dvec3 dd = glm::abs(ca - cb);
        worst = std::max({worst, dd.r, dd.g, dd.b});
    }
    return worst;
}

}  // namespace atonlab::bench
