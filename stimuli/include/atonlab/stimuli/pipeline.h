#pragma once
// The whole pipeline of one displayed frame, for a simulator that owns its
// window and GL context (docs/architecture.md "The pipeline, one frame"; issue: the simulator's
// pipeline, embeddable): lights → glare → adaptation → tone mapping → display
// encoding, or the LDR path (glare tone-mapped on its own and added to a
// display-referred scene). Call render() once per frame with the frame time;
// present() draws the code values into the caller's framebuffer.
//
//     atonlab::stimuli::Pipeline pipeline;         // needs a current GL 4.5 context
//     for (;;) {
//         pipeline.render(scene, t, dt);           // t: scene time (rhythms), dt: frame time (adaptation)
//         glBindFramebuffer(GL_FRAMEBUFFER, 0);
//         pipeline.present(0, 0);
//         swap_buffers();
//     }
#include <cstdint>

#include "atonlab/stimuli/display_pipeline.h"
#include "atonlab/stimuli/frame_renderer.h"

namespace atonlab::stimuli {

class Pipeline {
public:
    /// The frame renderer's display skips are on here (frame_renderer.h
    /// DisplaySkips; docs/bench.md "Skips"): this path ends in code values, so
    /// what cannot move a code by the threshold is left out.
    Pipeline();
    void set_frame_options(const FrameOptions& options) { frame_.set_options(options); }

    /// Renders the scene at time_s (s) and runs adaptation over dt_s (s since
    /// the previous frame; 0 for the first). Validates scene.output first.
    void render(const Scene& scene, double time_s, double dt_s);
    /// render() with the dither pattern of frame `frame_index`, leaving
    /// frame_index() as it is: a frame that depends only on its arguments
    /// (and, with dt_s > 0, on the adaptation state; display().reset_adaptation()
    /// clears it). The runner renders every stimulus frame this way at index 0,
    /// so a cached or resumed frame is the one an uninterrupted session showed.
    void render_at(const Scene& scene, double time_s, double dt_s, std::uint32_t frame_index);
    /// The LDR path with the simulator's own display-referred frame `ldr`
    /// (linear RGB relative to the display's white, the scene's size): only the
    /// scene's lights are drawn, as glare, tone-mapped and added.
    void render_ldr(const gl::Texture2D& ldr, const Scene& scene, double time_s);
    void present(int x, int y) const { display_.present(x, y); }

    /// The last frame's renderer (its HDR image, projection and light draws).
    const FrameRenderer& frame() const { return frame_; }
    const DisplayPipeline& display() const { return display_; }
    DisplayPipeline& display() { return display_; }
    std::uint32_t frame_index() const { return frame_index_; }

private:
    FrameRenderer frame_;
    DisplayPipeline display_;
    std::uint32_t frame_index_ = 0;
};

}  // namespace atonlab::stimuli
