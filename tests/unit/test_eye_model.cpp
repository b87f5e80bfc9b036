// The eye model (K2012 §4.2.1): eq 3.15 and eq 4.7 against values worked out
// by hand, the pupil-plane image against areas and phases known in closed form,
// the seeded geometry's placement, validate()'s keys, and Spencer et al.'s PSF.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstring>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/eye_model.h"
#include "input_error.h"

namespace {

using namespace atonlab::stimuli;
using atonlab::InputError;
using atonlab::test::input_error_of;

constexpr double pi = std::numbers::pi;

/// Σ |P|² × texel area (mm²): the energy through the pupil plane.
double energy_mm2(const ComplexImage<double>& p, double plane_width_mm) {
    double s = 0;
    for (const auto& v : p.data) s += std::norm(v);
    const double h = plane_width_mm / p.n;
    return s * h * h;
}

/// Σ |P| × texel area (mm²): the transmitted area.
double area_mm2(const ComplexImage<double>& p, double plane_width_mm) {
    double s = 0;
    for (const auto& v : p.data) s += std::abs(v);
    const double h = plane_width_mm / p.n;
    return s * h * h;
}

/// Texel centre coordinate (mm) of index i, as the header defines it.
double centre_mm(int i, int n, double w) {
    return (i + 0.5 - n / 2.0) * w / n;
}

// ---- eq 3.15 -----------------------------------------------------------------

TEST(PupilFromAdaptation, Eq315AtHandComputedLuminances) {
    // p = 4.9 - 3 tanh(0.4 (log10 L + 1)):
    // L = 0.1: log10 = -1, tanh(0) = 0          -> 4.9
    // L = 1:   tanh(0.4) = 0.3799489622552249   -> 4.9 - 1.1398468867656747 = 3.7601531132343253
    // L = 10:  tanh(0.8) = 0.6640367702678489   -> 4.9 - 1.9921103108035467 = 2.9078896891964533
    EXPECT_NEAR(pupil_diameter_mm_from_adaptation(0.1), 4.9, 1e-12);
    EXPECT_NEAR(pupil_diameter_mm_from_adaptation(1.0), 3.7601531132343253, 1e-12);
    EXPECT_NEAR(pupil_diameter_mm_from_adaptation(10.0), 2.9078896891964533, 1e-12);
}

TEST(PupilFromAdaptation, LimitsAreFinite) {
    // L = 0: tanh(-inf) = -1 -> 7.9 mm (dark adapted).
    EXPECT_DOUBLE_EQ(pupil_diameter_mm_from_adaptation(0.0), 7.9);
    // L = 1e9: tanh(4) = 0.999329299739067 -> 4.9 - 2.997987899217201 = 1.902012100782799.
    EXPECT_NEAR(pupil_diameter_mm_from_adaptation(1e9), 1.902012100782799, 1e-12);
    // The bright limit 1.9 mm, even at the largest double and at infinity.
    EXPECT_NEAR(pupil_diameter_mm_from_adaptation(std::numeric_limits<double>::max()), 1.9, 1e-12);
    EXPECT_NEAR(pupil_diameter_mm_from_adaptation(std::numeric_limits<double>::infinity()), 1.9, 1e-12);
    EXPECT_NEAR(pupil_diameter_mm_from_adaptation(std::numeric_limits<double>::denorm_min()), 7.9, 1e-12);
}

TEST(PupilFromAdaptation, RefusesNegativeAndNaN) {
    EXPECT_THROW(pupil_diameter_mm_from_adaptation(-1e-9), InputError);
    EXPECT_THROW(pupil_diameter_mm_from_adaptation(std::nan("")), InputError);
}

// ---- the clear pupil ---------------------------------------------------------

TEST(PupilPlane, ClearPupilTransmitsItsArea) {
    const int n = 256;
    const double w = 18.0;
    // Σ|P| is the area π r² up to the sampling error of the edge (< 0.2% here).
    const auto p4 = pupil_plane(EyeModel::clear_pupil(4.0), n, kReferenceWavelengthNm, w);
    EXPECT_NEAR(area_mm2(p4, w), pi * 2.0 * 2.0, 0.005 * pi * 4.0);
    // Σ|P|² loses about (edge texels)/6 texels to partial coverage (c² < c):
    // ~0.75% for an 8 mm pupil at n = 256, so the 1% bound holds.
    const auto p8 = pupil_plane(EyeModel::clear_pupil(8.0), n, kReferenceWavelengthNm, w);
    EXPECT_NEAR(energy_mm2(p8, w), pi * 4.0 * 4.0, 0.01 * pi * 16.0);
    EXPECT_LE(energy_mm2(p8, w), area_mm2(p8, w));
}

TEST(PupilPlane, ClearPupilIsOneInsideAndZeroOutside) {
    const int n = 256;
    const double w = 18.0, r = 2.5, h = w / n;
    const auto p = pupil_plane(EyeModel::clear_pupil(2 * r), n, kReferenceWavelengthNm, w);
    int inside = 0, outside = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double rho = std::hypot(centre_mm(i, n, w), centre_mm(j, n, w));
            if (rho < r - h) {
                EXPECT_EQ(p.at(i, j), std::complex<double>(1.0, 0.0)) << i << "," << j;
                ++inside;
            } else if (rho > r + h) {
                EXPECT_EQ(p.at(i, j), std::complex<double>(0.0, 0.0)) << i << "," << j;
                ++outside;
            }
        }
    EXPECT_GT(inside, 3000);
    EXPECT_GT(outside, 50000);
}

