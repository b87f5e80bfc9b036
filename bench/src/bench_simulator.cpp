// Issue 27 item 4: a simulator's frames (simulator_frames.h). The bench runs
// the sequence once with the default eye (wave-optics billboards) and once
// with every light through the `cie` veil, and reports per-frame time
// p50/p99/max, each stage's CPU (and, where timer queries are trusted, GPU)
// time and the work counted per frame, in bench.csv and simulator_frames.md.
#include "atonlab/bench/simulator_frames.h"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <string>

#include "atonlab/stimuli/cpu_threads.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/pipeline.h"
#include "bench_common.h"

namespace atonlab::bench {

using namespace atonlab::stimuli;

std::vector<SimulatorFrame> run_simulator_sequence(const SimulatorSequence& q, bool gpu_timing) {
    Scene scene = k2012_scene(q.lights, Layout::apart, 7, q.width_px);
    scene.output.adaptation.mode = AdaptationMode::dynamic;  // the first frame adopts its log-average
    scene.glare.model = q.glare;
    scene.glare.eye.hippus.enabled = q.hippus;
    if (q.psf_size > 0) scene.glare.psf_size = q.psf_size;
    scene.glare.placement = q.placement;

    Pipeline pipeline;
    FrameOptions options;
    options.skips.cull_invisible_lights = true;
    options.skips.crop_billboards = true;
    options.gpu_timing = gpu_timing;
    pipeline.set_frame_options(options);

    const double dt = 1.0 / q.frame_rate_hz;
    const double span = std::max(1, q.frames - 1) * dt;
    const double decades = std::log10(q.adaptation_to_cd_m2 / q.adaptation_from_cd_m2);
    std::vector<SimulatorFrame> frames;
    frames.reserve(static_cast<std::size_t>(q.frames));
    GlareBuildCounts before = pipeline.frame().glare().build_counts();
    for (int i = 0; i < q.frames; ++i) {
        const double t = i * dt;
        const double la = q.adaptation_from_cd_m2 * std::pow(10.0, decades * t / span);
        scene.environment.luminance_cd_m2 = la;
        scene.adaptation_cd_m2 = la;  // the eye's: the pupil (K2012 eq 3.15); the tone mapper measures the frame
        const std::uint64_t ffts = cpu_fft_count();
        const auto t0 = std::chrono::steady_clock::now();
        pipeline.render(scene, t, i == 0 ? 0.0 : dt);
        glFinish();
        SimulatorFrame f;
        f.wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        f.timings = pipeline.frame().timings();
        f.adaptation_cd_m2 = la;
        const auto& report = pipeline.frame().glare().report();
        for (const GlareGroupReport& g : report) f.pupil_mm = std::max(f.pupil_mm, g.pupil_mm);
        const GlareBuildCounts now = pipeline.frame().glare().build_counts();
        f.psf_builds = now.kernels - before.kernels;
        f.psf_builds_ahead = now.kernels_ahead - before.kernels_ahead;
        f.interpolations = now.interpolations - before.interpolations;
        f.layer_builds = now.layers - before.layers;
        f.cpu_ffts = cpu_fft_count() - ffts;
        before = now;
        frames.push_back(f);
    }
    return frames;
}

namespace {

template <class F>
std::vector<double> column(const std::vector<SimulatorFrame>& frames, std::size_t first, F f) {
    std::vector<double> v;
    for (std::size_t i = first; i < frames.size(); ++i) v.push_back(static_cast<double>(f(frames[i])));
    return v;
}

double mean(const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? kNaN : s / static_cast<double>(v.size());
}

std::string fmt_ms(double v) {
    return std::isnan(v) ? "–" : fmt::format("{:.1f}", v);
}

}  // namespace

void bench_simulator_frames(Bench& b) {
    SimulatorSequence q;
    if (b.quick()) {
        q.frames = 12;
        q.width_px = 320;
        q.lights = 20;
        q.psf_size = 64;
    }
    const bool gpu = gpu_timer_trusted();
    std::ostringstream md;
    md << "# simulator_frames\n\n"
       << fmt::format("{} frames at {:g} Hz, {}×{} px, {} lights of the K2012 table 6.2 scene spread over the view "
                      "(0.5–10 km, 0.01–10 000 cd), the adaptation luminance falling log-linearly from {:g} to "
                      "{:g} cd/m² (sky and pupil, K2012 eq 3.15), hippus {}, the tone mapper's adaptation dynamic, "
                      "display skips on. Frame 0 is the warm-up (first PSFs, plans, shaders); the statistics are "
                      "over the frames after it. Times in ms; counts per frame (mean / max).\n\n",
                      q.frames, q.frame_rate_hz, q.width_px, q.width_px * 9 / 16, q.lights, q.adaptation_from_cd_m2,
                      q.adaptation_to_cd_m2, q.hippus ? "on" : "off")
       << "| eye's glare | p50 | p99 | max | glare prepare CPU (median) | veil CPU (median) | GPU (median) "
          "| PSF builds | kernels interpolated | layer builds | CPU FFTs | PSF builds in all (planes drawn ahead) |\n"
       << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (GlareModel model : {GlareModel::wave_optics, GlareModel::cie}) {
        q.glare = model;
        const std::vector<SimulatorFrame> frames = run_simulator_sequence(q, gpu);
        const std::size_t first = frames.size() > 1 ? 1 : 0;
        const std::vector<double> wall = column(frames, first, [](const auto& f) { return f.wall_ms; });
        auto per_frame = [&](auto f) {
            const std::vector<double> v = column(frames, first, f);
            return fmt::format("{:.2f} / {:.0f}", mean(v), v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()));
        };
        const double prepare =
            quantile_of(column(frames, first, [](const auto& f) { return f.timings.glare_prepare_cpu_ms; }), 0.50);
        const double veil =
            quantile_of(column(frames, first, [](const auto& f) { return f.timings.veil_cpu_ms; }), 0.50);
        const double gpu_ms =
            gpu ? quantile_of(column(frames, first, [](const auto& f) { return f.timings.gpu_ms(); }), 0.50) : kNaN;
        int builds = 0, ahead = 0;
        for (const SimulatorFrame& f : frames) builds += f.psf_builds, ahead += f.psf_builds_ahead;
        const std::string name(glare_model_type(model).name());
        md << fmt::format("| `{}` | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", name,
                          fmt_ms(quantile_of(wall, 0.50)), fmt_ms(quantile_of(wall, 0.99)),
                          fmt_ms(wall.empty() ? kNaN : *std::max_element(wall.begin(), wall.end())), fmt_ms(prepare),
                          fmt_ms(veil), fmt_ms(gpu_ms), per_frame([](const auto& f) { return f.psf_builds; }),
                          per_frame([](const auto& f) { return f.interpolations; }),
                          per_frame([](const auto& f) { return f.layer_builds; }),
                          per_frame([](const auto& f) { return f.cpu_ffts; }), fmt::format("{} ({})", builds, ahead));
        Row r;
        // Two pipelines, not two settings of one knob: each its own bench row
        // (as tonemap_empirical and tonemap_perceptual), so neither is weighed
        // against the other on a Pareto front.
        r.bench = model == GlareModel::wave_optics ? "simulator_frames" : "simulator_frames_cie";
        r.setting = fmt::format("eye's glare {}", name);
        r.is_default = true;
        r.time.wall = stats_of(wall);
        // One fixed pipeline timed, no quality knob to weigh: the error column holds 0 and the metric says
        // so. The moving pupil's kernel error is the moving_pupil bench's.
        r.error = 0.0;
        r.metric = "none (0): frame times of the default pipeline (simulator_frames.md); kernel error in moving_pupil";
        r.note = fmt::format("p99 {} ms, max {} ms over {} frames; {} PSF builds in all",
                             fmt_ms(quantile_of(wall, 0.99)),
                             fmt_ms(r.time.wall.max), wall.size(), builds);
        b.add(r);
    }
    md << "\nThe 60 Hz budget is 16.7 ms per frame. On a software rasteriser (llvmpipe) the GPU column is empty: "
          "its timer queries are not trusted, and every stage runs on the CPU cores.\n";
    b.documents.emplace_back("simulator_frames.md", md.str());
}

}  // namespace atonlab::bench
