#include "atonlab/stimuli/pipeline.h"

#include "atonlab/stimuli/error.h"

namespace atonlab::stimuli {

Pipeline::Pipeline() {
    FrameOptions o;
    o.skips.cull_invisible_lights = true;
    o.skips.crop_billboards = true;
    frame_.set_options(o);
}

void Pipeline::render(const Scene& scene, double time_s, double dt_s) {
    render_at(scene, time_s, dt_s, frame_index_);
    ++frame_index_;
}

void Pipeline::render_at(const Scene& scene, double time_s, double dt_s, std::uint32_t frame_index) {
    validate_output_settings(scene.output, scene.adaptation_cd_m2);
    frame_.render(scene, time_s);
    const OutputSettings& out = scene.output;
    if (const gl::Texture2D* glare = frame_.glare_texture();
        glare && out.ldr_glare && (scene.glare.model != GlareModel::none || any_light_glare(scene))) {
        // The scene as an LDR renderer shows it: exposure to the linear
        // operator's white (the adaptation luminance at the display's own
        // adaptation level), clipped; the glare is tone-mapped and added.
        const double white = display::linear_white_cd_m2(scene.adaptation_cd_m2, out.tonemap);
        display_.process_ldr(frame_.hdr_texture(), *glare, out, scene.adaptation_cd_m2, frame_index,
                             1.0 / (white * frame_.pre_exposure()), true);
    } else {
        // The frame's alpha is its scotopic channel (frame_renderer.h).
        display_.process(frame_.hdr_texture(), out, scene.adaptation_cd_m2, dt_s, frame_index, frame_.pre_exposure(),
                         true);
    }
}

void Pipeline::render_ldr(const gl::Texture2D& ldr, const Scene& scene, double time_s) {
    validate_output_settings(scene.output, scene.adaptation_cd_m2);
    Scene glare_scene = scene;
    glare_scene.output.ldr_glare = true;
    if (glare_scene.glare.model == GlareModel::none && !any_light_glare(glare_scene))
        throw InputError(
            SourceLocation{"", 0, 0, "eye.glare"},
            "the LDR path adds glare to a display-referred frame; choose a glare model other than \"none\".");
    frame_.render(glare_scene, time_s);
    display_.process_ldr(ldr, *frame_.glare_texture(), scene.output, scene.adaptation_cd_m2, frame_index_, 0.0, true);
    ++frame_index_;
}

}  // namespace atonlab::stimuli
