// `atonlab render SCENE.toml -o OUT.exr [--png OUT.png] [--time S] [--set key=value]...`
// One frame, headless: the scene-referred EXR (cd/m²) and optionally a PNG.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "atonlab/stimuli/colour.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/gl/context.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/scene_file.h"
#include "commands.h"

namespace atonlab::runner {

void add_render_command(CLI::App& app, RenderOptions& o) {
    CLI::App* cmd = app.add_subcommand("render", "Render one frame of a scene headless to an EXR (cd/m²) and a PNG");
    cmd->add_option("scene", o.scene, "Scene file (TOML; see docs/scene-file.md)")->required();
    cmd->add_option("-o,--output", o.exr, "Output EXR: linear Rec.709, absolute cd/m²")->required();
    cmd->add_option("--png", o.png, "Also write a display-encoded PNG (plain exposure + sRGB curve)");
    cmd->add_option("--time", o.time_s, "Time in seconds at which rhythms are sampled (default 0)");
    cmd->add_option("--set", o.overrides, "Override a scene key: section.key=value (TOML value; repeatable)");
    cmd->add_flag("--half", o.half, "Write the EXR as half floats instead of 32-bit floats");
    cmd->add_option("--white-cd-m2", o.white_cd_m2,
                    "PNG exposure: the luminance (cd/m²) shown as display white (default 20 × the adaptation luminance)");
}

namespace {

// Plain exposure and the sRGB curve (K2012 eq 3.13): the PNG of this command is
// a preview, not a calibrated stimulus (tone mapping and display models are
// their own stage).
std::vector<float> encode_preview(const stimuli::ImageRGBA32F& img, double white_cd_m2) {
    std::vector<float> rgb(static_cast<std::size_t>(img.width) * img.height * 3);
    const double scale = 1.0 / white_cd_m2;
    for (std::size_t i = 0, n = rgb.size() / 3; i < n; ++i)
        for (int c = 0; c < 3; ++c)
            rgb[i * 3 + c] = static_cast<float>(stimuli::srgb_encode(std::clamp(img.rgba[i * 4 + c] * scale, 0.0, 1.0)));
    return rgb;
}

}  // namespace

int run_render(const RenderOptions& o) {
    std::vector<stimuli::SceneOverride> overrides;
    for (const auto& s : o.overrides) overrides.push_back(stimuli::SceneOverride::parse(s));
    if (!std::isfinite(o.time_s)) throw InputError(SourceLocation{"--time", 0, 0, ""}, "the time must be a finite number of seconds");
    if (o.white_cd_m2 && !(*o.white_cd_m2 > 0.0 && std::isfinite(*o.white_cd_m2)))
        throw InputError(SourceLocation{"--white-cd-m2", 0, 0, ""}, "the white luminance must be a positive number of cd/m²");
    // Validate everything before touching the GPU or the output paths.
    const stimuli::Scene scene = stimuli::load_scene(o.scene, overrides);

    auto context = gl::create_headless_context();
    stimuli::FrameRenderer renderer;
    renderer.render(scene, o.time_s);
    const stimuli::ImageRGBA32F hdr = renderer.read_hdr();

    stimuli::ExrMetadata meta;
    meta.units = "cd/m2";
    meta.degrees_per_pixel = renderer.projection().degrees_per_pixel_at_centre();
    meta.adaptation_cd_m2 = scene.adaptation_cd_m2;
    const auto& cam = scene.camera;
    meta.strings["camera"] = fmt::format("position_m=[{}, {}, {}] yaw_deg={} pitch_deg={} roll_deg={} focal_px={:.3f}",
                                         cam.position_m.x, cam.position_m.y, cam.position_m.z, cam.yaw_deg,
                                         cam.pitch_deg, cam.roll_deg, renderer.projection().focal_px);
    meta.strings["scene"] = o.scene;
    meta.strings["time_s"] = fmt::format("{}", o.time_s);
    meta.strings["software"] = "atonlab " ATONLAB_VERSION;
    meta.strings["glare"] = std::string(stimuli::glare_model_name(scene.glare.model));
    std::string glare_note;
    for (const auto& g : renderer.glare().report()) {
        const std::string line = fmt::format(
            "spd={} pupil_mm={:.3f} kernel_px={} radius_deg={:.3f} window={} window_cut_rgb=[{:.4f}, {:.4f}, {:.4f}] "
            "area_layers={} area_max_radius_px={:.1f}",
            g.spd.empty() ? "d65" : g.spd, g.pupil_mm, g.kernel_size_px, g.radius_deg,
            stimuli::glare_window_name(scene.glare.window), g.window_cut.r, g.window_cut.g, g.window_cut.b,
            g.area_layers, g.area_max_radius_px);
        meta.strings[fmt::format("glare_{}", g.spd.empty() ? "d65" : g.spd)] = line;
        glare_note += fmt::format("  glare ({}): {}\n", stimuli::glare_model_name(scene.glare.model), line);
    }
    if (o.half) {
        // Half floats end at 65504; the core of a bright light is far above that
        // (a 250 cd, 0.1 m light is ~8000 cd/m² ... 1e9 cd/m² sub-pixel). Clamp rather
        // than write +inf, and say so: half EXRs are for viewing, not photometry.
        constexpr float half_max = 65504.0f;
        std::size_t clamped = 0;
        stimuli::ImageRGBA32F h = hdr;
        for (float& v : h.rgba)
            if (v > half_max) {
                v = half_max;
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
            const double white = o.white_cd_m2.value_or(20.0 * scene.adaptation_cd_m2);
            stimuli::write_png_rgb8(o.png, hdr.width, hdr.height, encode_preview(hdr, white));
        } catch (...) {
            // Both or neither: a half-written result set is worse than none.
            std::error_code ec;
            std::filesystem::remove(o.exr, ec);
            throw;
        }
    }
    const auto st = renderer.stats();
    std::printf("%s: %dx%d, %d of %d lights drawn, %.4f deg/px -> %s%s%s\n", o.scene.c_str(), hdr.width, hdr.height,
                st.drawn, st.lights, meta.degrees_per_pixel, o.exr.c_str(), o.png.empty() ? "" : ", ",
                o.png.c_str());
    std::fputs(glare_note.c_str(), stdout);
    return 0;
}

}  // namespace atonlab::runner