TEST(PupilPlane, DefocusPhaseIsPiDeltaDRSquaredOverLambda) {
    // ΔD = 1/1.1 m: the same phase as K2012 eq 4.6's E at d = 1100 mm.
    EyeModel eye = EyeModel::clear_pupil(4.0);
    eye.defocus_diopters = 1.0 / 1.1;
    const int n = 256;
    for (double lambda_nm : {575.0, 450.0}) {
        const double w = 18.0 * lambda_nm / kReferenceWavelengthNm;
        const auto p = pupil_plane(eye, n, lambda_nm, w);
        for (auto [i, j] : {std::pair{140, 133}, std::pair{118, 137}, std::pair{128, 128}}) {
            const double x = centre_mm(i, n, w), y = centre_mm(j, n, w);
            const double want = pi * (x * x + y * y) / (lambda_nm * 1e-6 * 1100.0);
            const std::complex<double> v = p.at(i, j);
            EXPECT_NEAR(std::abs(v), 1.0, 1e-12);
            // Compare modulo 2π.
            const double diff = std::remainder(std::arg(v) - want, 2 * pi);
            EXPECT_NEAR(diff, 0.0, 1e-9) << "lambda " << lambda_nm << " texel " << i << "," << j;
        }
    }
}

TEST(PupilPlane, NoPhaseWhenInFocus) {
    const auto p = pupil_plane(EyeModel::clear_pupil(4.0), 128, 500.0, 18.0);
    for (const auto& v : p.data) EXPECT_EQ(v.imag(), 0.0);
}

// ---- determinism -------------------------------------------------------------

TEST(PupilPlane, SameSeedGivesBitIdenticalImages) {
    const EyeModel eye;  // defaults: gratings, lens and vitreous particles, E on
    const auto a = pupil_plane(eye, 256, kReferenceWavelengthNm, eye.plane_width_mm);
    const auto b = pupil_plane(eye, 256, kReferenceWavelengthNm, eye.plane_width_mm);
    ASSERT_EQ(a.data.size(), b.data.size());
    EXPECT_EQ(std::memcmp(a.data.data(), b.data.data(), a.data.size() * sizeof(a.data[0])), 0);

    EyeModel other = eye;
    other.seed = 2;
    const auto c = pupil_plane(other, 256, kReferenceWavelengthNm, other.plane_width_mm);
    EXPECT_NE(std::memcmp(a.data.data(), c.data.data(), a.data.size() * sizeof(a.data[0])), 0);
}

