// `atonlab render SCENE.toml -o OUT.exr [--png OUT.png] [--time S] [--set key=value]...`
// One frame, headless: the scene-referred EXR (cd/m²) and optionally the PNG of
// the code values the calibrated display is sent (tone mapped, encoded, dithered).
#include "render_command.h"

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "atonlab/display/colour.h"
#include "atonlab/runner/render_frame.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/gl/context.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/pipeline.h"
#include "atonlab/stimuli/scene_file.h"

namespace atonlab::runner {

void add_render_command(CLI::App& app, RenderOptions& o) {
    CLI::App* cmd = app.add_subcommand("render", "Render one frame of a scene headless to an EXR (cd/m²) and a PNG");
    cmd->add_option("scene", o.scene, "Scene file (TOML; see docs/scene-file.md)")->required();
    cmd->add_option("-o,--output", o.exr, "Output EXR: linear Rec.709, absolute cd/m²")->required();
    cmd->add_option("--png", o.png,
                    "Also write the PNG the display would show (the scene's tone mapper and display encoding)");
    cmd->add_option("--time", o.time_s, "Time in seconds at which rhythms are sampled (default 0)");
    cmd->add_option("--set", o.overrides, "Override a scene key: section.key=value (TOML value; repeatable)");
    cmd->add_flag("--half", o.half, "Write the EXR as half floats instead of 32-bit floats");
    cmd->add_option("--white-cd-m2", o.white_cd_m2,
                    "linear and clamp tone mappers: the luminance (cd/m²) shown as display white "
                    "(default: the adaptation luminance at the display's own adaptation level)");
}

namespace {

// The display's code values as the 8-bit PNG (exact for an 8-bit display;
// deeper displays are rounded to 8 bits for the preview and say so).
std::vector<float> png_values(const stimuli::EncodedImage& codes) {
    std::vector<float> v(codes.rgb.size());
    const double max_code = static_cast<double>((1 << codes.bits) - 1);
    for (std::size_t i = 0; i < v.size(); ++i)
        v[i] = static_cast<float>(std::round(codes.rgb[i] / max_code * 255.0) / 255.0);
    return v;
}

}  // namespace

int run_render(const RenderOptions& o) {
    std::vector<stimuli::SceneOverride> overrides;
    for (const auto& s : o.overrides) overrides.push_back(stimuli::SceneOverride::parse(s));
    if (!std::isfinite(o.time_s))
        throw InputError(SourceLocation::command_line("--time"), "the time must be a finite number of seconds");
    if (o.white_cd_m2 && !(*o.white_cd_m2 > 0.0 && std::isfinite(*o.white_cd_m2)))
        throw InputError(SourceLocation::command_line("--white-cd-m2"),
                         "the white luminance must be a positive number of cd/m²");
    // Validate everything before touching the GPU or the output paths.
    stimuli::Scene scene = stimuli::load_scene(o.scene, overrides);
    if (o.white_cd_m2) scene.output.tonemap.white_cd_m2 = *o.white_cd_m2;
    stimuli::validate_output_settings(scene.output, scene.adaptation_cd_m2);

    auto context = gl::create_headless_context();
    stimuli::Pipeline pipeline;
    RenderedFrame frame = render_frame(pipeline, scene, o.scene, o.time_s);
    const stimuli::ImageRGBA32F& hdr = frame.hdr;
    stimuli::ExrMetadata& meta = frame.meta;
    const std::string& glare_note = frame.glare_note;
    if (o.half) {
        // Half floats end at 65504; the core of a bright light is far above that
        // (a 250 cd, 0.1 m light is ~8000 cd/m² ... 1e9 cd/m² sub-pixel). Clamp rather
        // than write +inf, and say so: half EXRs are for viewing, not photometry.
        constexpr float half_max = 65504.0f;
        std::size_t clamped = 0;
        stimuli::ImageRGBA32F h = hdr;
        // R, G, B only: the alpha (the scotopic channel, up to 19 × Y for a blue light) is not written.
        for (std::size_t i = 0; i < h.rgba.size(); ++i)
            if (i % 4 != 3 && h.rgba[i] > half_max) {
                h.rgba[i] = half_max;
                ++clamped;
            }
        if (clamped > 0)
            std::fprintf(stderr,
                         "atonlab: warning: %zu values exceed the half-float range (65504 cd/m2) and were clamped in "
                         "%s; write a 32-bit EXR (no --half) for photometric work\n",
                         clamped, o.exr.c_str());
        stimuli::write_exr(o.exr, h, meta, stimuli::ExrPixelType::half);
    } else {
        stimuli::write_exr(o.exr, hdr, meta, stimuli::ExrPixelType::float32);
    }
    if (!o.png.empty()) {
        try {
            const stimuli::EncodedImage codes = pipeline.display().read_codes();
            if (codes.bits != 8)
                std::fprintf(stderr, "atonlab: note: the display takes %d-bit codes; %s shows them rounded to 8 bits\n",
                             codes.bits, o.png.c_str());
            stimuli::write_png_rgb8(o.png, codes.width, codes.height, png_values(codes));
        } catch (...) {
            // Both or neither: a half-written result set is worse than none.
            std::error_code ec;
            std::filesystem::remove(o.exr, ec);
            throw;
        }
    }
    const auto& st = frame.stats;
    std::printf("%s: %dx%d, %d of %d lights drawn, %.4f deg/px -> %s%s%s\n", o.scene.c_str(), hdr.width, hdr.height,
                st.drawn, st.lights, meta.degrees_per_pixel, o.exr.c_str(), o.png.empty() ? "" : ", ", o.png.c_str());
    if (auto it = meta.strings.find("spd_lights"); it != meta.strings.end())
        std::printf("  light spectra: %s\n", it->second.c_str());
    std::fputs(glare_note.c_str(), stdout);
    std::printf("  %s\n", meta.strings["tonemap"].c_str());
    return 0;
}

}  // namespace atonlab::runner
