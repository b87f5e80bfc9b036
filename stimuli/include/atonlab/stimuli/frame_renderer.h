#pragma once
// One HDR frame of a scene (docs/architecture.md "The pipeline, one frame", steps 1-3): the background, the
// discs (scene.h Disc, over the background, never glared), and
// each light's direct image or glare, into an RGBA32F target in absolute units
// (pixel Y = cd/m², linear Rec.709, D65; FrameOptions can make it RGBA16F with a
// pre-exposure) plus a linear view-depth target (metres along the view axis,
// +inf for sky) for later occlusion tests. Needs a current GL 4.5 context; a
// simulator that owns its context uses this class directly.
//
// What a frame leaves out (docs/bench.md "Skips"). Always, exactly: lights
// behind the eye or whose footprint and glare cannot reach the image, lights
// hidden by the scene's depth at their centre (K2012 §5.3.2), lights dark in
// their sector or rhythm (E = 0). With FrameOptions::skips (on in Pipeline, off
// here by default so that HDR/EXR output stays exact): lights too dim to move
// any displayed code by threshold_codes, and billboard tails below it.
#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "atonlab/stimuli/gl/objects.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/scene.h"
#include "atonlab/stimuli/veiling_glare.h"

namespace atonlab::stimuli {

class GlareStage;

/// The pinhole camera a scene implies: image size from the display, focal
/// length from the field of view (the display's visual angle unless the camera
/// names one).
struct CameraProjection {
    int width_px = 0, height_px = 0;
    double focal_px = 0;          ///< f = (h/2) / tan(fov_y/2)
    glm::dmat3 world_from_view{1.0};
    glm::dvec3 eye_position_m{0.0};

    static CameraProjection from_scene(const Scene& scene);
    double degrees_per_pixel_at_centre() const;  ///< 180/π / f
    glm::dvec3 view_from_world(glm::dvec3 world_direction) const { return glm::transpose(world_from_view) * world_direction; }
};

/// What the GPU decided for one light in the last frame (read back for tests and stats).
struct LightDrawRecord {
    glm::dvec2 centre_px{0};            ///< projected centre, window coordinates (origin lower-left)
    double view_depth_m = 0;
    double area_px2 = 0;                ///< 0 when not drawn (culled, hidden, dark or behind)
    glm::dvec3 illuminance_rgb_lux{0};  ///< at the eye
    double distance_m = 0;
    double vertical = 0, horizontal = 0, rhythm = 0, transmittance = 0;
    /// Half-extent (px) of the glare billboard after the display crop; 0 when uncropped.
    double crop_half_extent_px = 0;
    /// The illuminance (lux, Y) below which this light could not change a displayed
    /// code (DisplaySkips); 0 when the skips were off.
    double invisible_lux = 0;
};

struct FrameStats {
    int lights = 0;
    int drawn = 0;
};

/// Work left out because the display cannot show it (docs/bench.md "Skips").
/// Used only where the adaptation is fixed (scene.output.adaptation.mode ==
/// fixed) and the frame is not the LDR glare path: the bound needs the tone
/// mapper's adaptation before the frame is drawn.
struct DisplaySkips {
    /// A light whose brightest pixel (kernel peak × E / smallest pixel solid
    /// angle, or E / (max(A,1) Ω) without glare) stays below the bound emits nothing.
    bool cull_invisible_lights = false;
    /// A glare billboard is cropped to the square beyond which every texel of
    /// its kernel (any channel, any area layer) stays below the bound.
    bool crop_billboards = false;
    /// The bound, in display code values before dither: a skipped light, or a
    /// cropped tail, would have moved no channel of any pixel's code by more
    /// than this (display_threshold.h, on the darkest background of the frame).
    /// Per light: n skipped lights on one pixel add at most n times this.
    double threshold_codes = 0.25;
};

/// Storage of the HDR target.
enum class HdrFormat : std::uint8_t {
    rgba32f,  ///< fp32: exact enough for every test (the default)
    rgba16f,  ///< half floats: 11-bit mantissa, largest value 65504 (use a pre-exposure)
};

struct FrameOptions {
    HdrFormat hdr_format = HdrFormat::rgba32f;
    /// The HDR target stores luminance × pre_exposure (pre-exposure as in
    /// Frostbite/UE4: brings the adaptation level near 1 for half floats). 0:
    /// 1 / the eye's adaptation luminance, Scene::adaptation_cd_m2 (cd/m²; in
    /// either adaptation mode). read_hdr() divides it out;
    /// DisplayPipeline::process() takes it as its pre_exposure.
    double pre_exposure = 1.0;
    DisplaySkips skips;
    /// Time the stages with GL timer queries (timings()); off: no queries issued.
    bool gpu_timing = false;
};

/// Times of the last frame (ms): GPU from GL_TIME_ELAPSED queries (0 when
/// FrameOptions::gpu_timing is off), CPU from a steady clock.
struct FrameTimings {
    double background_gpu_ms = 0;
    double light_eval_gpu_ms = 0;
    double lights_draw_gpu_ms = 0;  ///< direct images or glare billboards (both passes with ldr_glare)
    double glare_prepare_cpu_ms = 0;  ///< kernels, layers, crop tables (PSF rebuilds included)
    double veil_cpu_ms = 0;           ///< the `cie` model's frame convolution (0 for other models)
    double total_cpu_ms = 0;          ///< render() from entry to return (GPU work may still run)
    double gpu_ms() const { return background_gpu_ms + light_eval_gpu_ms + lights_draw_gpu_ms; }
};

/// Where a frame of a scene runs its glare arithmetic (placement.h), resolved
/// for the current GL context: what FrameRenderer::render does, and what a
/// trial records.
struct FramePlacements {
    std::optional<ComputePlacement> veil;     ///< the `cie` veil's convolution; nullopt: no `cie` light
    std::optional<ComputePlacement> psf_fft;  ///< the PSF models' FFTs (cpu if any runs there); nullopt: none
};
/// Throws InputError (key "placement") where `placement = "gpu"` is asked for
/// and this GPU's workgroups cannot hold the veil's transforms of a
/// width × height frame (GpuVeilingGlare::unsupported_reason); automatic takes
/// the CPU there.
FramePlacements frame_placements(const Scene& scene, int width, int height);
std::string_view placement_name(const std::optional<ComputePlacement>& p);  ///< "none" for nullopt

class FrameRenderer {
public:
    FrameRenderer();
    ~FrameRenderer();
    FrameRenderer(const FrameRenderer&) = delete;
    FrameRenderer& operator=(const FrameRenderer&) = delete;