TEST(EyeGeometry, SameSeedSameGeometryAndComponentsDrawIndependently) {
    EyeModel eye;
    eye.eyelashes.enabled = true;
    const EyeGeometry a = eye_geometry(eye), b = eye_geometry(eye);
    ASSERT_EQ(a.discs.size(), 640u);  // 600 lens + 40 vitreous particles
    ASSERT_EQ(a.lines.size(), 132u);  // 120 grating lines + 12 eyelashes
    for (std::size_t k = 0; k < a.discs.size(); ++k) EXPECT_EQ(a.discs[k].centre_mm, b.discs[k].centre_mm);
    for (std::size_t k = 0; k < a.lines.size(); ++k) EXPECT_EQ(a.lines[k].b_mm, b.lines[k].b_mm);

    // Switching the gratings off leaves the particles where they were.
    EyeModel no_gratings = eye;
    no_gratings.gratings.enabled = false;
    const EyeGeometry c = eye_geometry(no_gratings);
    ASSERT_EQ(c.discs.size(), a.discs.size());
    for (std::size_t k = 0; k < a.discs.size(); ++k) EXPECT_EQ(a.discs[k].centre_mm, c.discs[k].centre_mm);
}

// ---- obstacles ---------------------------------------------------------------

TEST(PupilPlane, EveryObstacleReducesTheEnergy) {
    const int n = 512;
    const double w = 18.0;
    const EyeModel clear = EyeModel::clear_pupil(5.0);
    const double e_clear = energy_mm2(pupil_plane(clear, n, kReferenceWavelengthNm, w), w);
    const EyeModel defaults;
    auto with = [&](auto set) {
        EyeModel e = clear;
        set(e);
        return energy_mm2(pupil_plane(e, n, kReferenceWavelengthNm, w), w);
    };
    EXPECT_LT(with([&](EyeModel& e) { e.gratings = defaults.gratings; }), e_clear * 0.999);
    EXPECT_LT(with([&](EyeModel& e) { e.lens_particles = defaults.lens_particles; }), e_clear * 0.99);
    EXPECT_LT(with([&](EyeModel& e) { e.vitreous_particles = defaults.vitreous_particles; }), e_clear * 0.99);
    EXPECT_LT(with([&](EyeModel& e) { e.eyelashes.enabled = true; }), e_clear * 0.995);
    EXPECT_LT(with([&](EyeModel& e) { e.eyelid = Eyelid{true, 1.0}; }), e_clear * 0.9);
}

TEST(PupilPlane, ParticlesBlockTheirArea) {
    // Discs wholly inside the pupil (spread radius 1.5 mm + 22.5 µm < 2 mm)
    // block Σ opacity · π r² minus their overlaps (a few % at this density).
    const int n = 1024;
    const double w = 18.0;
    EyeModel eye = EyeModel::clear_pupil(4.0);
    eye.lens_particles = EyeModel{}.lens_particles;
    eye.lens_particles.spread_radius_mm = 1.5;
    double blocked_sum = 0;
    for (const auto& d : eye_geometry(eye).discs) {
        ASSERT_LE(std::hypot(d.centre_mm.x, d.centre_mm.y), 1.5);
        blocked_sum += d.opacity * pi * d.radius_mm * d.radius_mm;
    }
    const double clear = area_mm2(pupil_plane(EyeModel::clear_pupil(4.0), n, kReferenceWavelengthNm, w), w);
    const double blocked = clear - area_mm2(pupil_plane(eye, n, kReferenceWavelengthNm, w), w);
    EXPECT_GT(blocked, 0.92 * blocked_sum);
    EXPECT_LT(blocked, 1.01 * blocked_sum);
}

TEST(PupilPlane, OverlappingOpacitiesMultiply) {
    // Two concentric 1 mm discs of opacity 0.5 (spread radius 0.1 µm): the
    // centre transmits 0.5 × 0.5 = 0.25; one disc alone transmits 0.5.
    EyeModel eye = EyeModel::clear_pupil(4.0);
    eye.vitreous_particles = Particles{true, 2, 1000.0, 0.0, 0.5, 1e-4};
    const int n = 256;
    EXPECT_NEAR(pupil_plane(eye, n, kReferenceWavelengthNm, 18.0).at(n / 2, n / 2).real(), 0.25, 1e-12);
    eye.vitreous_particles.count = 1;
    EXPECT_NEAR(pupil_plane(eye, n, kReferenceWavelengthNm, 18.0).at(n / 2, n / 2).real(), 0.5, 1e-12);
}

