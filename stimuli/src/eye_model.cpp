// The eye model of the wave-optics glare (K2012 §4.2.1): pupil size from
// adaptation (eq 3.15), pupillary hippus (eq 4.7), the seeded obstacle geometry,
// its area-sampled pupil-plane image times the defocus phase (eq 4.6's E), its
// split into core and scatter (docs/glare.md), and Spencer et al.'s analytic
// PSF for comparison.
//
// Determinism: every random number comes from SplitMix64 (Steele, Lea & Flood
// 2014) with our own conversion to doubles, never from <random>'s
// distributions, whose output is implementation-defined. Each component draws
// from its own stream, so switching one on or off leaves the others unchanged.
#include "atonlab/stimuli/eye_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstddef>
#include <numbers>
#include <string>
#include <utility>

#include "atonlab/stimuli/error.h"

namespace atonlab::stimuli {
namespace {

constexpr double pi = std::numbers::pi;
constexpr double mm_per_um = 1e-3;
constexpr double mm_per_nm = 1e-6;
constexpr double reference_wavelength_mm = kReferenceWavelengthNm * mm_per_nm;

// ---- random numbers -------------------------------------------------------

/// SplitMix64's output function: a bijective 64-bit mixer.
constexpr std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/// One independent SplitMix64 stream per (seed, component).
class Rng {
public:
    Rng(std::uint64_t seed, std::uint64_t stream) : state_(mix64(seed) ^ mix64(stream * 0x9E3779B97F4A7C15ull + 1)) {}

