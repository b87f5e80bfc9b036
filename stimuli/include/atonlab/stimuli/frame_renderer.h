#pragma once
// One HDR frame of a scene (DESIGN.md pipeline steps 1-2): the background and
// each light's direct image, into an RGBA32F target in absolute units (pixel
// Y = cd/m², linear Rec.709, D65) plus a linear view-depth target (metres along
// the view axis, +inf for sky) for later occlusion tests. Needs a current GL
// 4.5 context; a simulator that owns its context uses this class directly.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "atonlab/stimuli/gl/objects.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/scene.h"

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
};

struct FrameStats {
    int lights = 0;
    int drawn = 0;
};

class FrameRenderer {
public:
    FrameRenderer();
    ~FrameRenderer();
    FrameRenderer(const FrameRenderer&) = delete;
    FrameRenderer& operator=(const FrameRenderer&) = delete;

    /// Renders the scene at time_s (seconds; drives rhythms). Resizes targets to the display.
    void render(const Scene& scene, double time_s);

    const CameraProjection& projection() const { return projection_; }
    /// The HDR frame, row 0 at the top.
    ImageRGBA32F read_hdr() const;
    /// Linear view depth (m), row 0 at the top.
    std::vector<float> read_view_depth() const;
    std::vector<LightDrawRecord> read_light_draws() const;
    FrameStats stats() const;

    /// The glare stage of the last frame: kernels, layers, what it reported.
    const GlareStage& glare() const;
    const gl::Texture2D& hdr_texture() const;
    /// With scene.output.ldr_glare and a glare model: the glare billboards alone
    /// (cd/m²), while hdr_texture() holds the scene with direct images; else nullptr.
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
    std::vector<float> lights;           ///< 24 floats (6 vec4) per light; integer fields bit-cast
    std::vector<float> profile_values;
    std::vector<glm::vec2> rhythm_knots;
};
/// Packs lights relative to the eye (positions differenced in double before the
/// fp32 rounding, so distant lights keep their precision).
/// glare_groups: each light's glare SPD group (GlareStage::light_groups()), 0 when empty.
GpuLightTables pack_lights(const Scene& scene, glm::dvec3 eye_position_m, std::span<const unsigned> glare_groups = {});

}  // namespace atonlab::stimuli