/// Dips (runs of |P| < 0.5) met walking once round a circle of radius r,
/// runs closer than `merge` samples joined; returns each dip's centre angle (rad).
std::vector<double> dips_on_circle(const ComplexImage<double>& p, double w, double r, int samples, int merge) {
    const int n = p.n;
    std::vector<bool> low(static_cast<std::size_t>(samples));
    for (int k = 0; k < samples; ++k) {
        const double phi = 2 * pi * k / samples;
        const int i = static_cast<int>(std::floor(r * std::cos(phi) / (w / n) + n / 2.0));
        const int j = static_cast<int>(std::floor(r * std::sin(phi) / (w / n) + n / 2.0));
        low[static_cast<std::size_t>(k)] = std::abs(p.at(i, j)) < 0.5;
    }
    // Start at a high sample so no run wraps.
    int start = 0;
    while (start < samples && low[static_cast<std::size_t>(start)]) ++start;
    std::vector<std::pair<int, int>> runs;  // [first, last] in unwrapped sample index
    for (int m = 0; m < samples; ++m) {
        const int k = start + m;
        if (!low[static_cast<std::size_t>(k % samples)]) continue;
        if (!runs.empty() && k - runs.back().second <= merge)
            runs.back().second = k;
        else
            runs.push_back({k, k});
    }
    std::vector<double> centres;
    for (auto [a, b] : runs) centres.push_back(2 * pi * (0.5 * (a + b)) / samples);
    return centres;
}

TEST(PupilPlane, GratingsHaveCountLinesAtTheirAngles) {
    const int n = 1024;
    const double w = 18.0;
    EyeModel eye = EyeModel::clear_pupil(8.0);
    eye.gratings = LensGratings{true, 120, 1.6, 30.0, 1.0, 0.0};
    const double period = 2 * pi / 120;

    // Walk a circle between the inner radius (1.6) and the pupil edge (4).
    auto p = pupil_plane(eye, n, kReferenceWavelengthNm, w);
    std::vector<double> dips = dips_on_circle(p, w, 3.0, 7200, 12);
    ASSERT_EQ(dips.size(), 120u);
    // No jitter: line k lies at 2πk/120 (within 0.3°: the walk steps 0.05° and a
    // texel spans 0.34° at r = 3 mm; the period is 3°).
    for (double phi : dips) {
        const double off = std::remainder(phi, period);
        EXPECT_LT(std::abs(off), 0.3 * pi / 180) << phi * 180 / pi;
    }
    // Inside the inner radius there are no lines.
    EXPECT_EQ(dips_on_circle(p, w, 1.4, 7200, 12).size(), 0u);

    // With jitter 0.25 each line stays within ±period/8 of its slot.
    eye.gratings.angle_jitter = 0.25;
    p = pupil_plane(eye, n, kReferenceWavelengthNm, w);
    dips = dips_on_circle(p, w, 3.0, 7200, 12);
    ASSERT_EQ(dips.size(), 120u);
    double largest = 0;
    for (double phi : dips) largest = std::max(largest, std::abs(std::remainder(phi, period)));
    EXPECT_LT(largest, period / 8 + 0.3 * pi / 180);
    EXPECT_GT(largest, 0.02 * period);  // the jitter moved them
}

TEST(EyeGeometry, GratingLinesStartAtTheInnerRadius) {
    EyeModel eye;
    eye.lens_particles.enabled = eye.vitreous_particles.enabled = false;
    const EyeGeometry g = eye_geometry(eye);
    ASSERT_EQ(g.lines.size(), 120u);
    const double period = 2 * pi / 120;
    for (std::size_t k = 0; k < g.lines.size(); ++k) {
        const auto& l = g.lines[k];
        EXPECT_NEAR(std::hypot(l.a_mm.x, l.a_mm.y), 1.6, 1e-12);
        EXPECT_GE(std::hypot(l.b_mm.x, l.b_mm.y), 9.0);  // out to the plane's edge
        EXPECT_NEAR(l.width_mm, 0.012, 1e-15);
        EXPECT_EQ(l.opacity, 0.35);
        const double off = std::remainder(std::atan2(l.a_mm.y, l.a_mm.x) - period * static_cast<double>(k), 2 * pi);
        EXPECT_LE(std::abs(off), 0.125 * period + 1e-12);
    }
}

