// Numerical stress tests of the light's path to the eye (issue 8): Bouguer's fog
// (K2012 eq 4.14), the emission profiles (eq 4.1-4.4), the rhythms, the light model
// E = I·rgb·P_v·P_h·B(t)·T(d)/d² and the footprint on the pixel grid (eq 4.5), each
// swept over its whole domain — distances 0.1 m … 50 km, intensities 0 … 1e7 cd,
// times 0 … 10 years, every direction — with fixed-seed random inputs plus the
// singular points by name. Every result must be finite; transmittance, illuminance
// and footprint area must not increase with distance. docs/numerical-behaviour.md
// lists the singular points and what each stage does there.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/gtc/quaternion.hpp>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "atonlab/stimuli/atmosphere.h"
#include "atonlab/display/colour.h"
#include "atonlab/stimuli/footprint.h"
#include "atonlab/stimuli/light_model.h"
#include "atonlab/stimuli/profile.h"
#include "atonlab/stimuli/rhythm.h"

namespace atonlab::stimuli {
using namespace atonlab::display;  // colour science, the tone-mapping CPU reference (display/)
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kDenorm = std::numeric_limits<double>::denorm_min();

/// n values log-uniform over [lo, hi] (both > 0), sorted, both ends included.
std::vector<double> log_sweep(double lo, double hi, int n) {
    std::vector<double> v;
    for (int i = 0; i < n; ++i) v.push_back(lo * std::pow(hi / lo, static_cast<double>(i) / (n - 1)));
    v.back() = hi;
    return v;
}

/// Distances 0.1 m … 50 km: a log grid plus fixed-seed random draws, sorted.
std::vector<double> distances_m(std::uint32_t seed) {
    std::vector<double> d = log_sweep(0.1, 5e4, 400);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(std::log(0.1), std::log(5e4));
    for (int i = 0; i < 400; ++i) d.push_back(std::exp(u(rng)));
    std::sort(d.begin(), d.end());
    return d;
}

// ---------------------------------------------------------------------------
// Bouguer's law, K2012 eq 4.14.

TEST(StressAtmosphere, BouguerTransmittanceNonIncreasingFromZeroToFiftyKilometres) {
    // Koschmieder: T(d) = 0.05^(d/V) for the extinction of visibility V. Visibilities from
    // 1 m (thick fog) to 1000 km, and a clear atmosphere (σ = 0, T = 1 everywhere).
    std::vector<double> d = distances_m(81);
    d.insert(d.begin(), 0.0);
    long checked = 0;
    for (double vis_m : {1.0, 10.0, 100.0, 1852.0, 18520.0, 1e6, kInf}) {
        const double sigma = std::isinf(vis_m) ? 0.0 : extinction_per_m_from_visibility_m(vis_m);
        double prev = 1.0;
        for (double dist : d) {
            const double t = bouguer_transmittance(sigma, dist);
            ASSERT_TRUE(std::isfinite(t) && t >= 0.0 && t <= 1.0) << "V " << vis_m << " d " << dist << ": " << t;
            ASSERT_LE(t, prev) << "V " << vis_m << " d " << dist;
            // An independent form of the same law (Allard's 0.05^(d/V)); far below the
            // smallest normal double both are 0.
            const double expected = std::isinf(vis_m) ? 1.0 : std::pow(0.05, dist / vis_m);
            ASSERT_NEAR(t, expected, 1e-12 * expected + 1e-300) << "V " << vis_m << " d " << dist;
            prev = t;
            ++checked;
        }
        EXPECT_EQ(bouguer_transmittance(sigma, 0.0), 1.0) << "V " << vis_m;
    }
    std::printf("Bouguer: %ld (visibility, distance) pairs finite, in [0, 1] and non-increasing\n", checked);
}

TEST(StressAtmosphere, BouguerSingularPointsAreFinite) {
    // d = 0 means no path through the fog: T = 1 whatever σ, including σ = ∞ (visibility
    // 0), where exp(-σ·d) would be exp(-∞·0) = NaN.
    EXPECT_EQ(bouguer_transmittance(kInf, 0.0), 1.0);
    EXPECT_EQ(bouguer_transmittance(1e300, 0.0), 1.0);
    EXPECT_EQ(bouguer_transmittance(kInf, 0.1), 0.0);
    EXPECT_EQ(bouguer_transmittance(1e300, 1e300), 0.0);
    EXPECT_EQ(bouguer_transmittance(0.0, 1e300), 1.0);
    EXPECT_EQ(bouguer_transmittance(kDenorm, kDenorm), 1.0);
    // Visibility -> 0: σ = ln 20 / V overflows to +∞ at the smallest double (never NaN), and
    // that σ still gives T(0) = 1 and T(d > 0) = 0. Visibility ∞: σ = 0, T = 1.
    const double sigma = extinction_per_m_from_visibility_m(kDenorm);
    EXPECT_EQ(sigma, kInf);
    EXPECT_EQ(bouguer_transmittance(sigma, 0.0), 1.0);
    EXPECT_EQ(bouguer_transmittance(sigma, 1e-3), 0.0);
    EXPECT_EQ(extinction_per_m_from_visibility_m(kInf), 0.0);
}

TEST(StressAtmosphere, AllardRangeNonDecreasingInIntensityOverSeventeenDecades) {
    // More light is seen at least as far, at every visibility, random intensities 1e-7 … 1e10 cd.
    std::mt19937 rng(82);
    std::uniform_real_distribution<double> u(-7.0, 10.0);
    std::vector<double> intensities(600);
    for (double& i : intensities) i = std::pow(10.0, u(rng));
    intensities.push_back(0.0);
    intensities.push_back(1e7);
    std::sort(intensities.begin(), intensities.end());
    for (double vis : {1e-3, 0.1, 1.0, 10.0, 100.0, kInf}) {
        for (double threshold : {allard_threshold_night_lux, allard_threshold_day_lux}) {
            double prev = 0.0;
            for (double i : intensities) {
                const double r = allard_range_nmi(i, threshold, vis);
                ASSERT_TRUE(std::isfinite(r) && r >= 0.0) << "I " << i << " V " << vis;
                ASSERT_GE(r, prev * (1.0 - 1e-14)) << "I " << i << " V " << vis;
                prev = r;
            }
        }
    }
}

// ---------------------------------------------------------------------------
// Emission profiles, K2012 eq 4.1-4.4.

TEST(StressProfile, VerticalProfileFiniteAndWithinItsTableForEveryCosTheta) {
    // The lookup clamps p to [0, 1] (NaN -> 0): it never leaves the table's range.
    std::mt19937 rng(83);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const std::vector<double> elev = {-90, -20, -10, 0, 10, 20, 90}, rel = {0, 0.1, 0.5, 1, 0.5, 0.1, 0};
    const std::vector<VerticalProfile> profiles = {VerticalProfile::uniform(), sabik_vp_vertical_profile(),
                                                   VerticalProfile::from_elevation_table(elev, rel),
                                                   VerticalProfile::from_elevation_table(elev, rel, 2)};
    std::vector<double> cosines = {-1.0,
                                   -0.0,
                                   0.0,
                                   1.0,
                                   std::nextafter(1.0, 2.0),
                                   std::nextafter(-1.0, -2.0),
                                   kDenorm,
                                   -kDenorm,
                                   1e300,
                                   -1e300,
                                   kInf,
                                   -kInf,
                                   std::nan("")};
    for (int i = 0; i < 5000; ++i) cosines.push_back(u(rng));
    for (const VerticalProfile& v : profiles) {
        const auto [lo, hi] = std::minmax_element(v.table.begin(), v.table.end());
        for (double c : cosines) {
            const double p = v.at_cos_theta(c);
            ASSERT_TRUE(std::isfinite(p)) << c;
            ASSERT_GE(p, *lo) << c;
            ASSERT_LE(p, *hi) << c;
        }
        // The ends: straight down and straight up are the first and last entries exactly.
        EXPECT_EQ(v.at_cos_theta(-1.0), v.table.front());
        EXPECT_EQ(v.at_cos_theta(1.0), v.table.back());
        EXPECT_EQ(v.at_cos_theta(std::nan("")), v.table.front());  // documented: NaN p -> 0
    }
}

TEST(StressProfile, HorizontalProfileFiniteForBearingsFarOutsideOneTurn) {
    // Sectors with soft edges, one through north. Any real bearing wraps into [0, 360);
    // non-finite bearings read the 0° entry. Periodic to rounding for |b| up to 1e6 turns.
    const std::vector<Sector> sectors = {{20, 110, 1.0, 3.0}, {200, 260, 0.6, 1.0}, {330, 30, 0.8, 5.0}};
    const HorizontalProfile h = HorizontalProfile::from_sectors(sectors);
    std::mt19937 rng(84);
    std::uniform_real_distribution<double> u(0.0, 360.0);
    std::vector<double> specials = {
        0.0,  -0.0,  -kDenorm, kDenorm, -1e-300, 360.0, -360.0,      std::nextafter(360.0, 0.0),
        1e15, -1e15, 1e300,    -1e300,  kInf,    -kInf, std::nan("")};
    for (double b : specials) {
        const double v = h.at_bearing_deg(b);
        ASSERT_TRUE(std::isfinite(v) && v >= 0.0 && v <= 1.0) << b;
    }
    EXPECT_EQ(h.at_bearing_deg(kInf), h.at_bearing_deg(0.0));
    EXPECT_EQ(h.at_bearing_deg(std::nan("")), h.at_bearing_deg(0.0));
    for (int i = 0; i < 3000; ++i) {
        const double b = u(rng);
        const double ref = h.at_bearing_deg(b);
        ASSERT_TRUE(std::isfinite(ref) && ref >= 0.0 && ref <= 1.0);
        for (double turns : {-1e6, -1.0, 1.0, 1e3, 1e6}) {
            // b + 360·turns rounds by up to ulp(3.6e8) = 6e-8° at 1e6 turns; the steepest
            // slope (1/1° sector edge) turns that into 6e-8.
            ASSERT_NEAR(h.at_bearing_deg(b + 360.0 * turns), ref, 1e-6) << b << " + " << turns << " turns";
        }
    }
}

TEST(StressProfile, BearingOfEveryDirectionIsInZeroTo360) {
    std::mt19937 rng(85);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const double vals[] = {0.0, -0.0, kDenorm, -kDenorm, 1e-300, -1e-300, 1.0, -1.0, 1e300, -1e300};
    auto check = [](double x, double z) {
        const double b = bearing_deg_of_direction(x, z);
        ASSERT_TRUE(std::isfinite(b) && b >= 0.0 && b < 360.0) << x << ", " << z << " -> " << b;
    };
    for (double x : vals)
        for (double z : vals) check(x, z);
    for (int i = 0; i < 5000; ++i) check(u(rng), u(rng));
    EXPECT_EQ(bearing_deg_of_direction(0.0, 0.0), 0.0);    // straight up or down: documented 0
    EXPECT_EQ(bearing_deg_of_direction(-0.0, -0.0), 0.0);  // signed zeros too
}

TEST(StressProfile, SabikVpNonIncreasingAwayFromTheHorizontal) {
    // K2012 §2.3's lantern: brightest in the horizontal plane, symmetric, falling to
    // either pole; positive (no underflow to a black pole) and ≤ 1 everywhere.
    double prev = 2.0;
    for (int i = 0; i <= 9000; ++i) {
        const double e = i * 0.01;
        const double up = sabik_vp_relative_intensity(e), down = sabik_vp_relative_intensity(-e);
        ASSERT_TRUE(std::isfinite(up) && up > 0.0 && up <= 1.0) << e;
        ASSERT_EQ(up, down) << e;
        ASSERT_LE(up, prev) << e;
        prev = up;
    }
    EXPECT_EQ(sabik_vp_relative_intensity(0.0), 1.0);
}

// ---------------------------------------------------------------------------
// Rhythms.

const char* const kCharacters[] = {"F",        "Fl 5s",     "Fl(2) 10s",    "Oc(2+1) 12s",
                                   "Al.WR 4s", "Mo(U) 15s", "Q(6)+LFl 15s", "VQ(3) 5s",
                                   "UQ",       "Iso 2s",    "LFl 10s",      "Oc 3s"};

TEST(StressRhythm, LevelInUnitIntervalFromTimeZeroToTenYears) {
    // B(t) for every kind of character at random times over 0 … 3.2e8 s (ten years of
    // simulation), log-uniform so every scale is met, plus the period boundaries exactly.
    std::mt19937 rng(86);
    std::uniform_real_distribution<double> u(-3.0, std::log10(3.2e8));
    long checked = 0;
    for (const char* text : kCharacters) {
        const Rhythm r = parse_rhythm(text);
        std::vector<double> times = {0.0,   -0.0, kDenorm, r.period_s, -r.period_s, std::nextafter(r.period_s, 0.0),
                                     3.2e8, 1e9,  -1e9,    1e17 + 16};
        for (int i = 0; i < 2000; ++i) times.push_back(std::pow(10.0, u(rng)));
        for (std::size_t c = 0; c < r.channels.size(); ++c) {
            for (double t : times) {
                const double b = r.level(t, c);
                ASSERT_TRUE(std::isfinite(b) && b >= 0.0 && b <= 1.0) << text << " t " << t << " -> " << b;
                ++checked;
            }
        }
    }
    std::printf("rhythms: %ld levels finite and in [0, 1]\n", checked);
}

TEST(StressRhythm, PeriodicOverAMillionPeriods) {
    // B(t + kP) = B(t) while t + kP still resolves the ramps: at k = 1e6 and P = 15 s,
    // t + kP ≈ 1.5e7 s has an ulp of 1.9e-9 s, which a 20 ms ramp turns into 1e-7.
    std::mt19937 rng(87);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (const char* text : kCharacters) {
        const Rhythm r = parse_rhythm(text);
        if (r.period_s == 0) continue;
        for (int i = 0; i < 300; ++i) {
            const double t = u(rng) * r.period_s;
            for (double k : {1.0, 1e3, 1e6}) {
                ASSERT_NEAR(r.level(t + k * r.period_s), r.level(t), 1e-6) << text << " t " << t << " k " << k;
            }
        }
    }
}

// ---------------------------------------------------------------------------
// The light model at the eye.

TEST(StressLightModel, IlluminanceNonIncreasingFromTenCentimetresToFiftyKilometres) {
    // E = I·T(d)/d² along random directions (uniform profiles, fixed light), intensities
    // 0 … 1e7 cd, fog from none to 10 m visibility: finite, ≥ 0, never growing with d, and
    // equal to the closed form I·0.05^(d/V)/d².
    std::mt19937 rng(88);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const std::vector<double> dists = distances_m(89);
    const ProfileTables profiles;
    long checked = 0;
    for (double intensity : {0.0, 1e-3, 1.0, 250.0, 1e5, 1e7}) {
        for (double vis_m : {kInf, 18520.0, 1852.0, 10.0}) {
            const double sigma = std::isinf(vis_m) ? 0.0 : extinction_per_m_from_visibility_m(vis_m);
            for (int k = 0; k < 4; ++k) {
                const glm::dvec3 dir = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
                Light L;
                L.intensity_cd = intensity;
                L.rgb_per_cd = *iala_colour_rgb("red");
                double prev = kInf;
                for (double d : dists) {
                    L.position_m = dir * d;
                    const LightAtEye e = evaluate_light(L, profiles, glm::dvec3(0.0), 0.0, sigma);
                    const double lux = illuminance_lux(e);
                    ASSERT_TRUE(std::isfinite(lux) && lux >= 0.0) << "I " << intensity << " d " << d;
                    for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(e.illuminance_rgb_lux[c]));
                    ASSERT_LE(lux, prev * (1.0 + 1e-12)) << "I " << intensity << " V " << vis_m << " d " << d;
                    const double dd = glm::length(L.position_m);
                    const double expected =
                        intensity * (std::isinf(vis_m) ? 1.0 : std::pow(0.05, dd / vis_m)) / (dd * dd);
                    ASSERT_NEAR(lux, expected, 1e-10 * expected + 1e-300) << "I " << intensity << " d " << d;
                    if (intensity == 0.0) {
                        ASSERT_EQ(lux, 0.0);
                    }
                    prev = lux;
                    ++checked;
                }
            }
        }
    }
    std::printf("light model: %ld evaluations finite, non-increasing in distance, equal to I·T/d²\n", checked);
}

