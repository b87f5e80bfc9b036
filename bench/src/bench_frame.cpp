// Knobs of the frame (K2012 §4.3-4.4): the HDR target's format, the
// log-average's stride, each tone-mapping operator on the GPU against its CPU
// double reference, and the display skips (frame_renderer.h DisplaySkips).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iterator>
#include <memory>

#include "atonlab/display/display_model.h"
#include "atonlab/stimuli/display_pipeline.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/tonemap.h"
#include "bench_common.h"

namespace atonlab::bench {

using namespace atonlab::stimuli;
using namespace atonlab::display;

namespace {

/// The scene of the frame benches: the K2012 table 6.2 scene with lights apart.
Scene frame_scene(const Bench& b) {
    return b.quick() ? k2012_scene(20, Layout::apart, 7, 320) : k2012_scene(100, Layout::apart, 7);
}

/// Codes of an HDR frame (cd/m², top row first) by the CPU double references,
/// top row first like EncodedImage (frame 0's dither).
std::vector<std::uint16_t> cpu_codes(const ImageRGBA32F& hdr, double adaptation, const OutputSettings& out) {
    std::vector<std::uint16_t> codes(static_cast<std::size_t>(hdr.width) * hdr.height * 3);
    for (int y = 0; y < hdr.height; ++y)
        for (int x = 0; x < hdr.width; ++x) {
            const float* p = hdr.pixel(x, y);
            const glm::dvec3 rel = tonemap_pixel(glm::dvec3(p[0], p[1], p[2]), adaptation, out.tonemap);
            // The GPU's pixel coordinates count rows from the bottom.
            const glm::ivec3 c = encode_pixel(out.display, rel, {x, hdr.height - 1 - y}, 0, out.encode);
            const std::size_t o = (static_cast<std::size_t>(y) * hdr.width + x) * 3;
            for (int k = 0; k < 3; ++k) codes[o + static_cast<std::size_t>(k)] = static_cast<std::uint16_t>(c[k]);
        }
    return codes;
}

struct CodeAgreement {
    int max_diff = 0;
    double identical = 0;  ///< fraction of identical code values
};
CodeAgreement compare_codes(const std::vector<std::uint16_t>& a, const std::vector<std::uint16_t>& b) {
    CodeAgreement r;
    std::size_t same = 0;
    for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
        const int d = std::abs(static_cast<int>(a[i]) - static_cast<int>(b[i]));
        r.max_diff = std::max(r.max_diff, d);
        same += d == 0 ? 1 : 0;
    }
    r.identical = a.empty() ? 1.0 : static_cast<double>(same) / static_cast<double>(a.size());
    return r;
}

}  // namespace

void bench_hdr_format(Bench& b) {
    Scene scene = frame_scene(b);
    scene.output.encode.dither = Dither::none;
    const double la = scene.adaptation_cd_m2;
    FrameRenderer renderer;
    DisplayPipeline display;
    // The reference: the RGBA32F frame through the CPU double tone mapper and encoder.
    renderer.render(scene, 0.0);
    const ImageRGBA32F ref = renderer.read_hdr();
    const double f = renderer.projection().focal_px;
    const std::vector<std::uint16_t> ref_codes = cpu_codes(ref, la, scene.output);
    Scene dark = scene;
    dark.lights.clear();
    renderer.render(dark, 0.0);
    const double e_background = frame_illuminance_lux(renderer.read_hdr(), f);
    const double e_ref = frame_illuminance_lux(ref, f) - e_background;

    struct Setting {
        HdrFormat format;
        double pre_exposure;
        const char* name;
    };
    const Setting settings[] = {Setting{HdrFormat::rgba32f, 1.0, "RGBA32F"}, Setting{HdrFormat::rgba16f, 1.0, "RGBA16F"},
                                Setting{HdrFormat::rgba16f, 0.0, "RGBA16F, pre-exposure 1/L_a"}};
    // One renderer per format (a format change reallocates the target), timed in rounds.
    std::vector<std::unique_ptr<FrameRenderer>> renderers;
    std::vector<std::function<void()>> runs;
    for (const Setting& s : settings) {
        FrameOptions o;
        o.hdr_format = s.format;
        o.pre_exposure = s.pre_exposure;
        renderers.push_back(std::make_unique<FrameRenderer>());
        renderers.back()->set_options(o);
        renderers.back()->render(scene, 0.0);  // its PSF, outside the timed runs
        runs.emplace_back([&display, &scene, r = renderers.back().get()] {
            r->render(scene, 0.0);
            display.process(r->hdr_texture(), scene.output, scene.adaptation_cd_m2, 0.0, 0, r->pre_exposure());
        });
    }
    const std::vector<Timing> times = measure_interleaved(runs, b.spec(7, true));
    for (std::size_t k = 0; k < std::size(settings); ++k) {
        const Setting& s = settings[k];
        const Timing& t = times[k];
        FrameRenderer& fr = *renderers[k];
        fr.render(scene, 0.0);
        display.process(fr.hdr_texture(), scene.output, la, 0.0, 0, fr.pre_exposure());
        const ImageRGBA32F img = fr.read_hdr();
        const CodeAgreement a = compare_codes(display.read_codes().rgb, ref_codes);
        Row r;
        r.bench = "hdr_format";
        r.setting = s.name;
        r.is_default = s.format == HdrFormat::rgba32f;
        r.time = t;
        r.error = max_code_change(img, la, ref, la, scene.output);
        r.codes = a.max_diff;
        r.energy_pct = 100.0 * ((frame_illuminance_lux(img, f) - e_background) / e_ref - 1.0);
        r.metric = "max continuous display code change vs the RGBA32F frame (CPU double tone mapping)";
        r.note = fmt::format("frame + display pass; max Δcode: the GPU's 8-bit codes vs the CPU double reference "
                             "({:.4f}% identical); {} lights",
                             100.0 * a.identical, scene.lights.size());
        b.add(r);
    }
}