TEST(EyeGeometry, ParticlesFillTheMeanPupil) {
    EyeModel eye;  // spread radius 0 -> the mean pupil radius, 2 mm
    eye.gratings.enabled = false;
    const EyeGeometry g = eye_geometry(eye);
    ASSERT_EQ(g.discs.size(), 640u);
    int inner_half = 0;
    for (std::size_t k = 0; k < g.discs.size(); ++k) {
        const auto& d = g.discs[k];
        const double r = std::hypot(d.centre_mm.x, d.centre_mm.y);
        EXPECT_LE(r, 2.0);
        const double d0 = k < 600 ? 30.0 : 150.0;
        EXPECT_GE(2 * d.radius_mm, 0.5 * d0 * 1e-3 - 1e-15);
        EXPECT_LE(2 * d.radius_mm, 1.5 * d0 * 1e-3 + 1e-15);
        if (r < std::sqrt(2.0)) ++inner_half;  // half the disc's area
    }
    // Uniform in area: about half of 640 (binomial σ ≈ 12.6) within r/√2.
    EXPECT_NEAR(inner_half, 320, 60);
}

TEST(PupilPlane, EyelidCutsTheTopOfThePupil) {
    const int n = 512;
    const double w = 18.0, h = w / n, edge = 1.0, r = 3.0;
    EyeModel eye = EyeModel::clear_pupil(2 * r);
    eye.eyelid = Eyelid{true, edge};
    const auto p = pupil_plane(eye, n, kReferenceWavelengthNm, w);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double x = centre_mm(i, n, w), y = centre_mm(j, n, w);
            if (y > edge + h) {
                ASSERT_EQ(p.at(i, j), std::complex<double>(0.0)) << i << "," << j;
            } else if (y < edge - h && std::hypot(x, y) < r - h) {
                ASSERT_EQ(p.at(i, j), std::complex<double>(1.0)) << i << "," << j;
            }
        }
    // The disc less the segment above y = e: π r² - (r² acos(e/r) - e √(r² - e²))
    // = 28.274333882 - (9 × 1.230959417 - 2.828427125) = 20.024126.
    EXPECT_NEAR(area_mm2(p, w), 20.024126, 0.005 * 20.024126);
}

TEST(PupilPlane, EyelashesHangFromTheTopDownToTheirReach) {
    const int n = 512;
    const double w = 18.0, h = w / n, reach = 1.0;
    EyeModel eye = EyeModel::clear_pupil(6.0);
    eye.eyelashes = Eyelashes{true, 12, 80.0, reach, 15.0};
    const EyeGeometry g = eye_geometry(eye);
    ASSERT_EQ(g.lines.size(), 12u);
    for (const auto& l : g.lines) {
        EXPECT_EQ(l.a_mm.y, 9.0);
        EXPECT_EQ(l.b_mm.y, reach);
        EXPECT_LE(std::abs(l.b_mm.x - l.a_mm.x), 8.0 * std::tan(15.0 * pi / 180) + 1e-12);
        EXPECT_LE(std::abs(l.a_mm.x), 9.0);
    }
    const auto p = pupil_plane(eye, n, kReferenceWavelengthNm, w);
    const auto clear = pupil_plane(EyeModel::clear_pupil(6.0), n, kReferenceWavelengthNm, w);
    // Below the tips (less the half width), nothing changes.
    for (int j = 0; j < n; ++j) {
        if (centre_mm(j, n, w) + h > reach - 0.04) continue;
        for (int i = 0; i < n; ++i) ASSERT_EQ(p.at(i, j), clear.at(i, j)) << i << "," << j;
    }
    EXPECT_LT(area_mm2(p, w), area_mm2(clear, w) * 0.99);
}

// ---- scale and validation ------------------------------------------------------------

