#pragma once
// The glare stage of one frame (docs/architecture.md "The pipeline, one frame", step 3; K2012 §4.2-4.3,
// §5.3): per billboard model and SPD (each light's own model, else the eye's), the glare kernel, its area layers up to
// the largest projected radius the scene needs, and the billboards that draw
// each visible light's glare in place of its direct image. Caches everything
// that did not change since the last frame. Needs a current GL 4.5 context.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "atonlab/stimuli/gl/objects.h"
#include "atonlab/stimuli/glare_kernel.h"
#include "atonlab/stimuli/psf.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli {

struct CameraProjection;

/// What the glare stage used for one SPD group in the last frame.
struct GlareGroupReport {
    GlareModel model = GlareModel::none;  ///< the group's model (the eye's, or its lights' own)
    std::string spd;               ///< the named spectrum ("d65" for lights that name none)
    double pupil_mm = 0;           ///< the pupil the PSF was computed for (wave-optics)
    double degrees_per_texel = 0;  ///< the PSF's angular texel (wave-optics, aperture)
    int kernel_size_px = 0;
    double radius_deg = 0;
    glm::dvec3 window_cut{0.0};  ///< energy fraction the window cut (then restored by renormalisation)
    int area_layers = 1;
    double area_max_radius_px = 0;
    double kernel_peak = 0;  ///< the kernel's largest texel value (any channel; fraction of the light's energy)
    /// Where its PSF's FFTs ran (gpu or cpu; the two-scale eye's and the
    /// anchored and exact spectral paths' are always the CPU's); nullopt: no
    /// PSF (gaussian-bloom, spencer, an interpolated kernel).
    std::optional<ComputePlacement> psf_fft;
};

/// How often the stage rebuilt what it caches (since it was made): the glare
/// kernel (the PSF with its spectral integration, once per SPD group and
/// pupil/eye state) and the area layers.
struct GlareBuildCounts {
    int kernels = 0;         ///< PSFs built (exact pupils and the moving pupil's grid pupils)
    /// Of `kernels`, grid pupils whose work without GL (the GPU placement's
    /// pupil planes) a worker thread did before the frame needed it.
    int kernels_ahead = 0;
    int layers = 0;
    int interpolations = 0;  ///< kernels interpolated between grid pupils (a moving pupil; no PSF built)
};

/// Default billboard radius (degrees) of a model: for the FFT models the part
/// of the PSF's half field that every wavelength covers ((N/2 - 1)·dpt·380/575),
/// 4σ for the Gaussian bloom, 6° for Spencer's PSF.
double default_glare_radius_deg(const GlareSettings& glare, double psf_degrees_per_texel);

/// The billboard radius (degrees) the stage will use for `glare`: radius_deg
/// when given, else the model's default, with the FFT models' texel known from
/// the eye model (wave-optics) or the aperture's width (aperture); 0 for
/// GlareModel::none. Needs no GL: the scene file checks it against the display.
double glare_billboard_radius_deg(const GlareSettings& glare);
/// The PSF's texel pitch (degrees) for the FFT models (wave optics: the eye's
/// pupil plane, eq 4.9 at λ0; aperture: λ0 over the aperture's width); 0 for
/// the analytic ones, which have no PSF texture.
double glare_psf_degrees_per_texel(const GlareSettings& glare);

/// Pupil diameter (mm) a scene's glare uses: the given one, or eq 3.15 from the adaptation.
double glare_pupil_mm(const Scene& scene);

/// The pupil (mm) the PSF is computed for: pupil_mm rounded to the nearest
/// multiple of tolerance_mm (GlareSettings::pupil_tolerance_mm; at least one
/// step), or pupil_mm itself when the tolerance is 0.
double cached_pupil_mm(double pupil_mm, double tolerance_mm);

/// Spencer's vision class from the adaptation luminance when not given:
/// photopic ≥ 3 cd/m², scotopic ≤ 0.001 cd/m², mesopic between (CIE 191 limits)
/// ([glare] spencer_vision, declared in glare_models/spencer.cpp).
SpencerVision spencer_vision_for(const Scene& scene);

class GlareStage {
public:
    GlareStage();
    ~GlareStage();
    GlareStage(const GlareStage&) = delete;
    GlareStage& operator=(const GlareStage&) = delete;

    /// Builds (or reuses) kernels and layers for the scene at time_s. Returns
    /// the billboard half-extent (px) the light pass must cull with.
    double prepare(const Scene& scene, const CameraProjection& projection, double time_s);
    /// Draws the billboards additively into the bound framebuffer (colour 0),
    /// each pixel's luminance times pre_exposure (frame_renderer.h FrameOptions).
    /// Expects the light SSBOs at bindings 0-3 as FrameRenderer binds them.
    void draw(int light_count, const CameraProjection& projection, double pre_exposure = 1.0);

    /// The billboard crop table of the last prepared frame, for light_eval.comp:
    /// per SPD group g, entry e < stride - 1 (at g · envelope_stride() + e) is
    /// the largest value of any channel of the kernel over the texels at
    /// Chebyshev distance ≥ e from its centre (non-increasing in e, ending in
    /// 0); entry stride - 1 is the group's area-layer step (px). Stride 0
    /// without glare.
    const gl::Buffer& envelope_buffer() const;
    unsigned envelope_stride() const;
    GlareBuildCounts build_counts() const;

    const std::vector<GlareGroupReport>& report() const;
    /// The RGB PSF of group g (wave-optics, aperture), for files and tests.
    const RgbPsf* psf(std::size_t group) const;
    const GlareKernel* kernel(std::size_t group) const;
    /// The (model, SPD) group index each light of the last prepared scene
    /// uses; 0 for a light whose model draws no billboard (`none`, `cie`).
    const std::vector<unsigned>& light_groups() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace atonlab::stimuli