TEST(StressLightModel, LightAtTheEyeGivesZeroIlluminance) {
    // d = 0: the inverse-square law is singular; documented: zero illuminance, every factor 0.
    Light L;
    L.intensity_cd = 1e7;
    L.position_m = {12.0, 3.0, -7.0};
    const LightAtEye e = evaluate_light(L, ProfileTables{}, L.position_m, 0.0, 0.0);
    EXPECT_EQ(e.distance_m, 0.0);
    EXPECT_EQ(e.illuminance_rgb_lux, glm::dvec3(0.0));
    EXPECT_EQ(e.transmittance, 0.0);
    // Just outside: finite (1e7 cd at 1 µm is 1e19 lux), and in double down to ~1e-150 m.
    for (double d : {1e-6, 1e-30, 1e-150}) {
        L.position_m = {0.0, 0.0, -d};
        const LightAtEye n = evaluate_light(L, ProfileTables{}, glm::dvec3(0.0), 0.0, 1e-3);
        EXPECT_TRUE(std::isfinite(illuminance_lux(n))) << d;
        EXPECT_NEAR(illuminance_lux(n), 1e7 / (d * d), 1e-9 * 1e7 / (d * d)) << d;
    }
}

TEST(StressLightModel, EveryDirectionAroundASectoredLightIsFinite) {
    // Profiles looked up in light space from every direction (poles and the sector edges
    // included), at random orientations and times: every factor finite and in [0, 1].
    std::mt19937 rng(90);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    ProfileTables profiles;
    const std::vector<Sector> sectors = {{20, 110, 1.0, 3.0}, {330, 30, 0.8, 0.0}};
    profiles.horizontal.push_back(HorizontalProfile::from_sectors(sectors));
    profiles.vertical.push_back(sabik_vp_vertical_profile());
    const Rhythm rhythm = parse_rhythm("Q(6)+LFl 15s");
    Light L;
    L.intensity_cd = 1e7;
    L.horizontal_profile = 1;
    L.vertical_profile = 1;
    L.rhythm = rhythm.channels[0].knots;
    L.rhythm_period_s = rhythm.period_s;
    std::vector<glm::dvec3> dirs = {{0, 1, 0}, {0, -1, 0}, {1, 0, 0}, {0, 0, -1}, {0, 0, 1}, {-1, 0, 0}};
    for (int i = 0; i < 3000; ++i) dirs.push_back(glm::normalize(glm::dvec3(u(rng), u(rng), u(rng))));
    for (std::size_t i = 0; i < dirs.size(); ++i) {
        L.orientation = i % 2 ? glm::normalize(glm::dquat(u(rng), u(rng), u(rng), u(rng))) : glm::dquat(1, 0, 0, 0);
        L.position_m = -dirs[i] * 100.0;  // the eye sits at dirs[i] from the light
        const LightAtEye e = evaluate_light(L, profiles, glm::dvec3(0.0), 1e6 * (u(rng) + 1.0), 1e-4);
        for (double f : {e.vertical, e.horizontal, e.rhythm, e.transmittance}) {
            ASSERT_TRUE(std::isfinite(f) && f >= 0.0 && f <= 1.0) << i;
        }
        ASSERT_TRUE(std::isfinite(e.bearing_deg) && e.bearing_deg >= 0.0 && e.bearing_deg < 360.0);
        ASSERT_TRUE(std::isfinite(illuminance_lux(e)) && illuminance_lux(e) >= 0.0);
    }
}