TEST(AngularScale, DefaultsPutTheHalosBrightestRingAtFourDegrees) {
    // two_scales: the ring the gratings at the pupil's edge (r = p/2 = 2 mm)
    // diffract λ0 to, λ0 count / (2π r), moves to 4°.
    const EyeModel eye;
    const double s = (4.0 * pi / 180.0) / (575e-6 * 120.0 / (2 * pi * 2.0));
    EXPECT_NEAR(angular_scale(eye), s, 1e-12 * s);
    EXPECT_NEAR(angular_scale(eye), 12.714, 0.001);  // by hand: 0.0698132 / 0.0054910
    EXPECT_NEAR(psf_degrees_per_texel(eye), s * 575e-6 / 18.0 * 180.0 / pi, 1e-15);
    // The core stays physical.
    EXPECT_NEAR(core_degrees_per_texel(eye), 575e-6 / 18.0 * 180.0 / pi, 1e-15);
    // A pupil that does not reach the gratings: their inner radius sets the ring.
    EyeModel small = eye;
    small.pupil_diameter_mm = 3.0;
    EXPECT_NEAR(angular_scale(small), (4.0 * pi / 180.0) / (575e-6 * 120.0 / (2 * pi * 1.6)), 1e-9);

    EyeModel off = eye;
    off.gratings.enabled = false;
    EXPECT_EQ(angular_scale(off), 1.0);
    off = eye;
    off.halo_radius_deg = std::nullopt;
    EXPECT_EQ(angular_scale(off), 1.0);
    EXPECT_NEAR(psf_degrees_per_texel(off), 575e-6 / 18.0 * 180.0 / pi, 1e-15);
}

TEST(AngularScale, K2012PresetPutsTheHaloEdgeAtFourDegreesAndStretchesTheCore) {
    const EyeModel eye = EyeModel::k2012();
    EXPECT_EQ(eye.scale, EyeScale::k2012_single);
    EXPECT_DOUBLE_EQ(eye.defocus_diopters, 0.2);  // K2012 eq 4.6's E at d = 5000 mm
    // s = 4° (in rad) / (λ0 count / (2π r_inner)), λ0 = 575e-6 mm.
    const double s = (4.0 * pi / 180.0) / (575e-6 * 120.0 / (2 * pi * 1.6));
    EXPECT_NEAR(angular_scale(eye), s, 1e-12 * s);
    EXPECT_NEAR(angular_scale(eye), 10.171, 0.001);  // by hand: 0.0698132 / 0.0068638
    EXPECT_NEAR(core_degrees_per_texel(eye), psf_degrees_per_texel(eye), 1e-15);
    EXPECT_TRUE(eye_preset("k2012").has_value());
    EXPECT_EQ(eye_preset("focused")->scale, EyeScale::two_scales);
    EXPECT_FALSE(eye_preset("k2013").has_value());
}

TEST(Validate, DefaultsAreValidAtTheSizesWeUse) {
    const EyeModel eye;
    EXPECT_NO_THROW(eye.validate(512));
    EXPECT_NO_THROW(eye.validate(1024));
    EXPECT_NO_THROW(EyeModel::clear_pupil(4.0).validate(64));
}

/// The what() of validate(n) after `change`, for checking the key it names.
template <class F>
std::string error_after(F change, int n = 512) {
    EyeModel eye;
    change(eye);
    return input_error_of([&] { eye.validate(n); });
}

#define EXPECT_KEY(what, key) EXPECT_NE((what).find("key '" key "'"), std::string::npos) << (what)

