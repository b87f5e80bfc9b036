#pragma once
// The eye model that the wave-optics glare is computed from (K2012 §4.2.1,
// after Ritschel et al. 2009 and Kakimoto et al. 2005): a pupil-plane image of
// the aperture and the obstacles in and in front of the eye, each switchable,
// with parameters in physical units, multiplied by the Fresnel term E of
// K2012 eq 4.6. Deterministic for a seed: the obstacle geometry is drawn in
// millimetres from the seed alone, so every image size and wavelength sees the
// same eye.
//
// Pupil-plane coordinates: millimetres, origin at the pupil centre, +x right,
// +y up (as the observer's eye sees the world), image row 0 at the bottom
// (y = -W/2), texel (i, j) centred at ((i + 0.5 - n/2) W/n, (j + 0.5 - n/2) W/n).
#include <cstdint>
#include <optional>
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

struct EyeModel {
    double pupil_diameter_mm = 4.0;  ///< mean diameter p (eq 3.15 gives it from adaptation)
    Hippus hippus;
    LensGratings gratings;
    Particles lens_particles{true, 600, 30.0, 0.5, 1.0, 0.0};       ///< many small discs within the pupil
    Particles vitreous_particles{true, 40, 150.0, 0.5, 0.6, 0.0};   ///< few large, partly transparent discs
    Eyelashes eyelashes;
    Eyelid eyelid;
    /// d of eq 4.6 in mm; 0 turns E off (E = 1: the focused eye's Fraunhofer limit).
    /// E is a quadratic phase, i.e. defocus: its geometric blur radius is about
    /// (p/2)/d rad before the angular scale. Trester's λd = N texel² (K2012 §5.2)
    /// is d ≈ 1100 mm at N = 512 here, which blurs the core to ~1.8° under the
    /// 4° halo scale; the default 5000 mm keeps the core within ~0.4°, closer to
    /// K2012's figures. The anatomical 24 mm cannot be sampled (the phase step
    /// between texels at the pupil edge would exceed π) and is refused by validate().
    double fresnel_distance_mm = 5000.0;
    /// Side W of the square pupil plane (mm). The PSF's physical angular texel
    /// is λ/W rad; W ≥ 2 × the largest pupil keeps |F|² unaliased.
    double plane_width_mm = 18.0;
    /// Angular scale (K2012 §4.2, "a user parameter that adjusts the size of the
    /// glare"): with gratings on, the PSF is scaled so the halo's outer edge lies
    /// at this visual angle (Simpson 1953: about 4°). nullopt, or gratings off:
    /// physical Fraunhofer scale (λ/W rad per texel).
    std::optional<double> halo_radius_deg = 4.0;
    std::uint64_t seed = 1;
    int supersampling = 4;  ///< samples per texel per axis when rasterising

    /// A clear circular pupil of the given diameter: every obstacle, hippus and
    /// E off, physical scale. For tests and for studies.
    static EyeModel clear_pupil(double diameter_mm);

    /// Throws InputError (key names the field, e.g. "pupil_diameter_mm") for a
    /// pupil ≤ 0 or larger than the plane allows, negative counts or sizes, a
    /// Fresnel distance too short to sample at `n` texels, supersampling < 1.
    void validate(int n) const;
};

/// Pupil diameter (mm) at time t with hippus applied (eq 4.7); the mean
/// diameter when hippus is off. Always within (0, max(p, p_max)].
double pupil_diameter_mm_at(const EyeModel& eye, double time_s);

/// Angular scale factor s: the PSF's angular texel is s · λ0 / W rad.
/// 1 when the scale is physical (see EyeModel::halo_radius_deg).
double angular_scale(const EyeModel& eye);

/// Degrees per PSF texel at λ0 for this eye: s · λ0 / W, in degrees.
double psf_degrees_per_texel(const EyeModel& eye);

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
/// sampled with eye.supersampling² samples per texel. E uses the physical
/// coordinates and the wavelength: exp(iπ r²/(λ d)).
ComplexImage<double> pupil_plane(const EyeModel& eye, int n, double wavelength_nm, double plane_width_mm,
                                 double time_s = 0.0);

/// Spencer et al. 1995, "Physically-based glare effects for digital images",
/// eq 1-4 (the analytic PSF per unit solid angle, θ in degrees, λ in nm).
enum class SpencerVision { photopic, mesopic, scotopic };
double spencer_psf(double theta_deg, double wavelength_nm, SpencerVision vision);

}  // namespace atonlab::stimuli