    std::uint64_t next() {
        state_ += 0x9E3779B97F4A7C15ull;
        return mix64(state_);
    }
    /// Uniform in [0, 1): the top 53 bits, exactly representable.
    double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
    /// Uniform in [-0.5, 0.5).
    double centred() { return uniform() - 0.5; }

private:
    std::uint64_t state_;
};

// Stream tags: fixed forever, or every seeded eye changes.
enum : std::uint64_t {
    stream_gratings = 1,
    stream_lens_particles = 2,
    stream_vitreous_particles = 3,
    stream_eyelashes = 4,
    stream_hippus = 5,
};

// ---- hippus noise -----------------------------------------------------------

/// A lattice value in [-1, 1] hashed from (seed, octave, i).
double lattice_value(std::uint64_t seed, int octave, std::int64_t i) {
    const std::uint64_t h =
        mix64(mix64(seed ^ mix64(stream_hippus)) + static_cast<std::uint64_t>(octave) * 0xD1B54A32D192ED03ull +
              static_cast<std::uint64_t>(i) * 0x9E3779B97F4A7C15ull);
    return static_cast<double>(h >> 11) * 0x1.0p-52 - 1.0;
}

/// 1-D value noise: lattice values joined by the quintic fade 6f⁵ - 15f⁴ + 10f³
/// (C² continuous, so the pupil never jerks). A convex combination of two
/// lattice values, hence in [-1, 1].
double value_noise(std::uint64_t seed, int octave, double x) {
    const double fl = std::floor(x);
    const double f = x - fl;
    const auto i = static_cast<std::int64_t>(fl);
    const double u = f * f * f * (f * (f * 6 - 15) + 10);
    const double a = lattice_value(seed, octave, i), b = lattice_value(seed, octave, i + 1);
    return a + (b - a) * u;
}

/// Three octaves (frequencies 1, 2, 4; amplitudes 1, 1/2, 1/4), divided by
/// 1.75 so the sum stays in [-1, 1] (K2012 §4.2.1 asks for three octaves).
double hippus_noise(std::uint64_t seed, double x) {
    // Wrap far arguments into [-2^40, 2^40]: the cast to int64 stays defined,
    // and the noise repeats only after ~10^12 lattice cells.
    constexpr double wrap = 0x1.0p40;
    if (std::abs(x) > wrap) x = std::fmod(x, wrap);
    double sum = 0;
    for (int octave = 0; octave < 3; ++octave) {
        const double scale = std::ldexp(1.0, octave);
        sum += value_noise(seed, octave, x * scale) / scale;
    }
    return sum / 1.75;
}

/// The factor multiplying noise in eq 4.7: amplitude · (p_max/p) · sqrt(1 - p/p_max),
/// 0 when p ≥ p_max (a pupil at its maximum cannot dilate further).
double hippus_swing_mm(const EyeModel& eye) {
    const double p = eye.pupil_diameter_mm, p_max = eye.hippus.max_pupil_mm;
    if (!eye.hippus.enabled || p >= p_max) return 0.0;
    return eye.hippus.amplitude * (p_max / p) * std::sqrt(1.0 - p / p_max);
}

/// The clamp of pupil_diameter_mm_at: [p/2, max(p, p_max)]. The upper end keeps
/// a pupil under its anatomical maximum; the lower end keeps a large amplitude
/// from closing (or inverting) the pupil.
double hippus_lower_mm(const EyeModel& eye) {
    return 0.5 * eye.pupil_diameter_mm;
}
double hippus_upper_mm(const EyeModel& eye) {
    return std::max(eye.pupil_diameter_mm, eye.hippus.max_pupil_mm);
}

/// The largest diameter hippus can reach (noise ∈ [-1, 1]).
double largest_pupil_mm(const EyeModel& eye) {
    if (!eye.hippus.enabled) return eye.pupil_diameter_mm;
    return std::min(eye.pupil_diameter_mm + hippus_swing_mm(eye), hippus_upper_mm(eye));
}

// ---- validation ---------------------------------------------------------------

[[noreturn]] void refuse(const std::string& key, const std::string& sentence) {
    throw InputError(SourceLocation{"", 0, 0, key}, sentence);
}

void require_non_negative(const std::string& key, double v, const char* unit) {
    if (!(v >= 0) || !std::isfinite(v))
        refuse(key, fmt::format("{} must be a finite number ≥ 0{}, got {}.", key, unit, v));
}

void require_positive(const std::string& key, double v, const char* unit) {
    if (!(v > 0) || !std::isfinite(v))
        refuse(key, fmt::format("{} must be a finite number > 0{}, got {}.", key, unit, v));
}

void require_count(const std::string& key, int v) {
    if (v < 0) refuse(key, fmt::format("{} is a count and must be at least 0, got {}.", key, v));
}

void require_fraction(const std::string& key, double v, const char* what) {
    if (!(v >= 0 && v <= 1)) refuse(key, fmt::format("{} is {} and must be in [0, 1], got {}.", key, what, v));
}

void validate_particles(const std::string& prefix, const Particles& p) {
    require_count(prefix + ".count", p.count);
    require_non_negative(prefix + ".diameter_um", p.diameter_um, " µm");
    require_fraction(prefix + ".diameter_spread", p.diameter_spread, "the relative half-range of the diameters");
    require_fraction(prefix + ".opacity", p.opacity, "an opacity (1 = opaque)");
    require_non_negative(prefix + ".spread_radius_mm", p.spread_radius_mm, " mm");
}

// ---- geometry -------------------------------------------------------------------

void add_particles(std::vector<EyeGeometry::Disc>& out, const Particles& p, double default_radius_mm,
                   std::uint64_t seed, std::uint64_t stream) {
    if (!p.enabled) return;
    Rng rng(seed, stream);
    const double spread = p.spread_radius_mm > 0 ? p.spread_radius_mm : default_radius_mm;
    for (int k = 0; k < p.count; ++k) {
        // Uniform over the disc: r = R sqrt(u) makes the density uniform in area.
        const double r = spread * std::sqrt(rng.uniform());
        const double phi = 2 * pi * rng.uniform();
        const double d_um = p.diameter_um * (1 + p.diameter_spread * 2 * rng.centred());
        out.push_back({glm::dvec2(r * std::cos(phi), r * std::sin(phi)), 0.5 * d_um * mm_per_um, p.opacity});
    }
}

// ---- rasterising ----------------------------------------------------------------

/// A segment prepared for distance tests: a capsule of half-width hw around a→b.
struct Capsule {
    glm::dvec2 a, d;  ///< start, b - a
    double inv_len2;  ///< 1 / |d|², 0 for a point
    double hw2;       ///< (width/2)²
    double hw;
    double factor;  ///< 1 - opacity