TEST(Validate, ErrorsNameTheKey) {
    EXPECT_KEY(error_after([](EyeModel& e) { e.pupil_diameter_mm = 0; }), "pupil_diameter_mm");
    EXPECT_KEY(error_after([](EyeModel& e) { e.pupil_diameter_mm = std::nan(""); }), "pupil_diameter_mm");
    EXPECT_KEY(error_after([](EyeModel& e) { e.pupil_diameter_mm = 9.01; }), "pupil_diameter_mm");
    EXPECT_KEY(error_after([](EyeModel& e) { e.gratings.count = -1; }), "gratings.count");
    EXPECT_KEY(error_after([](EyeModel& e) { e.gratings.opacity = 1.5; }), "gratings.opacity");
    EXPECT_KEY(error_after([](EyeModel& e) { e.gratings.width_um = -1; }), "gratings.width_um");
    EXPECT_KEY(error_after([](EyeModel& e) { e.lens_particles.diameter_um = -1; }), "lens_particles.diameter_um");
    EXPECT_KEY(error_after([](EyeModel& e) { e.vitreous_particles.opacity = -0.1; }), "vitreous_particles.opacity");
    EXPECT_KEY(error_after([](EyeModel& e) { e.vitreous_particles.count = -3; }), "vitreous_particles.count");
    EXPECT_KEY(error_after([](EyeModel& e) { e.eyelashes.count = -1; }), "eyelashes.count");
    EXPECT_KEY(error_after([](EyeModel& e) { e.plane_width_mm = 0; }), "plane_width_mm");
    EXPECT_KEY(error_after([](EyeModel& e) { e.supersampling = 0; }), "supersampling");
    EXPECT_KEY(error_after([](EyeModel& e) { e.defocus_diopters = std::nan(""); }), "defocus_diopters");
    EXPECT_KEY(error_after([](EyeModel& e) { e.halo_radius_deg = -4.0; }), "halo_radius_deg");
    EXPECT_KEY(error_after([](EyeModel&) {}, 300), "size");
    EXPECT_KEY(error_after([](EyeModel&) {}, 0), "size");
    // The gratings' physical ring is 0.31° for the default 4 mm pupil: the two-scale eye cannot shrink it.
    EXPECT_KEY(error_after([](EyeModel& e) { e.halo_radius_deg = 0.2; }), "halo_radius_deg");
    // 1000/24 mm = 41.7 D (the anatomical eye's Fresnel distance) cannot be sampled.
    EXPECT_KEY(error_after([](EyeModel& e) { e.defocus_diopters = -1000.0 / 24; }), "defocus_diopters");
}

TEST(Validate, PupilMayFillHalfThePlane) {
    EXPECT_NO_THROW(EyeModel::clear_pupil(9.0).validate(512));
    EXPECT_THROW(EyeModel::clear_pupil(9.01).validate(512), InputError);
}

TEST(Validate, HippusMaximumCountsAgainstThePlane) {
    // W = 16: p = 7.8 fits (≤ 8), but hippus at amplitude 1 swings it by
    // (9/7.8) √(1 - 7.8/9) = 1.1538462 × 0.3651484 = 0.4213250 to 8.221 > 8.
    EyeModel eye = EyeModel::clear_pupil(7.8);
    eye.plane_width_mm = 16.0;
    EXPECT_NO_THROW(eye.validate(512));
    eye.hippus = Hippus{true, 1.0, 9.0};
    EXPECT_KEY(input_error_of([&] { eye.validate(512); }), "pupil_diameter_mm");
    eye.hippus.amplitude = 0.4;  // 7.8 + 0.168530 = 7.9685 fits
    EXPECT_NO_THROW(eye.validate(512));
}

TEST(Validate, DefocusStepLimitIsPiAtThePupilEdge) {
    // step = 2π |ΔD| (p/2)(W/n) / λ0 ≤ π  <=>  |ΔD| ≤ n λ0 / (p W)
    // = 512 × 575e-9 / (4e-3 × 18e-3) = 4.0889 D for the default 4 mm pupil, either sign.
    EyeModel eye;
    EXPECT_NEAR(max_defocus_diopters(eye, 512), 4.0889, 1e-4);
    for (double sign : {1.0, -1.0}) {
        eye.defocus_diopters = sign * 4.08;
        EXPECT_NO_THROW(eye.validate(512));
        eye.defocus_diopters = sign * 4.10;
        const std::string what = input_error_of([&] { eye.validate(512); });
        EXPECT_KEY(what, "defocus_diopters");
        // The sentence says why: the phase step, and the blur disc against the grid.
        EXPECT_NE(what.find("more than π between texels"), std::string::npos) << what;
        EXPECT_NO_THROW(eye.validate(1024));  // half the texel: the limit doubles
    }
    eye.defocus_diopters = 0;  // in focus: no limit
    EXPECT_NO_THROW(eye.validate(16));
}

