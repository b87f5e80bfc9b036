#pragma once
// What a glare model is (docs/architecture.md "How to add a glare model"): its
// name (glare_model_list.h), its keys with their defaults and checks, how it
// draws a light (GlarePath), the kernel it builds for the glare stage's
// billboards and for `atonlab glare`, and a one-line summary for help texts.
// Every model conserves each light's energy: a kernel's channels each sum to 1
// (glare_kernel.h renormalises after the window), and the `cie` veil conserves
// the frame's energy less what it carries outside the frame (veiling_glare.h).
//
// The registry (glare_model_type, glare_models) is the one list every reader
// uses: the scene file's keys and `--set` checks, the glare stage, image_glare,
// `atonlab glare` and `atonlab view`.
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/stimuli/glare_kernel.h"
#include "atonlab/stimuli/placement.h"
#include "atonlab/stimuli/glare_models/glare_model_list.h"
#include "atonlab/stimuli/glare_models/glare_setting.h"
#include "atonlab/stimuli/psf.h"

namespace atonlab::toml_reader {
class Document;
class Section;
}  // namespace atonlab::toml_reader

namespace atonlab::stimuli {

struct GlareSettings;
struct Scene;
class GpuPsfGenerator;

/// How a glare model draws a light: its direct image only (`none`), a glare
/// billboard in place of the direct image (the PSF models), or its direct
/// image convolved with the whole-frame veil (`cie`). The values are
/// light_eval.comp's (the frame renderer uploads them per light).
enum class GlarePath : std::uint8_t { direct = 0, billboard = 1, veil = 2 };

/// What a model did on a worker thread ahead of the frame that needs its
/// kernel (GlareModelType::work_ahead); each model derives its own.
struct GlareKernelAhead {
    virtual ~GlareKernelAhead() = default;
};
/// That work as a job: it owns copies of all it reads and touches no GL.
using GlareKernelAheadJob = std::function<std::shared_ptr<const GlareKernelAhead>()>;

/// What a model's kernel is built for.
struct GlareKernelRequest {
    const GlareSettings& glare;      ///< the shared settings, with glare.model = this model
    const Scene& scene;              ///< its adaptation (Spencer's vision class) and eye
    const SpectralSamples& samples;  ///< the light's SPD, sampled (K2012 §4.2.4)
    double pixels_per_degree = 0;    ///< of the display (the stage) or the image (`atonlab glare`)
    double pupil_mm = 0;             ///< the pupil the kernel is for (GlareModelType::kernel_pupil_mm)
    double time_s = 0;               ///< the frame's time (the eye's time-varying parts)
    /// The glare stage's GPU PSF generator of size n; empty on the CPU (`atonlab glare`).
    std::function<GpuPsfGenerator&(int n)> gpu;
    /// work_ahead()'s result for this kernel when a worker ran it; null: none.
    const GlareKernelAhead* ahead = nullptr;
};

/// A model's kernel, with the PSF it came from (the FFT models) and its radius.
struct GlareModelKernel {
    std::optional<RgbPsf> psf;
    GlareKernel kernel;
    double radius_deg = 0;  ///< the billboard's (the window's) radius, degrees of visual angle
};

class GlareModelType {
public:
    explicit constexpr GlareModelType(GlareModel id) : id_(id) {}
    virtual ~GlareModelType() = default;
    GlareModelType(const GlareModelType&) = delete;
    GlareModelType& operator=(const GlareModelType&) = delete;

    GlareModel id() const { return id_; }
    std::string_view name() const;  ///< as glare_model_list.h spells it

    /// One line for help texts: what the model draws and its source.
    virtual std::string_view summary() const = 0;
    /// How it draws a light.
    virtual GlarePath path() const { return GlarePath::billboard; }

    /// The settings only this model reads, keys of [glare] and of [eye], each
    /// with its default, check and documentation line (glare_setting.h). The
    /// scene reader, `atonlab glare`'s options, the Python module and the
    /// glare stage's kernel cache key read these; docs/scene-file.md has a row
    /// for each, which the registry test holds to the declaration.
    virtual std::span<const GlareSetting> settings() const { return {}; }
    /// Reads its settings of [glare] into g and checks them, failing at the
    /// key's line. The default reads every declared setting stored in
    /// GlareSettings::values; a model overrides it for what a declaration
    /// cannot say (a typed home, a path relative to the file, a check of two
    /// keys together) and calls it for the rest. pupil_mm: the pupil the
    /// scene's frames use (the darkest one for dynamic adaptation).
    virtual void read_glare_keys(const toml_reader::Document& doc, const toml_reader::Section& s, GlareSettings& g,
                                 double pupil_mm) const;
    /// The same for its settings of [eye].
    virtual void read_eye_keys(const toml_reader::Section& s, GlareSettings& g) const;

