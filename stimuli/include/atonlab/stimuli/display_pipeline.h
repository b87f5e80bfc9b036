#pragma once
// Adaptation, tone mapping and display encoding of HDR frames on the GPU
// (docs/architecture.md "The pipeline, one frame", steps 4-6; K2012 §4.4): the log-average luminance by a
// double-precision GPU reduction (eq 4.15), temporal adaptation (eq 4.16-4.17)
// driven by the real frame time, or a fixed level; tonemap.glsl; then
// display_encode.glsl to the display's code values with dithering. The state
// stays on the GPU between frames: no CPU round trip per frame. Needs a
// current GL 4.5 context.
#include <cstdint>
#include <memory>
#include <vector>

#include "atonlab/stimuli/gl/objects.h"
#include "atonlab/stimuli/output_settings.h"

namespace atonlab::stimuli {

/// Code values of one frame, row 0 at the top, RGB interleaved.
struct EncodedImage {
    int width = 0, height = 0, bits = 8;
    std::vector<std::uint16_t> rgb;
};

class DisplayPipeline {
public:
    DisplayPipeline();
    ~DisplayPipeline();
    DisplayPipeline(const DisplayPipeline&) = delete;
    DisplayPipeline& operator=(const DisplayPipeline&) = delete;

    /// hdr: RGBA32F (or RGBA16F) holding cd/m² × pre_exposure (FrameRenderer::
    /// pre_exposure()). adaptation_cd_m2: the eye's adaptation luminance
    /// (Scene::adaptation_cd_m2), the tone mapper's level when s.adaptation.mode
    /// is fixed (> 0, finite); unused when it is dynamic, where the level is the
    /// frames' log-average followed in time. dt_s: seconds since the previous
    /// frame (≥ 0; dynamic: the first frame after a reset adopts its log-average
    /// at once). frame: dither frame index. scotopic_alpha: hdr's alpha holds each pixel's scotopic
    /// luminance (scotopic cd/m² × pre_exposure; FrameRenderer's frames do), the tone mapper's rod signal;
    /// false: the scotopic luminance is derived from RGB (display::scotopic_luminance_rgb).
    void process(const gl::Texture2D& hdr, const OutputSettings& s, double adaptation_cd_m2, double dt_s,
                 std::uint32_t frame, double pre_exposure = 1.0, bool scotopic_alpha = false);
    /// The LDR integration path (K2012 §6.2.2): `ldr` is display-referred linear
    /// RGB relative to the display's white (what an LDR renderer produced) when
    /// hdr_scale = 0, or an HDR frame (cd/m²) that is shown by exposure
    /// (× hdr_scale, clipped at white); `glare` holds the glare billboards alone
    /// in cd/m², tone-mapped at adaptation_cd_m2 (Scene::adaptation_cd_m2, in
    /// either mode: there is no HDR scene to measure) and added.
    /// scotopic_alpha: as for process(), of the glare buffer.
    void process_ldr(const gl::Texture2D& ldr, const gl::Texture2D& glare, const OutputSettings& s,
                     double adaptation_cd_m2, std::uint32_t frame, double hdr_scale = 0.0, bool scotopic_alpha = false);
    /// Forget the adapted luminance (the next dynamic frame adopts its log-average).
    void reset_adaptation();

    EncodedImage read_codes() const;
    /// The adapted luminance and the last log-average (cd/m²); reads the GPU state back.
    double adaptation_cd_m2() const;
    double log_average_cd_m2() const;
    /// Draws the codes into the bound framebuffer with the lower-left corner at
    /// (x, y); exact for a unorm framebuffer of the encoder's bit depth.
    void present(int x, int y) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace atonlab::stimuli
