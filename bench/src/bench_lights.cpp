// Frame time against the number of lights (K2012 §6.3.2, table 6.2): visible
// lights overlapping and apart, and lights culled by the frustum, by their
// rhythm and by the display skips; least-squares slope per visible light and
// the cost of 10 000 culled lights. Each time is FrameRenderer::render with
// stimuli::Pipeline's options (display skips on): background, light
// evaluation, direct images or glare billboards, the glare stage's CPU work.
// The display pass (tone mapping and encoding) costs the same for any number
// of lights; it is timed once and added as a note.
#include <fmt/format.h>

#include <cstdio>

#include "atonlab/stimuli/display_pipeline.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/pipeline.h"
#include "bench_common.h"

namespace atonlab::bench {

using namespace atonlab::stimuli;
using namespace atonlab::display;

void bench_lights(Bench& b) {
    const std::vector<int> counts =
        b.quick() ? std::vector<int>{0, 10, 100} : std::vector<int>{0, 1, 10, 100, 1000, 10000};
    const int width = b.quick() ? 320 : 1280;
    // A series stops growing once a frame takes longer than this (llvmpipe
    // cannot draw 10 000 overlapping billboards in a sensible time).
    const double budget_ms = b.quick() ? 500.0 : 5000.0;
    struct Series {
        Layout layout;
        bool skips;
    };
    const std::vector<Series> series = {{Layout::overlapping, true}, {Layout::apart, true}, {Layout::apart, false},
                                        {Layout::behind, true},      {Layout::dark, true},  {Layout::dim, true}};
    const FrameOptions with_skips = Pipeline().frame().options();
    FrameRenderer renderer;
    for (const Series& s : series) {
        const std::string name = layout_name(s.layout) + (s.skips ? "" : " (skips off)");
        renderer.set_options(s.skips ? with_skips : FrameOptions{});
        const double t_s = s.layout == Layout::dark ? 5.0 : 0.0;  // Fl 10s is dark at 5 s
        for (int n : counts) {
            const Scene scene = k2012_scene(n, s.layout, 3, width);
            renderer.render(scene, t_s);  // builds the PSF (its own timer queries) outside the timed runs
            const Timing t = measure_void([&] { renderer.render(scene, t_s); },
                                          n >= 10000 ? TimeSpec{0, 3, true} : b.spec(3, true, b.quick() ? 0 : 1));
            ScalePoint p;
            p.series = name;
            p.lights = n;
            p.drawn = renderer.stats().drawn;
            p.time = t;
            b.add(p);
            if (t.primary().median > budget_ms && n != counts.back()) {
                b.scaling_notes.push_back(fmt::format("\"{}\" stopped after {} lights: {:.0f} ms per frame exceeds "
                                                      "the bench's budget of {:.0f} ms on this machine.",
                                                      name, n, t.primary().median, budget_ms));
                break;
            }
        }
    }
    // The display pass, the same for any number of lights.
    {
        const Scene scene = k2012_scene(0, Layout::apart, 3, width);
        renderer.render(scene, 0.0);
        DisplayPipeline display;
        const Timing t =
            measure_void([&] { display.process(renderer.hdr_texture(), scene.output, scene.adaptation_cd_m2, 0.0, 0); },
                         b.spec(3, true));
        b.scaling_notes.push_back(fmt::format(
            "Times are FrameRenderer::render (lights and glare); the display pass (tone mapping, encoding) adds "
            "{:.0f} ms (median, {}) per {}×{} frame whatever the number of lights.",
            t.primary().median, t.clock(), scene.display.width_px, scene.display.height_px));
    }
    // The numbers the issue asks for.
    auto at = [&b](const std::string& which, int n) -> const ScalePoint* {
        for (const ScalePoint& p : b.points)
            if (p.series == which && p.lights == n) return &p;
        return nullptr;
    };
    for (const Series& s : series) {
        const std::string name = layout_name(s.layout) + (s.skips ? "" : " (skips off)");
        const Fit fit = fit_line(b.points, name);
        const ScalePoint* zero = at(name, 0);
        const ScalePoint* most = nullptr;
        for (const ScalePoint& p : b.points)
            if (p.series == name && (!most || p.lights > most->lights)) most = &p;
        if (!zero || !most || most->lights == 0) continue;
        b.scaling_notes.push_back(fmt::format(
            "{}: {:.4g} ms per light (least squares over {} counts, R² = {:.3f}); {} lights cost {:.1f} ms over the "
            "empty frame ({:.1f} ms), {} drawn.",
            name, fit.slope_ms, fit.points, fit.r2, most->lights,
            most->time.primary().median - zero->time.primary().median, zero->time.primary().median, most->drawn));
    }
}

}  // namespace atonlab::bench
