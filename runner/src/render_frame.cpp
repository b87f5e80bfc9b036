// One frame with its EXR metadata (render_frame.h): moved here from
// render_command.cpp so that `atonlab render` and the Python module share it.
#include "atonlab/runner/render_frame.h"

#include <fmt/format.h>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/glare_stage.h"

namespace atonlab::runner {

RenderedFrame render_frame(stimuli::Pipeline& pipeline, const stimuli::Scene& scene, const std::string& scene_label,
                           double time_s) {
    // One frame: dynamic adaptation adopts the frame's log-average at once.
    pipeline.render(scene, time_s, 0.0);
    const stimuli::FrameRenderer& renderer = pipeline.frame();
    RenderedFrame out;
    out.hdr = renderer.read_hdr();

    stimuli::ExrMetadata& meta = out.meta;
    meta.units = "cd/m2";
    meta.degrees_per_pixel = renderer.projection().degrees_per_pixel_at_centre();
    meta.adaptation_cd_m2 = scene.adaptation_cd_m2;
    const auto& cam = scene.camera;
    meta.strings["camera"] = fmt::format("position_m=[{}, {}, {}] yaw_deg={} pitch_deg={} roll_deg={} focal_px={:.3f}",
                                         cam.position_m.x, cam.position_m.y, cam.position_m.z, cam.yaw_deg,
                                         cam.pitch_deg, cam.roll_deg, renderer.projection().focal_px);
    meta.strings["scene"] = scene_label;
    meta.strings["time_s"] = fmt::format("{}", time_s);
    meta.strings["software"] = "atonlab " ATONLAB_VERSION;
    meta.strings["glare"] = std::string(stimuli::glare_model_name(scene.glare.model));
    {
        // Lights with a glare model of their own ([[light]] glare).
        std::string own;
        for (const auto& l : scene.lights)
            if (l.glare.has_value())
                own += fmt::format("{}{}={}", own.empty() ? "" : " ", l.name,
                                   stimuli::glare_model_name(stimuli::light_glare_model(scene, l)));
        if (!own.empty()) meta.strings["glare_lights"] = own;
        // Every light's glare spectrum (docs/glare.md "The light's spectrum"): its spd, or its colour's.
        std::string spectra;
        for (const auto& l : scene.lights)
            spectra += fmt::format("{}{}={}", spectra.empty() ? "" : " ", l.name, l.spd.empty() ? "d65" : l.spd);
        if (!spectra.empty()) meta.strings["spd_lights"] = spectra;
    }
    const double adapted = pipeline.display().adaptation_cd_m2();
    meta.strings["tonemap"] = fmt::format(
        "operator={} adaptation={} adapted_cd_m2={:.6g} blueshift={} hue_preservation={} display={} peak_cd_m2={} "
        "black_cd_m2={} bits={}{}{}",
        display::tone_operator_name(scene.output.tonemap.tone_operator),
        scene.output.adaptation.mode == stimuli::AdaptationMode::dynamic ? "dynamic" : "fixed", adapted,
        scene.output.tonemap.blueshift
            ? std::string(display::blueshift_luminance_name(scene.output.tonemap.blueshift_luminance))
            : std::string("off"),
        display::hue_preservation_name(scene.output.tonemap.hue_preservation), scene.output.display.name,
        scene.output.display.peak_cd_m2, scene.output.display.black_cd_m2, scene.output.encode.bits,
        scene.output.ldr_glare ? " ldr_glare" : "",
        // Named only when not the default, so the default's metadata stays as it was.
        scene.output.tonemap.mesopic == display::MesopicModel::cie191 ? " mesopic=cie191" : "");
    std::string& glare_note = out.glare_note;
    for (const auto& g : renderer.glare().report()) {
        const std::string line = fmt::format(
            "spd={} pupil_mm={:.3f} kernel_px={} radius_deg={:.3f} window={} window_cut_rgb=[{:.4f}, {:.4f}, {:.4f}] "
            "area_layers={} area_max_radius_px={:.1f} psf_fft={}",
            g.spd.empty() ? "d65" : g.spd, g.pupil_mm, g.kernel_size_px, g.radius_deg,
            stimuli::glare_window_name(scene.glare.window), g.window_cut.r, g.window_cut.g, g.window_cut.b,
            g.area_layers, g.area_max_radius_px, g.psf_fft ? stimuli::placement_name(*g.psf_fft) : "none");
        const std::string spd = g.spd.empty() ? "d65" : g.spd;
        meta.strings[g.model == scene.glare.model
                         ? fmt::format("glare_{}", spd)
                         : fmt::format("glare_{}_{}", stimuli::glare_model_name(g.model), spd)] = line;
        glare_note += fmt::format("  glare ({}): {}\n", stimuli::glare_model_name(g.model), line);
    }
    if (const stimuli::VeilReport& v = renderer.veil_report(); v.applied) {
        // The `cie` model: what the frame-sized convolution carried beyond the frame.
        const std::string line = fmt::format(
            "cie_age_years={} cie_pigmentation={} outside_frame_rgb=[{:.4f}, {:.4f}, {:.4f}] convolution_ms={:.0f} "
            "placement={}",
            v.observer.age_years, v.observer.pigmentation, v.outside_frame.r, v.outside_frame.g, v.outside_frame.b,
            v.cpu_ms, stimuli::placement_name(v.placement));
        const std::string_view cie = stimuli::glare_model_name(stimuli::GlareModel::cie);
        meta.strings[fmt::format("glare_{}", cie)] = line;
        glare_note += fmt::format("  glare ({}): {}\n", cie, line);
    }
    out.stats = renderer.stats();
    return out;
}

}  // namespace atonlab::runner