void bench_adaptation_stride(Bench& b) {
    Scene scene = frame_scene(b);
    scene.output.adaptation.mode = AdaptationMode::dynamic;
    FrameRenderer renderer;
    renderer.render(scene, 0.0);
    const ImageRGBA32F hdr = renderer.read_hdr();
    // The reference: eq 4.15 over every pixel in double (Neumaier summation).
    const double exact = log_average_luminance(hdr, scene.output.adaptation.epsilon_cd_m2);
    DisplayPipeline display;
    const std::vector<int> strides = b.quick() ? std::vector<int>{1, 8} : std::vector<int>{1, 2, 4, 8, 16, 32};
    auto settings_for = [&scene](int stride) {
        OutputSettings out = scene.output;
        out.adaptation.stride = stride;
        return out;
    };
    std::vector<std::function<void()>> runs;
    for (int stride : strides)
        runs.emplace_back([&display, &renderer, &scene, out = settings_for(stride)] {
            display.reset_adaptation();
            display.process(renderer.hdr_texture(), out, scene.adaptation_cd_m2, 0.0, 0);
        });
    const std::vector<Timing> times = measure_interleaved(runs, b.spec(9, true));
    for (std::size_t k = 0; k < strides.size(); ++k) {
        const int stride = strides[k];
        const Timing& t = times[k];
        const OutputSettings out = settings_for(stride);
        display.reset_adaptation();
        display.process(renderer.hdr_texture(), out, scene.adaptation_cd_m2, 0.0, 0);
        const double got = display.adaptation_cd_m2();
        Row r;
        r.bench = "adaptation_stride";
        r.setting = fmt::format("stride {}", stride);
        r.is_default = stride == 1;
        r.time = t;
        r.error = max_code_change(hdr, got, hdr, exact, out);
        r.codes = r.error;
        r.metric = "max display code change (continuous) from the adaptation error";
        r.note = fmt::format("log-average {:.5g} vs {:.5g} cd/m² exact ({:+.3g}%); whole display pass timed", got,
                             exact, 100.0 * (got / exact - 1.0));
        b.add(r);
    }
}