// ---------------------------------------------------------------------------
// The footprint, K2012 eq 4.5 generalised (footprint.h).

constexpr double kFocalPx = 2880.0;
constexpr int kWidth = 320, kHeight = 240;

TEST(StressFootprint, LightAtCameraPositionIsNotVisible) {
    const Footprint fp = light_footprint(glm::dvec3(0.0), 0.1, kFocalPx, kWidth, kHeight);
    EXPECT_FALSE(fp.visible);
    EXPECT_EQ(fp.area_px2, 0.0);
    EXPECT_EQ(fp.radius_px, 0.0);
}

TEST(StressFootprint, LightExactlyBehindOrBesideTheCameraIsNotVisible) {
    // Behind (view z > 0) at every distance, and in the camera's plane (z = ±0): the
    // pinhole cannot image it; nothing is drawn and nothing is infinite.
    for (double d : log_sweep(0.1, 5e4, 200)) {
        for (const glm::dvec3 v : {glm::dvec3(0, 0, d), glm::dvec3(d, 0, 0), glm::dvec3(0, d, -0.0),
                                   glm::dvec3(-d, d, 0.0), glm::dvec3(0.3 * d, 0, d)}) {
            const Footprint fp = light_footprint(v, 0.01, kFocalPx, kWidth, kHeight);
            ASSERT_FALSE(fp.visible) << v.x << "," << v.y << "," << v.z;
            ASSERT_EQ(fp.area_px2, 0.0);
        }
    }
}

