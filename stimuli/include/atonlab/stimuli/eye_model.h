#pragma once
// The eye model that the wave-optics glare is computed from (K2012 §4.2.1,
// after Ritschel et al. 2009 and Kakimoto et al. 2005): a pupil-plane image of
// the aperture and the obstacles in and in front of the eye, each switchable,
// with parameters in physical units, multiplied by the defocus phase (K2012
// eq 4.6's Fresnel term E with d = 1/ΔD). Deterministic for a seed: the
// obstacle geometry is drawn in millimetres from the seed alone, so every image
// size and wavelength sees the same eye.
//
// Pupil-plane coordinates: millimetres, origin at the pupil centre, +x right,
// +y up (as the observer's eye sees the world), image row 0 at the bottom
// (y = -W/2), texel (i, j) centred at ((i + 0.5 - n/2) W/n, (j + 0.5 - n/2) W/n).
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "atonlab/stimuli/fft.h"

namespace atonlab::stimuli {

/// λ0 of K2012 §4.2.4: the one wavelength the fast path transforms (nm).
constexpr double kReferenceWavelengthNm = 575.0;

/// Pupil diameter (mm) for an adaptation (field) luminance in cd/m², K2012 eq 3.15
/// (Moon & Spencer 1944 via Wyszecki & Stiles): p = 4.9 - 3 tanh(0.4 (log10 L + 1)).
/// Finite for every L ≥ 0 (L = 0 gives the dark-adapted limit 7.9 mm).
double pupil_diameter_mm_from_adaptation(double adaptation_cd_m2);

/// Pupillary hippus, K2012 eq 4.7 (Ritschel et al. 2009):
/// h(p, t) = p + amplitude · noise(t / p) · (p_max / p) · sqrt(1 - p / p_max),
/// noise: seeded smooth 1-D value noise of three octaves in [-1, 1].
struct Hippus {
    bool enabled = false;
    double amplitude = 0.1;      ///< scales the noise term (dimensionless)
    double max_pupil_mm = 9.0;   ///< p_max of eq 4.7
};

/// Lens gratings (K2012 §4.2.1): radial opaque lines from inner_radius_mm out
/// to the pupil edge, evenly spaced in angle with a seeded jitter. A radial
/// grating of `count` lines has angular period 2π/count; at radius r its
/// spacing is 2πr/count and it diffracts λ to the angle λ·count/(2πr). The
/// outer edge of the lenticular halo therefore lies at λ0·count/(2π·inner_radius).
struct LensGratings {
    bool enabled = true;
    int count = 120;                 ///< number of radial lines
    double inner_radius_mm = 1.6;    ///< where the lines start
    double width_um = 12.0;          ///< line width
    double opacity = 0.35;           ///< 1 = opaque
    double angle_jitter = 0.25;      ///< random offset of each line, in units of the angular period
};

/// Small opaque discs, uniformly distributed over a disc of `spread_radius_mm`
/// (0 = the pupil's radius), diameters uniform in diameter_um · [1 - spread, 1 + spread].
struct Particles {
    bool enabled = true;
    int count = 0;
    double diameter_um = 0.0;
    double diameter_spread = 0.5;  ///< relative half-range of the diameters
    double opacity = 1.0;
    double spread_radius_mm = 0.0;
};

/// Eyelashes (Kakimoto et al. 2005 §3): near-vertical opaque lines hanging from
/// the top of the pupil plane down to `reach_mm` above (+) or below (-) the
/// pupil centre, spaced across the plane with seeded jitter in position and angle.
struct Eyelashes {
    bool enabled = false;
    int count = 12;
    double width_um = 80.0;
    double reach_mm = 1.5;         ///< y of the lashes' tips (mm, pupil-centred)
    double max_tilt_deg = 15.0;    ///< tilt from vertical, uniform in ±max_tilt_deg
};

/// The eyelid edge: everything above y = edge_mm is opaque.
struct Eyelid {
    bool enabled = false;
    double edge_mm = 2.5;
};

/// How the eye's PSF is put together (docs/glare.md).
enum class EyeScale {
    /// Two angular scales, one PSF: the core (the aperture's diffraction with
    /// its defocus) at its physical scale λ/W rad per texel, the scatter of the
    /// obstacles (gratings, particles, eyelashes) at the scale that puts the
    /// halo at halo_radius_deg; their energies as the pupil function shares them.
    two_scales,
    /// K2012 §4.2 as the thesis draws it: one FFT of P·E, the whole PSF (core
    /// included) stretched so the gratings' outer halo edge lies at halo_radius_deg.
    k2012_single,
};

struct EyeModel {
    double pupil_diameter_mm = 4.0;  ///< mean diameter p (eq 3.15 gives it from adaptation)
    Hippus hippus;
    LensGratings gratings;
    Particles lens_particles{true, 600, 30.0, 0.5, 1.0, 0.0};       ///< many small discs within the pupil
    Particles vitreous_particles{true, 40, 150.0, 0.5, 0.6, 0.0};   ///< few large, partly transparent discs
    Eyelashes eyelashes;
    Eyelid eyelid;
    /// Defocus ΔD in diopters (1/m; + or −, 0 = in focus): the pupil phase
    /// 2π W(r)/λ with the wavefront error W(r) = ΔD r²/2 (paraxial defocus), i.e.
    /// exp(iπ ΔD r²/λ) at each wavelength. K2012 eq 4.6's Fresnel term E with
    /// distance d is the same phase with ΔD = 1/d. Geometric blur disc radius
    /// p·ΔD/2 rad. Sampling limit: |ΔD| ≤ λ0·n/(p·W) (validate()).
    double defocus_diopters = 0.0;
    /// Side W of the square pupil plane (mm). The PSF's physical angular texel
    /// is λ/W rad; W ≥ 2 × the largest pupil keeps |F|² unaliased.
    double plane_width_mm = 18.0;
    /// How the PSF's parts are placed in angle (docs/glare.md).
    EyeScale scale = EyeScale::two_scales;
    /// The scatter's angular scale (Simpson 1953: the lenticular halo at about
    /// 4°). two_scales: the ring the gratings at the pupil's edge diffract λ0
    /// into (the halo's brightest ring) lands at this visual angle. k2012_single
    /// (K2012 §4.2, "a user parameter that adjusts the size of the glare"): the
    /// whole PSF is scaled so the gratings' outer halo edge lands here. nullopt,
    /// or gratings off: physical Fraunhofer scale (λ/W rad per texel) for everything.
    std::optional<double> halo_radius_deg = 4.0;
    std::uint64_t seed = 1;
    int supersampling = 4;  ///< samples per texel per axis when rasterising

