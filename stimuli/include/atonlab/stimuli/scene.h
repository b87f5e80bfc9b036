#pragma once
// A scene: what the renderer draws in one frame (docs/architecture.md "Units and colour").
// World frame: metres, right-handed, x east, y up, -z north. Bearings and yaw
// are clockwise from north, as on a chart.
#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/display/geometry.h"
#include "atonlab/stimuli/cie_glare.h"
#include "atonlab/stimuli/eye_model.h"
#include "atonlab/stimuli/glare_kernel.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/glare_models/glare_setting.h"
#include "atonlab/stimuli/output_settings.h"
#include "atonlab/stimuli/placement.h"
#include "atonlab/stimuli/profile.h"
#include "atonlab/stimuli/rhythm.h"

namespace atonlab::stimuli {

struct Camera {
    glm::dvec3 position_m{0.0, 3.0, 0.0};
    double yaw_deg = 0.0;             ///< heading, clockwise from north (-z)
    double pitch_deg = 0.0;           ///< up positive
    double roll_deg = 0.0;            ///< clockwise positive, looking forward
    std::optional<double> fov_y_deg;  ///< vertical field of view; default: the display's visual angle

    /// World-from-camera rotation: camera looks down its -z, +y up, +x right.
    glm::dquat orientation() const;
};

enum class Background : std::uint8_t { uniform, sky_sea };

struct Environment {
    Background background = Background::sky_sea;
    double luminance_cd_m2 = 0.001;    ///< sky (or uniform field) luminance
    double sea_reflectance_f0 = 0.02;  ///< Schlick R_F(0°) of the sea (K2012 eq 3.17, §3.6.1)
    double extinction_per_m = 0.0;     ///< Bouguer σ (K2012 eq 4.14); 0 = clear
    /// The sky's (and the uniform field's) spectrum, a named_spectrum(): its S/P gives the sky's
    /// scotopic luminance (sky_s_p_ratio, frame_renderer.h), its chromaticity the colour it is drawn in.
    std::string spd = "d65";
    /// The colour the sky is drawn in: linear Rec.709 normalised to Y = 1, of spd's chromaticity
    /// (display::normalised_rgb_from_spectrum); D65 is the display's white, (1, 1, 1) exactly.
    glm::dvec3 rgb_per_cd_m2{1.0};
};

/// A light's emission pattern shared by lights (K2012 §5.1: profiles are
/// shared through ids).
struct ProfileTables {
    std::vector<VerticalProfile> vertical{VerticalProfile::uniform()};
    std::vector<HorizontalProfile> horizontal{HorizontalProfile::uniform()};
};

/// One ATON light (K2012 §4.1): an isotropic sphere of radius radius_m shielded
/// by its profiles, modulated by its rhythm. One colour: a sectored lighthouse is
/// several lights sharing a position and a horizontal profile table.

struct Light {
    std::string name;
    glm::dvec3 position_m{0.0};
    glm::dquat orientation{1.0, 0.0, 0.0, 0.0};  ///< world-from-light
    double radius_m = 0.1;
    double intensity_cd = 100.0;                 ///< peak luminous intensity
    glm::dvec3 rgb_per_cd{1.0};                  ///< linear Rec.709, normalised to Y = 1 (K2012 table 4.1)
    int vertical_profile = 0;                    ///< index into ProfileTables::vertical
    int horizontal_profile = 0;                  ///< index into ProfileTables::horizontal
    std::vector<RhythmKnot> rhythm{{0.0, 1.0}};  ///< B(t) knots of this light's colour channel
    double rhythm_period_s = 0.0;                ///< 0 = fixed
    double rhythm_phase_s = 0.0;                 ///< added to the time before the rhythm lookup
    /// The SPD its glare is integrated with (a named_spectrum(); K2012 §4.2.4,
    /// eq 4.10). The scene file sets it for every light but an `xy` one: its `spd`,
    /// else its IALA colour's spectrum (display::iala_colour_spectrum_name). Empty
    /// (an `xy` light, or a Light built in code): its glare is D65's, and its
    /// scotopic channel the RGB weights of rgb_per_cd (light_s_p_ratio).
    std::string spd;
    /// Its own glare model ([[light]] glare); nullopt: the eye's ([eye] glare).
    /// The models' settings ([glare], the eye's PSF) are shared by all lights.
    std::optional<GlareModel> glare;
};

/// A uniform disc of luminance: the extended reference of luminance-matching
/// designs (Yoshida et al. 2008, Suzuki et al. 2019: a plain patch beside a
/// glare stimulus; docs/scene-file.md "[[disc]]"). Not a light: it replaces the
/// background within its outline, before tone mapping, and no glare model
/// touches it. Its outline is the set of directions within diameter_deg / 2 of
/// its centre's direction (a circle of visual angle, whatever the projection),
/// its edge pixels weighted by the area they cover (disc.h).
struct Disc {
    std::string name;
    glm::dvec3 position_m{0.0, 0.0, -1.0};  ///< a world point on the line of sight to its centre, metres
    double diameter_deg = 1.0;              ///< angular diameter, degrees of visual angle; 0 draws nothing
    double luminance_cd_m2 = 1.0;           ///< Y of every point inside, cd/m²
    glm::dvec3 rgb_per_cd_m2{1.0};          ///< linear Rec.709, normalised to Y = 1 (a light's colour keys)
};

/// How the wave-optics PSF integrates over the spectrum (K2012 §4.2.4; docs/glare.md "The spectral path").
enum class SpectralPath : std::uint8_t {
    anchored,  ///< exact FFTs at a few anchor wavelengths, each sample rescaled from its two neighbours (default)
    rescaled,  ///< one FFT at λ0 rescaled to every sample (K2012 eq 4.9, on the GPU)
    exact,     ///< one pupil plane and FFT per sample (the reference)
};
std::string_view spectral_path_name(SpectralPath p);
std::optional<SpectralPath> spectral_path_from_name(std::string_view name);

/// The glare stage's settings (docs/architecture.md "The pipeline, one frame", step 3; K2012 §4.2-4.3): the
/// ones every model shares, the wave-optics eye (its typed home, which the pupil and hippus code share), and
/// the other models' declared settings (values). The models are glare_models/glare_model_list.h.
struct GlareSettings {
    GlareModel model = GlareModel::none;
    /// Pupil diameter (mm); nullopt: from the adaptation luminance (K2012 eq 3.15).
    std::optional<double> pupil_mm;
    EyeModel eye;               ///< wave-optics; its pupil_diameter_mm is set per frame
    int psf_size = 512;         ///< N of the PSF (power of two)
    int spectral_samples = 30;  ///< K2012 §6.1: 30 is the compromise between 15 (steps) and 60
    SpectralPath spectral_path = SpectralPath::anchored;
    int spectral_anchors = 6;                     ///< anchored: exact FFTs (wavelengths placed by the SPD's luminance)
    GlareWindow window = GlareWindow::silverman;  ///< K2012 §5.3.1: Silverman is safe at 16 bits
    std::optional<double> radius_deg;             ///< billboard radius; default per model (see glare_stage.h)
    int area_layers = 16;                         ///< at most this many disc layers (K2012 §4.2.6)
    /// The models' own settings that a file or an option gave, by key; each
    /// model declares its keys, defaults and checks in its own file
    /// (GlareModelType::settings(), glare_setting.h) and reads them with
    /// glare_number / glare_flag / glare_text.
    GlareSettingValues values;
    /// Where the `cie` veil's convolution and a one-scale PSF's FFT run
    /// (placement.h): automatic = the GPU on a hardware driver, the CPU on a
    /// software rasteriser.
    ComputePlacement placement = ComputePlacement::automatic;
    /// The PSF cache's pupil step (mm), when given: the kernel is computed for
    /// the pupil diameter rounded to a multiple of this step, so a pupil that
    /// moves by less (hippus, a drifting adaptation level) reuses the cached
    /// PSF; 0: the exact pupil, rebuilt on any change. Not given (the default):
    /// the exact pupil while it stays still, and while it moves (hippus, or a
    /// pupil that changed in each of the last two frames) the kernel
    /// interpolated between grid pupils 0.05 mm apart (pupil_kernel_cache.h,
    /// issue 27 item 2). docs/bench.md measures the errors of both.
    std::optional<double> pupil_tolerance_mm;
};

struct Scene {
    display::DisplayGeometry display;
    Camera camera;
    Environment environment;
    ProfileTables profiles;
    std::vector<Light> lights;
    std::vector<Disc> discs;  ///< drawn over the background, under the lights, in order
    /// The eye's adaptation luminance (cd/m², > 0; [eye] adaptation_cd_m2), the
    /// one stored level: it sets the pupil (K2012 eq 3.15) and Spencer's vision
    /// class, is recorded in image headers, is the tone mapper's level when
    /// output.adaptation.mode is fixed, and gives the automatic pre-exposure
    /// (FrameOptions::pre_exposure = 0). With dynamic adaptation the tone
    /// mapper measures the frames instead (output_settings.h).
    double adaptation_cd_m2 = 0.001;
    GlareSettings glare;
    /// Adaptation mode, tone mapping, display model and encoding ([eye],
    /// [tonemap], [display] of the scene file).
    OutputSettings output;
};

/// The glare model a light is drawn with: its own, else the eye's (docs/scene-file.md "[[light]]").
GlareModel light_glare_model(const Scene& scene, const Light& light);
/// Whether any light of the scene is drawn with glare (a model other than `none`).
bool any_light_glare(const Scene& scene);
/// Every glare model the scene uses: the eye's, then each light's own, each once.
std::vector<GlareModel> glare_models_used(const Scene& scene);

}  // namespace atonlab::stimuli