TEST(StressFootprint, EyeInsideTheLightSphereIsNotVisible) {
    // d <= radius: documented as not drawn (the eye is inside the lantern).
    for (double d : {0.0, 1e-9, 0.05, 0.1}) {
        const Footprint fp = light_footprint(glm::dvec3(0, 0, -d), 0.1, kFocalPx, kWidth, kHeight);
        EXPECT_FALSE(fp.visible) << d;
    }
    // Just outside: the sphere fills a hemisphere, 2π sr: a finite, huge disc.
    const Footprint fp = light_footprint(glm::dvec3(0, 0, -0.1000001), 0.1, kFocalPx, kWidth, kHeight);
    EXPECT_TRUE(fp.visible);
    EXPECT_TRUE(std::isfinite(fp.area_px2) && std::isfinite(fp.radius_px));
    EXPECT_NEAR(fp.area_px2, 2.0 * std::numbers::pi * kFocalPx * kFocalPx, 2e-3 * fp.area_px2);
}

TEST(StressFootprint, AreaNonIncreasingInDistanceAcrossTheSubPixelTransition) {
    // Radii 1 mm … 10 m, distances 0.1 m … 50 km, on the axis and 2° off it: the area is
    // finite and non-increasing, the disc/box switch happens at 1 px² exactly, the centre
    // is finite, and the solid angle tends to π r²/d².
    for (double radius : {0.001, 0.01, 0.1, 1.0, 10.0}) {
        for (double off_deg : {0.0, 2.0}) {
            const double a = off_deg * std::numbers::pi / 180.0;
            const glm::dvec3 dir(std::sin(a), 0.0, -std::cos(a));
            double prev = kInf;
            for (double d : distances_m(91)) {
                const Footprint fp = light_footprint(dir * d, radius, kFocalPx, kWidth, kHeight);
                if (-(dir * d).z <= radius) {  // the sphere reaches the camera's plane
                    ASSERT_FALSE(fp.visible);
                    continue;
                }
                ASSERT_TRUE(fp.visible);
                ASSERT_TRUE(std::isfinite(fp.area_px2) && fp.area_px2 > 0.0) << radius << " " << d;
                ASSERT_TRUE(std::isfinite(fp.centre_px.x) && std::isfinite(fp.centre_px.y));
                ASSERT_TRUE(std::isfinite(fp.radius_px));
                ASSERT_EQ(fp.disc, fp.area_px2 >= 1.0);
                ASSERT_LE(fp.area_px2, prev * (1.0 + 1e-12)) << radius << " " << d;
                prev = fp.area_px2;
                const double omega = sphere_solid_angle_sr(radius, d);
                ASSERT_TRUE(std::isfinite(omega) && omega > 0.0 && omega <= 2.0 * std::numbers::pi);
                if (d > 1e3 * radius) {
                    const double small = std::numbers::pi * radius * radius / (d * d);
                    ASSERT_NEAR(omega, small, 1e-5 * small);
                }
            }
        }
    }
}