void bench_tonemap(Bench& b) {
    Scene scene = frame_scene(b);
    const double la = scene.adaptation_cd_m2;
    FrameRenderer renderer;
    renderer.render(scene, 0.0);
    const ImageRGBA32F hdr = renderer.read_hdr();
    DisplayPipeline display;
    const std::vector<std::string> operators =
        b.quick() ? std::vector<std::string>{"empirical", "perceptual"} : tone_operator_names();
    for (const std::string& name : operators) {
        OutputSettings out = scene.output;
        out.tonemap.tone_operator = *tone_operator_from_name(name);
        std::vector<std::uint16_t> ref;
        const std::vector<Timing> times = measure_interleaved(
            {[&] { display.process(renderer.hdr_texture(), out, la, 0.0, 0); }, [&] { ref = cpu_codes(hdr, la, out); }},
            TimeSpec{1, b.quick() ? 1 : 5, false});
        Timing gpu = times[0];
        gpu.use_gpu = true;  // the GPU's own clock where it is trusted (measured by the wall clock here)
        const Timing& cpu = times[1];
        display.process(renderer.hdr_texture(), out, la, 0.0, 0);
        const CodeAgreement a = compare_codes(display.read_codes().rgb, ref);
        const std::string bench = "tonemap_" + name;
        Row g;
        g.bench = bench;
        g.setting = "GPU fp32";
        g.is_default = true;
        g.time = gpu;
        g.error = a.max_diff;
        g.codes = a.max_diff;
        g.metric = "max display code difference (8 bit, dithered) vs the CPU double reference";
        g.note = fmt::format("tone map + encode; {:.4f}% of codes identical", 100.0 * a.identical);
        b.add(g);
        Row c;
        c.bench = bench;
        c.setting = "CPU double (reference)";
        c.time = cpu;
        c.error = 0;
        c.codes = 0;
        c.metric = g.metric;
        c.note = "one thread";
        b.add(c);
    }
}

void bench_display_skips(Bench& b) {
    const Scene scene = b.quick() ? k2012_scene(40, Layout::apart, 11, 320) : k2012_scene(300, Layout::apart, 11);
    const double la = scene.adaptation_cd_m2;
    FrameRenderer renderer;
    renderer.render(scene, 0.0);
    const ImageRGBA32F exact = renderer.read_hdr();
    const double f = renderer.projection().focal_px;
    Scene dark = scene;
    dark.lights.clear();
    renderer.render(dark, 0.0);
    const double e_lights = frame_illuminance_lux(exact, f) - frame_illuminance_lux(renderer.read_hdr(), f);

    struct Setting {
        bool cull, crop;
        double threshold;
    };
    std::vector<Setting> settings = {{false, false, 0.25}, {true, false, 0.25}, {false, true, 0.25},
                                     {true, true, 1.0 / 16}, {true, true, 0.25}, {true, true, 1.0},
                                     {true, true, 4.0}};
    if (b.quick()) settings = {{false, false, 0.25}, {true, true, 0.25}};
    auto options_of = [](const Setting& s) {
        FrameOptions o;
        o.skips = {s.cull, s.crop, s.threshold};
        return o;
    };
    std::vector<std::function<void()>> runs;
    for (const Setting& s : settings)
        runs.emplace_back([&renderer, &scene, o = options_of(s)] {
            renderer.set_options(o);
            renderer.render(scene, 0.0);
        });
    const std::vector<Timing> times = measure_interleaved(runs, b.spec(15, true));
    for (std::size_t k = 0; k < settings.size(); ++k) {
        const Setting& s = settings[k];
        const Timing& t = times[k];
        renderer.set_options(options_of(s));
        renderer.render(scene, 0.0);
        const ImageRGBA32F img = renderer.read_hdr();
        const FrameStats stats = renderer.stats();
        double cropped_area = 0, full_area = 0;
        const double full = renderer.glare().kernel(0)->half() + 2.0;
        for (const auto& d : renderer.read_light_draws())
            if (d.area_px2 > 0) {
                const double e = d.crop_half_extent_px > 0 ? std::min(d.crop_half_extent_px, full) : full;
                cropped_area += 4 * e * e;
                full_area += 4 * full * full;
            }
        Row r;
        r.bench = "display_skips";
        if (!s.cull && !s.crop)
            r.setting = "off (exact)";
        else
            r.setting = fmt::format("{}{} {:g} code", s.cull ? "cull" : "", s.cull && s.crop ? "+crop" : s.crop ? "crop" : "",
                                    s.threshold);
        r.is_default = s.cull && s.crop && s.threshold == 0.25;
        r.time = t;
        r.error = max_code_change(img, la, exact, la, scene.output);
        r.codes = r.error;
        r.energy_pct = 100.0 * (frame_illuminance_lux(img, f) - frame_illuminance_lux(exact, f)) / e_lights;
        r.metric = "max display code change (continuous, before dither) vs the exact frame";
        r.note = fmt::format("{} of {} lights drawn; billboard area {:.0f}% of uncropped", stats.drawn, stats.lights,
                             full_area > 0 ? 100.0 * cropped_area / full_area : 100.0);
        b.add(r);
    }
}

}  // namespace atonlab::bench