TEST(PupilPlane, ValidatesItsInputs) {
    const EyeModel eye;
    EXPECT_KEY(input_error_of([&] { pupil_plane(eye, 100, 575.0, 18.0); }), "size");
    EXPECT_KEY(input_error_of([&] { pupil_plane(eye, 128, 0.0, 18.0); }), "wavelength_nm");
    EXPECT_KEY(input_error_of([&] { pupil_plane(eye, 128, 575.0, -1.0); }), "plane_width_mm");
}

// ---- hippus ----------------------------------------------------------------------

TEST(Hippus, OffGivesTheMeanPupil) {
    const EyeModel eye;
    EXPECT_EQ(pupil_diameter_mm_at(eye, 0.0), 4.0);
    EXPECT_EQ(pupil_diameter_mm_at(eye, 123.4), 4.0);
}

TEST(Hippus, StaysWithinItsSwingAndIsSmoothAndSeeded) {
    EyeModel eye;
    eye.hippus = Hippus{true, 0.1, 9.0};
    // swing = 0.1 × (9/4) × √(1 - 4/9) = 0.225 × 0.7453560 = 0.1677051 mm.
    const double swing = 0.1677051;
    double lo = 1e9, hi = -1e9, steepest = 0;
    bool differs = false;
    EyeModel other = eye;
    other.seed = 7;
    for (double t = -30.0; t < 600.0; t += 0.05) {
        const double p = pupil_diameter_mm_at(eye, t);
        ASSERT_GE(p, 4.0 - swing - 1e-7) << t;
        ASSERT_LE(p, 4.0 + swing + 1e-7) << t;
        lo = std::min(lo, p);
        hi = std::max(hi, p);
        steepest = std::max(steepest, std::abs(pupil_diameter_mm_at(eye, t + 1e-3) - p));
        EXPECT_EQ(p, pupil_diameter_mm_at(eye, t));  // deterministic
        differs = differs || p != pupil_diameter_mm_at(other, t);
    }
    // It moves over a good part of its range ...
    EXPECT_GT(hi - lo, 0.5 * swing);
    // ... smoothly: the noise's slope is at most 3 × 15/8 × 2 / 1.75 = 6.43 per
    // unit of t/p, so over 1 ms: 6.43 × 0.001/4 × 0.168 = 2.7e-4 mm.
    EXPECT_LT(steepest, 2.7e-4);
    EXPECT_GT(steepest, 0.0);
    EXPECT_TRUE(differs);  // another seed, another pupil
}

TEST(Hippus, ClampedToASaneRange) {
    EyeModel eye = EyeModel::clear_pupil(2.0);
    eye.hippus = Hippus{true, 50.0, 9.0};  // absurd amplitude
    for (double t = 0; t < 200.0; t += 0.1) {
        const double p = pupil_diameter_mm_at(eye, t);
        EXPECT_GE(p, 1.0);  // never below half the mean
        EXPECT_LE(p, 9.0);  // never above max(p, p_max)
    }
    // A pupil at or above p_max does not fluctuate: √(1 - p/p_max) is 0 or imaginary.
    eye.pupil_diameter_mm = 9.0;
    EXPECT_EQ(pupil_diameter_mm_at(eye, 3.3), 9.0);
}

TEST(Hippus, RefusesWhatEq47CannotUse) {
    EyeModel eye;
    eye.hippus.enabled = true;
    EXPECT_KEY(input_error_of([&] { pupil_diameter_mm_at(eye, std::nan("")); }), "time_s");
    eye.pupil_diameter_mm = 0;
    EXPECT_KEY(input_error_of([&] { pupil_diameter_mm_at(eye, 1.0); }), "pupil_diameter_mm");
}

TEST(Hippus, PupilPlaneFollowsTheHippusDiameter) {
    EyeModel eye = EyeModel::clear_pupil(4.0);
    eye.hippus = Hippus{true, 0.5, 9.0};
    const double t = 17.25;
    const double d = pupil_diameter_mm_at(eye, t);
    ASSERT_GT(std::abs(d - 4.0), 0.01);  // this instant is off the mean
    const auto p = pupil_plane(eye, 512, kReferenceWavelengthNm, 18.0, t);
    EXPECT_NEAR(area_mm2(p, 18.0), pi * d * d / 4, 0.003 * pi * d * d / 4);
}

}  // namespace