    /// Renders the scene at time_s (seconds; drives rhythms). Resizes targets to the display.
    void render(const Scene& scene, double time_s);

    void set_options(const FrameOptions& options);
    const FrameOptions& options() const;
    /// The factor the last frame's HDR target was stored with (see FrameOptions).
    double pre_exposure() const;
    /// Stage times of the last frame; waits for the GPU's timer queries.
    FrameTimings timings() const;

    const CameraProjection& projection() const { return projection_; }
    /// The HDR frame in cd/m² (the pre-exposure divided out), row 0 at the top.
    ImageRGBA32F read_hdr() const;
    /// Linear view depth (m), row 0 at the top.
    std::vector<float> read_view_depth() const;
    std::vector<LightDrawRecord> read_light_draws() const;
    FrameStats stats() const;

    /// The glare stage of the last frame: kernels, layers, what it reported.
    const GlareStage& glare() const;
    /// The `cie` model's last frame (applied = false for every other model).
    const VeilReport& veil_report() const;
    const gl::Texture2D& hdr_texture() const;
    /// With scene.output.ldr_glare and a glare model: the glare alone (the
    /// billboards, or the `cie` veil; cd/m²), while hdr_texture() holds the scene
    /// with direct images; else nullptr.
    const gl::Texture2D* glare_texture() const;
    const gl::Texture2D& view_depth_texture() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    CameraProjection projection_;
};

/// GPU light records: the packed std430 layout of shaders/light_model.glsl,
/// exposed so tests and benchmarks can drive the shader light model directly.
struct GpuLightTables {
    std::vector<float> lights;  ///< 24 floats (6 vec4) per light; integer fields bit-cast
                                ///< (float 21: the light's invisible illuminance, lux; 0 = never culled;
                                ///< float 22: light_s_p_ratio)
    std::vector<float> profile_values;
    std::vector<glm::vec2> rhythm_knots;
};
/// S/P of a light's spectrum (Light::spd; D65 when empty): the scotopic luminance, in scotopic cd/m², its
/// light carries per photopic cd/m² (display::scotopic_to_photopic_ratio). The frame's scotopic channel
/// (the HDR target's alpha) holds S/P × the luminance each light adds, plus sky_s_p_ratio() × the sky's.
double light_s_p_ratio(const Light& light);
/// S/P of the sky's (and the uniform field's) spectrum, Environment::spd ([environment] spd; D65 when
/// empty, 2.4645); the background is drawn in that spectrum's colour, Environment::rgb_per_cd_m2.
double sky_s_p_ratio(const Environment& environment);

/// Packs lights relative to the eye (positions differenced in double before the
/// fp32 rounding, so distant lights keep their precision).
/// glare_groups: each light's glare SPD group (GlareStage::light_groups()), 0 when empty.
/// invisible_lux: each light's display-skip threshold (lux, Y), 0 when empty.
GpuLightTables pack_lights(const Scene& scene, glm::dvec3 eye_position_m, std::span<const unsigned> glare_groups = {},
                           std::span<const double> invisible_lux = {});

}  // namespace atonlab::stimuli