    /// A clear circular pupil of the given diameter: every obstacle and hippus
    /// off, in focus, physical scale. For tests and for studies.
    static EyeModel clear_pupil(double diameter_mm);
    /// The `k2012` preset: the default obstacles with K2012's single angular
    /// scale and its Fresnel term at d = 5000 mm (ΔD = 0.2 D), the look of the
    /// thesis's figures (before this eye was split into two scales).
    static EyeModel k2012();

    /// Throws InputError (key names the field, e.g. "pupil_diameter_mm") for a
    /// pupil ≤ 0 or larger than the plane allows, negative counts or sizes, a
    /// defocus the grid of `n` texels cannot sample, supersampling < 1.
    void validate(int n) const;
};

/// A named eye: "focused" (the default EyeModel: two scales, in focus) or
/// "k2012" (EyeModel::k2012()); nullopt for any other name.
std::optional<EyeModel> eye_preset(std::string_view name);
/// The names eye_preset() knows, for messages.
std::vector<std::string> eye_preset_names();

/// Pupil diameter (mm) at time t with hippus applied (eq 4.7); the mean
/// diameter when hippus is off. Always within (0, max(p, p_max)].
double pupil_diameter_mm_at(const EyeModel& eye, double time_s);

/// Angular scale factor s of the scatter (two_scales) or of the whole PSF
/// (k2012_single): its angular texel is s · λ0 / W rad. 1 when the scale is
/// physical (see EyeModel::halo_radius_deg).
double angular_scale(const EyeModel& eye);

/// Degrees per texel of the eye's PSF grid at λ0: s · λ0 / W, in degrees.
double psf_degrees_per_texel(const EyeModel& eye);

/// True when the eye's PSF is put together from two parts at different scales
/// (EyeScale::two_scales with angular_scale ≠ 1). Otherwise one coherent FFT of
/// P·E is exact wave optics and is what every path computes.
bool has_two_scales(const EyeModel& eye);

/// Degrees per texel of the core's own grid at λ0: λ0 / W (two_scales), or
/// psf_degrees_per_texel (k2012_single, where the core is stretched too).
double core_degrees_per_texel(const EyeModel& eye);

/// The largest defocus (diopters, either sign) an n-texel plane can sample for
/// this eye's largest pupil: λ0·n/(p·W). Beyond it the defocus phase changes by
/// more than π between neighbouring texels at the pupil's edge, and (the same
/// condition) the geometric blur disc p·ΔD/2 rad overflows the core's grid.
double max_defocus_diopters(const EyeModel& eye, int n);

/// The obstacle geometry drawn from the seed, in pupil-plane millimetres.
struct EyeGeometry {
    struct Disc {
        glm::dvec2 centre_mm;
        double radius_mm;
        double opacity;
    };
    struct Segment {
        glm::dvec2 a_mm, b_mm;
        double width_mm;
        double opacity;
    };
    std::vector<Disc> discs;       ///< lens and vitreous particles
    std::vector<Segment> lines;    ///< gratings and eyelashes
    std::optional<double> eyelid_edge_mm;
};
EyeGeometry eye_geometry(const EyeModel& eye);

/// The complex pupil-plane image P·E of eq 4.6 at one wavelength: n×n texels
/// over a plane of side plane_width_mm (the exact per-wavelength reference
/// passes W·λ/λ0 so every wavelength's FFT lands on λ0's angular grid).
/// P is the transmittance (pupil disc of diameter pupil_diameter_mm_at(eye, t),
/// times Π(1 - opacity · coverage) of each obstacle, times the eyelid), area-
/// sampled with eye.supersampling² samples per texel. E is the defocus phase
/// exp(iπ ΔD r²/λ) in physical coordinates at this wavelength (eq 4.6 with d = 1/ΔD).
ComplexImage<double> pupil_plane(const EyeModel& eye, int n, double wavelength_nm, double plane_width_mm,
                                 double time_s = 0.0);

/// The pupil plane split into the two fields of EyeScale::two_scales
/// (docs/glare.md): with P the transmittance of pupil_plane() in focus and A the
/// aperture alone (pupil disc and eyelid, no obstacles), t = Σ P·A / Σ A² is the
/// obstacles' mean transmittance, core = t·A·exp(iπ ΔD r²/λ) and scatter =
/// P − t·A. The two are orthogonal (Σ core*·scatter = 0 in focus), so their
/// energies Σ|core|² + Σ|scatter|² equal Σ P²: the obstacles take from the
/// core exactly what they scatter or absorb.
struct PupilParts {
    ComplexImage<double> core;
    ComplexImage<double> scatter;
    double mean_transmittance = 1.0;  ///< t
};
PupilParts pupil_parts(const EyeModel& eye, int n, double wavelength_nm, double plane_width_mm, double time_s = 0.0);

/// Spencer et al. 1995, "Physically-based glare effects for digital images",
/// eq 1-4 (the analytic PSF per unit solid angle, θ in degrees, λ in nm).
enum class SpencerVision { photopic, mesopic, scotopic };
double spencer_psf(double theta_deg, double wavelength_nm, SpencerVision vision);

}  // namespace atonlab::stimuli