TEST(StressFootprint, NearTheCameraPlaneTheFootprintStaysFinite) {
    // A light almost exactly beside the camera (view z → 0⁻, e.g. a rounding residue of a
    // 90° yaw): its projected centre runs off to infinity. Documented: not visible once the
    // sphere reaches the camera's plane (depth <= radius), finite area and centre before.
    for (double z : {-1e-1, -1e-3, -1e-9, -1e-17, -1e-100, -1e-300, -kDenorm}) {
        const Footprint fp = light_footprint(glm::dvec3(10.0, 0.0, z), 0.1, kFocalPx, kWidth, kHeight);
        if (fp.visible) {
            EXPECT_TRUE(std::isfinite(fp.area_px2)) << z;
            EXPECT_TRUE(std::isfinite(fp.radius_px)) << z;
            EXPECT_TRUE(std::isfinite(fp.centre_px.x) && std::isfinite(fp.centre_px.y)) << z;
        }
        EXPECT_EQ(fp.visible, -z > 0.1) << z;  // documented: drawn only with depth > radius
    }
}

TEST(StressFootprint, CoverageFiniteForHugeAndTinyDiscs) {
    // Disc radii from 1e-6 px (a light at 50 km) to 1e7 px (a lantern at arm's length with
    // a telephoto camera), centres far off the pixel: coverage in [0, 1] and finite.
    std::mt19937 rng(92);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (double r : {1e-6, 1e-3, 0.3, 1.0, 17.0, 1e3, 1e5, 1e7}) {
        for (int i = 0; i < 500; ++i) {
            const double cx = u(rng) * 2.0 * r, cy = u(rng) * 2.0 * r;
            const double c = disc_pixel_coverage(cx, cy, r, std::floor(u(rng) * r), std::floor(u(rng) * r));
            ASSERT_TRUE(std::isfinite(c) && c >= 0.0 && c <= 1.0) << r;
            const double b = box_pixel_coverage(cx, cy, std::floor(cx + u(rng)), std::floor(cy + u(rng)));
            ASSERT_TRUE(std::isfinite(b) && b >= 0.0 && b <= 1.0) << r;
        }
    }
    EXPECT_EQ(disc_pixel_coverage(0.5, 0.5, 0.0, 0.0, 0.0), 0.0);  // r = 0: nothing
    EXPECT_EQ(disc_pixel_coverage(0.5, 0.5, std::nan(""), 0.0, 0.0), 0.0);
}

}  // namespace
}  // namespace atonlab::stimuli
