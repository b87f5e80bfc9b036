// `wave-optics`: the eye model's PSF by FFT of its pupil plane, integrated over
// the light's spectrum (K2012 §4.2, Ritschel et al. 2009; docs/glare.md). Its
// keys are the eye model's (eye_keys.cpp); the spectral paths are
// spectral_path.h (CPU) and psf_generator.h (GPU).
#include "../fft_radius.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/psf_generator.h"
#include "atonlab/stimuli/scene.h"
#include "atonlab/stimuli/spectral_path.h"
#include "eye_keys.h"

namespace atonlab::stimuli {
namespace {

/// The eye a billboard kernel is built for: the settings' at the kernel's
/// pupil, which already holds the hippus of its time (kernel_pupil_mm), so
/// hippus is applied once and the kernel does not depend on the time.
EyeModel billboard_eye(const GlareSettings& gs, double pupil_mm) {
    EyeModel eye = gs.eye;
    eye.pupil_diameter_mm = pupil_mm;
    eye.hippus.enabled = false;
    return eye;
}

/// A GPU build's pupil planes, drawn ahead on a worker thread.
struct PlanesDrawnAhead final : GlareKernelAhead {
    AnchoredPupilPlanes planes;
};

bool anchored_on_the_gpu(const GlareKernelRequest& r) {
    // No generator (a caller without GL, e.g. the unit tests): the CPU.
    return r.glare.spectral_path == SpectralPath::anchored && r.gpu &&
           resolve_placement(r.glare.placement) == ComputePlacement::gpu;
}

class WaveOptics final : public GlareModelType {
public:
    WaveOptics() : GlareModelType(GlareModel::wave_optics) {}
    std::string_view summary() const override {
        return "the eye model's PSF by FFT of its pupil plane, over the light's spectrum (K2012 §4.2)";
    }
    std::span<const GlareSetting> settings() const override { return wave_optics::settings(); }
    void read_glare_keys(const toml_reader::Document&, const toml_reader::Section& s, GlareSettings& g,
                         double pupil_mm) const override {
        wave_optics::read_keys(s, g, pupil_mm);
    }
    bool on_images() const override { return true; }
    /// The eye's pupil plane at λ0 (K2012 eq 4.9).
    double psf_degrees_per_texel(const GlareSettings& g) const override {
        return stimuli::psf_degrees_per_texel(g.eye);
    }
    double default_radius_deg(const GlareSettings& g, double dpt) const override {
        return fft_glare_radius_deg(g, dpt);
    }
    /// With the eye's hippus at time_s (eye_model.h).
    double kernel_pupil_mm(const GlareSettings& g, double pupil_mm, double time_s) const override {
        EyeModel eye = g.eye;
        eye.pupil_diameter_mm = pupil_mm;
        return pupil_diameter_mm_at(eye, time_s);
    }

    /// The anchored path (the default) as placed: the GPU generator's
    /// generate_anchored() or spectral_psf_anchored() on the CPU; the
    /// `rescaled` path's FFT as placed for a one-scale eye (a two-scale eye's
    /// parts on the CPU); the exact path on the CPU (docs/pipeline.md "Placement").
    std::optional<ComputePlacement> psf_fft_placement(const GlareSettings& g) const override {
        switch (g.spectral_path) {
            case SpectralPath::anchored:
                return resolve_placement(g.placement);
            case SpectralPath::rescaled:
                return has_two_scales(g.eye) ? ComputePlacement::cpu : resolve_placement(g.placement);
            case SpectralPath::exact:
                break;
        }
        return ComputePlacement::cpu;
    }

    GlareModelKernel billboard_kernel(const GlareKernelRequest& r) const override {
        const GlareSettings& gs = r.glare;
        const EyeModel eye = billboard_eye(gs, r.pupil_mm);
        eye.validate(gs.psf_size);
        GlareModelKernel k;
        switch (gs.spectral_path) {
            case SpectralPath::anchored:  // docs/glare.md "The spectral path", on the GPU or the CPU as placed
                if (anchored_on_the_gpu(r)) {
                    const auto* ahead = dynamic_cast<const PlanesDrawnAhead*>(r.ahead);
                    GpuPsfGenerator& gen = r.gpu(gs.psf_size);
                    gen.generate_anchored(eye, r.samples, gs.spectral_anchors, r.time_s,
                                          ahead ? &ahead->planes : nullptr);
                    k.psf = gen.read_rgb();
                } else {
                    k.psf = spectral_psf_anchored(eye, gs.psf_size, r.samples, gs.spectral_anchors, r.time_s);
                }
                break;
            case SpectralPath::exact:
                k.psf = spectral_psf_exact(eye, gs.psf_size, r.samples, r.time_s);
                break;
            case SpectralPath::rescaled: {  // K2012 eq 4.9 (on the GPU for a single-scale eye)
                GpuPsfGenerator& gen = r.gpu(gs.psf_size);
                gen.generate(eye, r.samples, r.time_s);
                k.psf = gen.read_rgb();
                break;
            }
        }
        k.radius_deg = default_glare_radius_deg(gs, k.psf->degrees_per_texel);
        k.kernel = glare_kernel_from_psf(*k.psf, r.pixels_per_degree, k.radius_deg, gs.window);
        return k;
    }

    /// On the GPU placement, the anchored path's pupil planes: the CPU's share
    /// of the build (68 ms at N = 512 on the 2-core VM), which a frame would
    /// otherwise wait for. On the CPU placement nothing: its build already
    /// keeps every core busy inside the frame, so a worker would only move the
    /// time, and the frames' CPU transforms would no longer be their own.
    GlareKernelAheadJob work_ahead(const GlareKernelRequest& r) const override {
        if (!anchored_on_the_gpu(r)) return {};
        return [eye = billboard_eye(r.glare, r.pupil_mm), n = r.glare.psf_size, samples = r.samples,
                anchors = r.glare.spectral_anchors, time_s = r.time_s] {
            auto out = std::make_shared<PlanesDrawnAhead>();
            out->planes = anchored_pupil_planes(eye, n, samples, anchors, time_s, ComputePlacement::gpu);
            return std::shared_ptr<const GlareKernelAhead>(std::move(out));
        };
    }

    /// On the CPU: `exact`, else `anchored` (`rescaled` runs on the GPU and is taken as `anchored`).
    GlareKernel image_kernel(const GlareKernelRequest& r) const override {
        const GlareSettings& glare = r.glare;
        EyeModel eye = glare.eye;
        eye.pupil_diameter_mm = r.pupil_mm;
        eye.validate(glare.psf_size);
        const RgbPsf psf = glare.spectral_path == SpectralPath::exact
                               ? spectral_psf_exact(eye, glare.psf_size, r.samples)
                               : spectral_psf_anchored(eye, glare.psf_size, r.samples, glare.spectral_anchors);
        return glare_kernel_from_psf(psf, r.pixels_per_degree, default_glare_radius_deg(glare, psf.degrees_per_texel),
                                     glare.window);
    }
};

}  // namespace

const GlareModelType& glare_model_wave_optics() {
    static const WaveOptics model;
    return model;
}

}  // namespace atonlab::stimuli