    /// Whether `atonlab view`'s m key offers it with these settings (aperture needs an image).
    virtual bool available(const GlareSettings& g) const;
    /// Whether `atonlab glare` can convolve an image with it (image_kernel).
    virtual bool on_images() const { return false; }

    /// The PSF's texel pitch (degrees) of the FFT models; 0 for the analytic ones.
    virtual double psf_degrees_per_texel(const GlareSettings& g) const;
    /// Its radius (degrees) when [glare] radius_deg is not given, for a PSF of
    /// psf_degrees_per_texel (0 for the analytic models).
    virtual double default_radius_deg(const GlareSettings& g, double psf_degrees_per_texel) const;
    /// The pupil (mm) its kernel is computed for at time_s, from the frame's pupil (before the cache's rounding).
    virtual double kernel_pupil_mm(const GlareSettings& g, double pupil_mm, double time_s) const;

    /// What of the scene, beyond its declared settings, the shared ones and
    /// the pupil, its kernel depends on, as text for the glare stage's cache key (Spencer's: the
    /// vision class its adaptation implies); empty for none. A change of it
    /// rebuilds the kernel, so a model must name only what it reads.
    virtual std::string kernel_scene_key(const Scene&) const { return {}; }

    /// Where its billboard PSF's FFTs run with these settings (placement.h;
    /// automatic resolved for the current GL context); nullopt for a model
    /// without a PSF. The glare stage reports it and a trial records it.
    virtual std::optional<ComputePlacement> psf_fft_placement(const GlareSettings&) const { return std::nullopt; }

    /// The glare stage's kernel for a billboard (path() == billboard only).
    virtual GlareModelKernel billboard_kernel(const GlareKernelRequest& r) const;
    /// The part of billboard_kernel(r) that needs no GL context, as a job a
    /// worker thread runs before a frame needs the kernel (a moving pupil's
    /// next grid pupil, pupil_kernel_cache.h); billboard_kernel() then gets
    /// its result as r.ahead and must build the same kernel, bit for bit, as
    /// without it. Empty (the default): nothing worth doing ahead.
    virtual GlareKernelAheadJob work_ahead(const GlareKernelRequest&) const { return {}; }
    /// `atonlab glare`'s kernel, on the CPU (on_images() only).
    virtual GlareKernel image_kernel(const GlareKernelRequest& r) const;

private:
    GlareModel id_;
};

/// The registry: the model of an enumerator, every model in glare_model_list.h's order.
const GlareModelType& glare_model_type(GlareModel m);
std::span<const GlareModelType* const> glare_models();

std::string_view glare_model_name(GlareModel m);
std::optional<GlareModel> glare_model_from_name(std::string_view name);
/// The names of the models that pass `keep` (all when empty), each in `quote`,
/// as a list ending "… or …": for error messages and help texts.
std::string glare_model_choices(std::string_view quote = "\"",
                                const std::function<bool(const GlareModelType&)>& keep = {});

GlarePath glare_path(GlareModel m);

/// Adds a model defined outside glare_model_list.h (a test's toy model, from
/// one file): `instance` returns its one instance, built with the enumerator
/// given (the next value after the list's). Its name must be new. Call it
/// before any scene is read (a namespace-scope initialiser in the model's
/// file), since the scene reader's key lists are made once.
GlareModel register_glare_model(std::string_view name, const GlareModelType& (*instance)(GlareModel id));

/// The glare stage's kernel cache key for `model`'s kernels of the light
/// SPD `spd` in `scene` (everything a kernel depends on but the pupil): the
/// model, the shared [glare] settings, each of the model's declared settings
/// (glare_setting.h) by key and value, the display's pixels per degree and the
/// model's kernel_scene_key. A declared setting is in it without being named
/// here, so none can be forgotten.
std::string glare_kernel_key(const Scene& scene, GlareModel model, std::string_view spd);

}  // namespace atonlab::stimuli