    bool covers(glm::dvec2 p) const { return distance2(p) <= hw2; }
    double distance2(glm::dvec2 p) const {
        const glm::dvec2 ap = p - a;
        const double t = std::clamp(glm::dot(ap, d) * inv_len2, 0.0, 1.0);
        const glm::dvec2 q = ap - t * d;
        return glm::dot(q, q);
    }
};

struct Circle {
    glm::dvec2 c;
    double r2;
    double factor;  ///< 1 - opacity
    bool covers(glm::dvec2 p) const {
        const glm::dvec2 q = p - c;
        return glm::dot(q, q) <= r2;
    }
};

/// Obstacles binned into square tiles of texels over the pupil's bounding box,
/// so each sample is tested only against the few obstacles near it.
struct TileGrid {
    static constexpr int tile = 16;  ///< texels per tile side
    int first = 0;                   ///< first texel (both axes) of the box
    int tiles = 0;                   ///< tiles per side
    std::vector<std::vector<int>> circles, capsules;

    std::size_t index(int tx, int ty) const { return static_cast<std::size_t>(ty) * tiles + tx; }
};

}  // namespace

// ---- public functions -------------------------------------------------------------

double pupil_diameter_mm_from_adaptation(double adaptation_cd_m2) {
    if (!(adaptation_cd_m2 >= 0))
        throw InputError(SourceLocation{"", 0, 0, "adaptation_cd_m2"},
                         fmt::format("the adaptation luminance must be ≥ 0 cd/m², not {}.", adaptation_cd_m2));
    // K2012 eq 3.15. log10(0) = -inf and tanh(-inf) = -1 give the limit 7.9 mm,
    // but say so explicitly rather than lean on infinities.
    if (adaptation_cd_m2 == 0) return 7.9;
    return 4.9 - 3.0 * std::tanh(0.4 * (std::log10(adaptation_cd_m2) + 1.0));
}

EyeModel EyeModel::clear_pupil(double diameter_mm) {
    EyeModel e;
    e.pupil_diameter_mm = diameter_mm;
    e.hippus.enabled = false;
    e.gratings.enabled = false;
    e.lens_particles.enabled = false;
    e.vitreous_particles.enabled = false;
    e.eyelashes.enabled = false;
    e.eyelid.enabled = false;
    e.defocus_diopters = 0.0;
    e.halo_radius_deg = std::nullopt;
    return e;
}

EyeModel EyeModel::k2012() {
    EyeModel e;
    e.scale = EyeScale::k2012_single;
    // The Fresnel distance this code used before the split, d = 5000 mm (K2012
    // §5.2 leaves d open; Trester's λd = N texel² gives ~1100 mm at N = 512,
    // which blurs the stretched core to ~1.8°): ΔD = 1/d.
    e.defocus_diopters = 1.0 / 5.0;
    return e;
}

std::optional<EyeModel> eye_preset(std::string_view name) {
    if (name == "focused") return EyeModel{};
    if (name == "k2012") return EyeModel::k2012();
    return std::nullopt;
}

std::vector<std::string> eye_preset_names() {
    return {"focused", "k2012"};
}

void EyeModel::validate(int n) const {
    if (!(pupil_diameter_mm > 0) || !std::isfinite(pupil_diameter_mm))
        refuse("pupil_diameter_mm",
               fmt::format("pupil_diameter_mm must be a finite number > 0 mm, got {}.", pupil_diameter_mm));
    require_non_negative("hippus.amplitude", hippus.amplitude, "");
    require_positive("hippus.max_pupil_mm", hippus.max_pupil_mm, " mm");

    require_count("gratings.count", gratings.count);
    require_non_negative("gratings.inner_radius_mm", gratings.inner_radius_mm, " mm");
    if (gratings.enabled && gratings.inner_radius_mm == 0)
        refuse("gratings.inner_radius_mm",
               "gratings.inner_radius_mm must be > 0 mm while the gratings are enabled, got 0.");
    require_non_negative("gratings.width_um", gratings.width_um, " µm");
    require_fraction("gratings.opacity", gratings.opacity, "an opacity (1 = opaque)");
    require_fraction("gratings.angle_jitter", gratings.angle_jitter, "a fraction of the angular period");

    validate_particles("lens_particles", lens_particles);
    validate_particles("vitreous_particles", vitreous_particles);

    require_count("eyelashes.count", eyelashes.count);
    require_non_negative("eyelashes.width_um", eyelashes.width_um, " µm");
    if (!std::isfinite(eyelashes.reach_mm))
        refuse("eyelashes.reach_mm",
               fmt::format("eyelashes.reach_mm must be a finite number of mm, got {}.", eyelashes.reach_mm));
    if (!(eyelashes.max_tilt_deg >= 0 && eyelashes.max_tilt_deg < 90))
        refuse("eyelashes.max_tilt_deg",
               fmt::format("eyelashes.max_tilt_deg must be in [0°, 90°), got {}°.", eyelashes.max_tilt_deg));
    if (!std::isfinite(eyelid.edge_mm))
        refuse("eyelid.edge_mm", fmt::format("eyelid.edge_mm must be a finite number of mm, got {}.", eyelid.edge_mm));

    if (!std::isfinite(defocus_diopters))
        refuse("defocus_diopters",
               fmt::format("defocus_diopters must be a finite number of diopters, got {}.", defocus_diopters));
    require_positive("plane_width_mm", plane_width_mm, " mm");
    if (halo_radius_deg && (!(*halo_radius_deg > 0) || !(*halo_radius_deg < 90)))
        refuse("halo_radius_deg", fmt::format("halo_radius_deg must be in (0°, 90°), got {}°.", *halo_radius_deg));
    // The two-scale eye only widens the scatter: its grid must be at least as
    // coarse as the core's, or the core would not fit onto it.
    if (scale == EyeScale::two_scales && angular_scale(*this) < 1.0)
        refuse("halo_radius_deg",
               fmt::format("halo_radius_deg = {}° lies inside the ring the gratings diffract to at their physical "
                           "scale ({:.3g}°); the two-scale eye can only widen the scatter, so give at least that, "
                           "or 0 for the physical scale.",
                           *halo_radius_deg, *halo_radius_deg / angular_scale(*this)));
    if (supersampling < 1)
        refuse("supersampling",
               fmt::format("supersampling must be at least 1 sample per texel per axis, got {}.", supersampling));
    if (!is_power_of_two(n)) refuse("size", fmt::format("the pupil plane's size must be a power of two, got {}.", n));

    // |F|² is the autocorrelation of P·E, twice the pupil wide: a pupil wider
    // than half the plane wraps around and aliases the PSF.
    const double largest = largest_pupil_mm(*this);
    if (largest > 0.5 * plane_width_mm)
        refuse("pupil_diameter_mm",
               fmt::format("the pupil ({} mm{}) is wider than half the pupil plane ({} mm), so |F|² would alias; "
                           "widen plane_width_mm or shrink the pupil.",
                           largest, hippus.enabled ? " at its hippus maximum" : "", plane_width_mm));

    // The defocus phase π ΔD r²/λ grows by 2π ΔD r h/λ per texel at radius r;
    // past π between neighbouring texels at the pupil's edge it is undersampled.
    const double limit = max_defocus_diopters(*this, n);
    if (std::abs(defocus_diopters) > limit)
        refuse("defocus_diopters",
               fmt::format("{} D of defocus cannot be sampled at size {} for a {} mm pupil: its phase would change by "
                           "more than π between texels at the pupil's edge (and its blur disc, p·ΔD/2 = {:.3g}°, "
                           "would overflow the grid); at most ±{:.3g} D here, or raise the size.",
                           defocus_diopters, n, largest, 0.5 * largest * 1e-3 * std::abs(defocus_diopters) * 180 / pi,
                           limit));
}

double pupil_diameter_mm_at(const EyeModel& eye, double time_s) {
    if (!eye.hippus.enabled) return eye.pupil_diameter_mm;
    if (!std::isfinite(time_s))
        throw InputError(SourceLocation{"", 0, 0, "time_s"}, fmt::format("time must be finite, not {} s.", time_s));
    // The fields eq 4.7 reads, checked here too: this is callable without validate().
    const double p = eye.pupil_diameter_mm;
    require_positive("pupil_diameter_mm", p, " mm");
    require_non_negative("hippus.amplitude", eye.hippus.amplitude, "");
    require_positive("hippus.max_pupil_mm", eye.hippus.max_pupil_mm, " mm");
    // K2012 eq 4.7 (Ritschel et al. 2009), with the amplitude the header adds;
    // the noise's argument is t/p as in the paper (t in s, p in mm).
    const double h = p + hippus_noise(eye.seed, time_s / p) * hippus_swing_mm(eye);
    return std::clamp(h, hippus_lower_mm(eye), hippus_upper_mm(eye));
}

double angular_scale(const EyeModel& eye) {
    const LensGratings& g = eye.gratings;
    if (!g.enabled || !eye.halo_radius_deg || g.count <= 0 || !(g.inner_radius_mm > 0)) return 1.0;
    // A radial grating of `count` lines has spacing 2πr/count at radius r and
    // diffracts λ0 to λ0·count/(2πr) rad. k2012_single moves its outer edge
    // (r = inner_radius_mm) to halo_radius_deg, as K2012 §4.2 does.
    // two_scales moves the ring from the pupil's edge instead: the per-steradian
    // intensity there is highest (the annulus at r holds energy ∝ r dr and
    // spreads it over a solid angle ∝ dr/r³), so that ring is the halo's radius
    // (docs/glare.md). Without gratings inside the pupil, the inner radius again.
    double r_mm = g.inner_radius_mm;
    if (eye.scale == EyeScale::two_scales) r_mm = std::max(r_mm, 0.5 * eye.pupil_diameter_mm);
    const double ring_rad = reference_wavelength_mm * g.count / (2 * pi * r_mm);
    return (*eye.halo_radius_deg * pi / 180.0) / ring_rad;
}

double psf_degrees_per_texel(const EyeModel& eye) {
    return angular_scale(eye) * reference_wavelength_mm / eye.plane_width_mm * 180.0 / pi;
}

bool has_two_scales(const EyeModel& eye) {
    return eye.scale == EyeScale::two_scales && angular_scale(eye) != 1.0;
}

double core_degrees_per_texel(const EyeModel& eye) {
    if (!has_two_scales(eye)) return psf_degrees_per_texel(eye);
    return reference_wavelength_mm / eye.plane_width_mm * 180.0 / pi;
}

double max_defocus_diopters(const EyeModel& eye, int n) {
    // 2π |ΔD| (p/2) h / λ ≤ π with h = W/n (all in metres): |ΔD| ≤ λ n / (p W).
    // The exact path's plane W·λ/λ0 gives the same bound at every λ.
    const double p_m = largest_pupil_mm(eye) * 1e-3;
    return kReferenceWavelengthNm * 1e-9 * n / (p_m * eye.plane_width_mm * 1e-3);
}

EyeGeometry eye_geometry(const EyeModel& eye) {
    EyeGeometry g;
    const double w = eye.plane_width_mm;
    const double mean_radius = 0.5 * eye.pupil_diameter_mm;

    if (eye.gratings.enabled && eye.gratings.count > 0) {
        const LensGratings& gr = eye.gratings;
        Rng rng(eye.seed, stream_gratings);
        const double period = 2 * pi / gr.count;
        // Out to the plane's corner: the pupil clips them.
        const double outer = std::max(gr.inner_radius_mm, w * std::numbers::sqrt2 / 2);
        for (int k = 0; k < gr.count; ++k) {
            const double phi = period * k + gr.angle_jitter * period * rng.centred();
            const glm::dvec2 dir(std::cos(phi), std::sin(phi));
            g.lines.push_back({gr.inner_radius_mm * dir, outer * dir, gr.width_um * mm_per_um, gr.opacity});
        }
    }

    add_particles(g.discs, eye.lens_particles, mean_radius, eye.seed, stream_lens_particles);
    add_particles(g.discs, eye.vitreous_particles, mean_radius, eye.seed, stream_vitreous_particles);

    if (eye.eyelashes.enabled && eye.eyelashes.count > 0) {
        const Eyelashes& el = eye.eyelashes;
        Rng rng(eye.seed, stream_eyelashes);
        const double spacing = w / el.count;
        for (int k = 0; k < el.count; ++k) {
            // Roots evenly across the top edge, each jittered by up to a quarter
            // spacing; the tip at y = reach_mm, displaced by the tilt.
            const double x_root = -0.5 * w + (k + 0.5 + 0.5 * rng.centred()) * spacing;
            const double tilt = el.max_tilt_deg * 2 * rng.centred() * pi / 180.0;
            const double drop = 0.5 * w - el.reach_mm;
            g.lines.push_back({glm::dvec2(x_root, 0.5 * w), glm::dvec2(x_root + drop * std::tan(tilt), el.reach_mm),
                               el.width_um * mm_per_um, 1.0});
        }
    }

    if (eye.eyelid.enabled) g.eyelid_edge_mm = eye.eyelid.edge_mm;
    return g;
}

ComplexImage<double> pupil_plane(const EyeModel& eye, int n, double wavelength_nm, double plane_width_mm,
                                 double time_s) {
    eye.validate(n);
    if (!(wavelength_nm > 0) || !std::isfinite(wavelength_nm))
        throw InputError(SourceLocation{"", 0, 0, "wavelength_nm"},
                         fmt::format("the wavelength must be a finite number > 0 nm, not {}.", wavelength_nm));
    if (!(plane_width_mm > 0) || !std::isfinite(plane_width_mm))
        throw InputError(
            SourceLocation{"", 0, 0, "plane_width_mm"},
            fmt::format("the pupil plane's width must be a finite number > 0 mm, not {}.", plane_width_mm));

    ComplexImage<double> image(n);
    const double radius = 0.5 * pupil_diameter_mm_at(eye, time_s);
    const double r2 = radius * radius;
    const double h = plane_width_mm / n;
    const int s = eye.supersampling;
    const double inv_samples = 1.0 / (static_cast<double>(s) * s);
    auto centre = [&](int i) { return (i + 0.5 - 0.5 * n) * h; };

    // Offsets of the s×s stratified samples from a texel centre.
    std::vector<double> offset(static_cast<std::size_t>(s));
    for (int a = 0; a < s; ++a) offset[static_cast<std::size_t>(a)] = ((a + 0.5) / s - 0.5) * h;

    // The texels the pupil can touch (same range on both axes).
    const int first = std::clamp(static_cast<int>(std::floor(-radius / h + 0.5 * n)), 0, n - 1);
    const int last = std::clamp(static_cast<int>(std::floor(radius / h + 0.5 * n)), 0, n - 1);

    // ---- obstacles, binned into tiles over [first, last]² ----
    const EyeGeometry geo = eye_geometry(eye);
    std::vector<Circle> circles;
    std::vector<Capsule> capsules;
    TileGrid grid;
    grid.first = first;
    grid.tiles = (last - first) / TileGrid::tile + 1;
    grid.circles.resize(static_cast<std::size_t>(grid.tiles) * grid.tiles);
    grid.capsules.resize(grid.circles.size());

    // Clamped to [-1, n] before the cast: a far-tilted eyelash may end light-years away.
    auto to_texel = [&](double mm) {
        return static_cast<int>(std::floor(std::clamp(mm / h + 0.5 * n, -1.0, static_cast<double>(n))));
    };
    // Tile range covering [lo, hi] mm on one axis, clipped to the grid; false if empty.
    auto tile_range = [&](double lo, double hi, int& t0, int& t1) {
        const int i0 = std::max(to_texel(lo), first), i1 = std::min(to_texel(hi), last);
        if (i0 > i1) return false;
        t0 = (i0 - first) / TileGrid::tile;
        t1 = (i1 - first) / TileGrid::tile;
        return true;
    };
    auto tile_centre_mm = [&](int t) { return centre(first + t * TileGrid::tile) + (0.5 * TileGrid::tile - 0.5) * h; };
    const double tile_half_diagonal = std::numbers::sqrt2 * 0.5 * TileGrid::tile * h;

    for (const auto& d : geo.discs) {
        if (d.opacity <= 0 || d.radius_mm <= 0) continue;
        int x0, x1, y0, y1;
        if (!tile_range(d.centre_mm.x - d.radius_mm, d.centre_mm.x + d.radius_mm, x0, x1) ||
            !tile_range(d.centre_mm.y - d.radius_mm, d.centre_mm.y + d.radius_mm, y0, y1))
            continue;
        const int id = static_cast<int>(circles.size());
        circles.push_back({d.centre_mm, d.radius_mm * d.radius_mm, 1 - d.opacity});
        for (int ty = y0; ty <= y1; ++ty)
            for (int tx = x0; tx <= x1; ++tx) grid.circles[grid.index(tx, ty)].push_back(id);
    }
    for (const auto& l : geo.lines) {
        if (l.opacity <= 0 || l.width_mm <= 0) continue;
        const double hw = 0.5 * l.width_mm;
        int x0, x1, y0, y1;
        if (!tile_range(std::min(l.a_mm.x, l.b_mm.x) - hw, std::max(l.a_mm.x, l.b_mm.x) + hw, x0, x1) ||
            !tile_range(std::min(l.a_mm.y, l.b_mm.y) - hw, std::max(l.a_mm.y, l.b_mm.y) + hw, y0, y1))
            continue;
        const glm::dvec2 d = l.b_mm - l.a_mm;
        const double len2 = glm::dot(d, d);
        const Capsule c{l.a_mm, d, len2 > 0 ? 1 / len2 : 0.0, hw * hw, hw, 1 - l.opacity};
        const int id = static_cast<int>(capsules.size());
        capsules.push_back(c);
        // A long diagonal line's box holds many tiles it never touches: keep
        // only those whose circumscribed circle the capsule reaches.
        const double reach = hw + tile_half_diagonal;
        for (int ty = y0; ty <= y1; ++ty)
            for (int tx = x0; tx <= x1; ++tx)
                if (c.distance2(glm::dvec2(tile_centre_mm(tx), tile_centre_mm(ty))) <= reach * reach)
                    grid.capsules[grid.index(tx, ty)].push_back(id);
    }

    // ---- defocus exp(iπ ΔD r²/λ): K2012 eq 4.6's E = exp(iπ r²/(λ d)) with d = 1/ΔD ----
    // ΔD in 1/m = 1e-3/mm, r in mm, λ in mm.
    const double phase_per_mm2 = pi * eye.defocus_diopters * 1e-3 / (wavelength_nm * mm_per_nm);
    const std::optional<double> lid = geo.eyelid_edge_mm;

    for (int j = first; j <= last; ++j) {
        const double yc = centre(j);
        for (int i = first; i <= last; ++i) {
            const double xc = centre(i);
            // Texel square against the pupil disc: nearest and farthest points.
            const double nx = std::max(std::abs(xc) - 0.5 * h, 0.0), ny = std::max(std::abs(yc) - 0.5 * h, 0.0);
            if (nx * nx + ny * ny > r2) continue;  // wholly outside: stays 0
            const double fx = std::abs(xc) + 0.5 * h, fy = std::abs(yc) + 0.5 * h;
            const bool inside = fx * fx + fy * fy <= r2;

            const std::size_t t = grid.index((i - first) / TileGrid::tile, (j - first) / TileGrid::tile);
            const std::vector<int>& near_circles = grid.circles[t];
            const std::vector<int>& near_capsules = grid.capsules[t];
            const bool lid_clear = !lid || yc + 0.5 * h <= *lid;

            double p;
            if (inside && lid_clear && near_circles.empty() && near_capsules.empty()) {
                p = 1.0;
            } else {
                double sum = 0;
                for (int b = 0; b < s; ++b) {
                    const double y = yc + offset[static_cast<std::size_t>(b)];
                    if (lid && y > *lid) continue;  // the eyelid: opaque above its edge
                    for (int a = 0; a < s; ++a) {
                        const glm::dvec2 q(xc + offset[static_cast<std::size_t>(a)], y);
                        if (!inside && glm::dot(q, q) > r2) continue;
                        // Overlapping obstacles multiply their transmittances.
                        double v = 1.0;
                        for (int c : near_circles)
                            if (circles[static_cast<std::size_t>(c)].covers(q))
                                v *= circles[static_cast<std::size_t>(c)].factor;
                        for (int c : near_capsules)
                            if (capsules[static_cast<std::size_t>(c)].covers(q))
                                v *= capsules[static_cast<std::size_t>(c)].factor;
                        sum += v;
                    }
                }
                p = sum * inv_samples;
            }
            if (p == 0) continue;
            const double phase = phase_per_mm2 * (xc * xc + yc * yc);
            image.at(i, j) = phase == 0 ? std::complex<double>(p, 0.0) : std::polar(p, phase);
        }
    }
    return image;
}

PupilParts pupil_parts(const EyeModel& eye, int n, double wavelength_nm, double plane_width_mm, double time_s) {
    // P in focus: the obstacles' transmittance over the aperture.
    EyeModel focused = eye;
    focused.defocus_diopters = 0.0;
    ComplexImage<double> p = pupil_plane(focused, n, wavelength_nm, plane_width_mm, time_s);
    // A·E: the aperture alone (the pupil disc with hippus, and the eyelid, which
    // shapes the aperture rather than scattering), with the defocus.
    EyeModel aperture = eye;
    aperture.gratings.enabled = false;
    aperture.lens_particles.enabled = false;
    aperture.vitreous_particles.enabled = false;
    aperture.eyelashes.enabled = false;
    PupilParts parts{pupil_plane(aperture, n, wavelength_nm, plane_width_mm, time_s), std::move(p), 1.0};

    // t = Σ P·A / Σ A²: the projection of P on A (A = |A·E|, P real), which
    // makes P − t·A orthogonal to A and hence to A·E's energy.
    double pa = 0, aa = 0;
    for (std::size_t i = 0; i < parts.core.data.size(); ++i) {
        const double a = std::abs(parts.core.data[i]);
        pa += parts.scatter.data[i].real() * a;
        aa += a * a;
    }
    const double t = aa > 0 ? pa / aa : 0.0;
    parts.mean_transmittance = t;
    for (std::size_t i = 0; i < parts.core.data.size(); ++i) {
        parts.scatter.data[i] -= t * std::abs(parts.core.data[i]);
        parts.core.data[i] *= t;
    }
    return parts;
}

double spencer_psf(double theta_deg, double wavelength_nm, SpencerVision vision) {
    if (!(theta_deg >= 0))
        throw InputError(SourceLocation{"", 0, 0, "theta_deg"},
                         fmt::format("the angle from the source must be ≥ 0°, not {}°.", theta_deg));
    // Spencer et al. 1995 eq 1-4 (θ in degrees, λ in nm). Each term integrates
    // to (180/π)² over the plane in deg² (f2 only within a finite field), i.e. to
    // 1 per steradian, so the weights are energy fractions summing to 1.
    const double t2 = theta_deg + 0.02;
    const double f0 = 2.61e6 * std::exp(-(theta_deg / 0.02) * (theta_deg / 0.02));
    const double f1 = 20.91 / (t2 * t2 * t2);
    const double f2 = 72.37 / (t2 * t2);
    auto f3 = [&] {
        if (!(wavelength_nm > 0) || !std::isfinite(wavelength_nm))
            throw InputError(SourceLocation{"", 0, 0, "wavelength_nm"},
                             fmt::format("the wavelength must be a finite number > 0 nm, not {}.", wavelength_nm));
        // The lenticular halo: a ring at 3λ/568 degrees of width ~0.37° (FWHM).
        const double u = theta_deg - 3.0 * wavelength_nm / 568.0;
        return 436.9 * (568.0 / wavelength_nm) * std::exp(-19.75 * u * u);
    };
    switch (vision) {
        case SpencerVision::photopic:
            return 0.384 * f0 + 0.478 * f1 + 0.138 * f2;
        case SpencerVision::mesopic:
            return 0.368 * f0 + 0.478 * f1 + 0.138 * f2 + 0.016 * f3();
        case SpencerVision::scotopic:
            return 0.282 * f0 + 0.478 * f1 + 0.207 * f2 + 0.033 * f3();
    }
    return 0.0;  // unreachable: every enumerator is handled above
}

}  // namespace atonlab::stimuli
