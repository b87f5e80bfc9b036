// The `cie` veiling glare: the CIE glare spread function (CIE 135/1-1999) and
// the CIE 146:2002 General Disability Glare equation against independent
// transcriptions, the ratio between the two, the integral another
// implementation publishes, the
// energy-conserving GSF, the pixel kernel, and the frame convolution (CPU,
// FFTW) against the equation and an independent integral of the frame's share.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "atonlab/stimuli/cie_glare.h"
#include "atonlab/stimuli/footprint.h"
#include "atonlab/stimuli/veiling_glare.h"
#include "input_error.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;

constexpr double kDeg = std::numbers::pi / 180.0;

// The CIE glare spread function of Vos & van den Berg (CIE 135/1-1999),
// transcribed term by term, independently of cie_glare.cpp.
double cie135_gsf(double theta_deg, double age, double p) {
    const double a = std::pow(age / 70.0, 4);
    const double t2 = theta_deg * theta_deg;
    const double x1 = 1 + t2 / (0.0046 * 0.0046), x2 = 1 + t2 / (0.045 * 0.045), x3 = 1 + t2 / 0.01;
    const double young = 9.2e6 * std::pow(x1, -1.5) + 1.5e5 * std::pow(x2, -1.5);
    const double old = 400.0 / x3 + 3e-8 * t2;
    const double pigment = 1300.0 * std::pow(x3, -1.5) + 0.8 * std::pow(x3, -0.5);
    return (1 - 0.08 * a) * young + (1 + 1.6 * a) * (old + p * pigment) + 2.5e-3 * p;
}

TEST(CieEquation, MatchesAnIndependentTranscription) {
    for (double age : {0.0, 25.0, 50.0, 70.0, 85.0})
        for (double p : {0.0, 0.5, 1.0, 1.2})
            for (double t : {0.0, 0.01, 0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 60.0, 100.0}) {
                const double want = cie135_gsf(t, age, p);
                EXPECT_NEAR(cie_gsf_veil_per_lux(t, {age, p}) / want, 1.0, 1e-12) << t << "° A " << age << " p " << p;
            }
}

// The CIE 146:2002 General Disability Glare equation as printed (CIE 146:2002;
// Vos 2003, Clin Exp Optom 86:363), in another arrangement than cie_glare.cpp's.
double cie146_general(double theta_deg, double age, double p) {
    const double age_factor = 1 + std::pow(age / 62.5, 4);
    return (10 / theta_deg + (5 + 0.1 * p * theta_deg) * age_factor) / (theta_deg * theta_deg) + 0.0025 * p;
}

TEST(CieEquation, TheGeneralDisabilityGlareEquationMatchesItsPrintedForm) {
    for (double age : {0.0, 25.0, 50.0, 70.0, 85.0})
        for (double p : {0.0, 0.5, 1.0, 1.2})
            for (double t : {0.1, 0.3, 1.0, 3.0, 10.0, 30.0, 60.0, 100.0})
                EXPECT_NEAR(cie146_general_veil_per_lux(t, {age, p}) / cie146_general(t, age, p), 1.0, 1e-12)
                    << t << "° A " << age << " p " << p;
}

TEST(CieEquation, BothEquationsTakeTheirHandValues) {
    // A = 25 years, p = 0.5 (brown eyes), worked out term by term by hand:
    // General at 1°:  10 + (5 + 0.05)(1 + 0.4⁴) + 0.00125          = 15.18053
    //         at 10°: 0.01 + (0.05 + 0.005)(1.0256) + 0.00125       = 0.0676580
    // GSF at 1°: (1 − 0.08·(25/70)⁴)(9.2e6·(1 + (1/0.0046)²)^−1.5 + 1.5e5·(1 + (1/0.045)²)^−1.5)
    //            + (1 + 1.6·(25/70)⁴)(400/101 + 3e-8 + 0.5(1300·101^−1.5 + 0.8·101^−0.5)) + 0.00125
    //          = 0.998698 · (0.895463 + 13.627336) + 1.026031 · (3.960396 + 0.640370 + 0.039801)
    //          = 14.503897 + 4.761366 + 0.00125                      = 19.26651
    const CieObserver o{25, 0.5};
    EXPECT_NEAR(cie146_general_veil_per_lux(1.0, o), 15.18053, 5e-5);
    EXPECT_NEAR(cie146_general_veil_per_lux(10.0, o), 0.0676580, 5e-7);
    EXPECT_NEAR(cie_gsf_veil_per_lux(1.0, o), 19.26651, 5e-5);
}

TEST(CieEquation, TheGlareSpreadFunctionAndTheGeneralEquationDifferBetweenATenthAndAHundredDegrees) {
    // Not one equation under two names: within the General equation's domain
    // (0.1° … 100°) the GSF the `cie` model uses is 27% above it at 1°, 8% at 3°
    // and 9% below at 10° (A = 25, p = 0.5), both from the independent
    // transcriptions above; the `cie` model keeps the GSF (docs/glare.md).
    const double want[][2] = {{1.0, 1.2692}, {3.0, 1.0784}, {10.0, 0.9105}};
    for (const auto& [theta, ratio] : want) {
        EXPECT_NEAR(cie135_gsf(theta, 25, 0.5) / cie146_general(theta, 25, 0.5), ratio, 5e-4) << theta << "°";
        const CieObserver o{25, 0.5};
        EXPECT_NEAR(cie_gsf_veil_per_lux(theta, o) / cie146_general_veil_per_lux(theta, o), ratio, 5e-4) << theta;
    }
    // The General equation's 10/θ³ diverges at 0; the GSF is finite there
    // (9.2e6 + 1.5e5 + 400 + 1300 p + 0.8 p, scaled by age, + 0.0025 p).
    EXPECT_TRUE(std::isinf(cie146_general_veil_per_lux(0.0, {25, 0.5})));
    EXPECT_NEAR(cie_gsf_veil_per_lux(0.0, {0, 0.5}) / (9.2e6 + 1.5e5 + 400 + 650.4 + 0.00125), 1.0, 1e-12);
}

TEST(CieEquation, SphereIntegralAgreesWithThePublishedValues) {
    // Integrals over the sphere that another implementation reports for the
    // same equation (1.047 at A = 25, p = 0.5; 1.010 at p = 0), i.e. the
    // equation is ~5% above unit energy, which the GSF must correct.
    EXPECT_NEAR(cie_gsf_energy_between({25.0, 0.5}, 0.0, 180.0), 1.047, 0.001);
    EXPECT_NEAR(cie_gsf_energy_between({25.0, 0.0}, 0.0, 180.0), 1.010, 0.001);
}

TEST(CieGlareSpread, ConservesEnergyKeepsTheEquationBeyondATenthOfADegreeAndIsContinuous) {
    for (CieObserver o : {CieObserver{25, 0.5}, CieObserver{0, 0}, CieObserver{70, 1.2}, CieObserver{90, 0.5}}) {
        const CieGlareSpread g = cie_glare_spread(o);
        EXPECT_NEAR(cie_energy_between(g, 0.0, 180.0), 1.0, 1e-8) << o.age_years << " " << o.pigmentation;
        EXPECT_LE(g.kappa, 1.0);
        for (double t : {0.1, 0.5, 1.0, 3.0, 10.0, 45.0, 100.0})
            EXPECT_EQ(g.density_sr(t), cie_gsf_veil_per_lux(t, o)) << t;
        // Continuous at 0.1°: just inside differs from just outside by the slope only.
        EXPECT_NEAR(g.density_sr(0.1 - 1e-9) / g.density_sr(0.1), 1.0, 1e-6);
        // Positive and decreasing from the centre.
        double last = g.density_sr(0.0);
        for (double t = 0.001; t < 179; t *= 1.1) {
            const double d = g.density_sr(t);
            EXPECT_GT(d, 0.0);
            if (t < 100) {
                EXPECT_LE(d, last * (1 + 1e-12)) << t;
            }
            last = d;
        }
    }
}

TEST(CieGlareSpread, BadObserversAreRefusedNamingTheKey) {
    EXPECT_NE(input_error_of([] { cie_glare_spread({-1, 0.5}); }).find("cie_age_years"), std::string::npos);
    EXPECT_NE(input_error_of([] { cie_glare_spread({std::nan(""), 0.5}); }).find("cie_age_years"), std::string::npos);
    EXPECT_NE(input_error_of([] { cie_glare_spread({25, -0.1}); }).find("cie_pigmentation"), std::string::npos);
    EXPECT_NE(input_error_of([] { cie_glare_spread({25, 1.5}); }).find("cie_pigmentation"), std::string::npos);
    // Each in range, together scattering more than all the light beyond 0.1°.
    EXPECT_NE(input_error_of([] { cie_glare_spread({100, 1.2}); }).find("more than all"), std::string::npos);
}

TEST(CieKernel, PixelsHoldTheEquationTimesTheirSolidAngle) {
    // 12 px per degree: 1°, 3° and 10° are 12, 36 and 120 px away.
    const double f = 12.0 / kDeg;
    const CieGlareSpread g = cie_glare_spread({25, 0.5});
    const VeilKernelQuadrant k = veil_kernel_quadrant(g, 140, 60, f);
    for (int dx : {12, 36, 120}) {
        // The pixel's mean of the equation (a 1/θ³ term curves by ~0.2% over a
        // pixel at 1°), by a 32×32 midpoint rule of L/E · dΩ/dA.
        double want = 0;
        for (int b = 0; b < 32; ++b)
            for (int a = 0; a < 32; ++a) {
                const double x = dx - 0.5 + (a + 0.5) / 32, y = -0.5 + (b + 0.5) / 32;
                const double q = f * f + x * x + y * y;
                want += cie135_gsf(std::atan(std::hypot(x, y) / f) / kDeg, 25, 0.5) * f / (q * std::sqrt(q)) / 1024;
            }
        EXPECT_NEAR(k.at(dx, 0) / want, 1.0, 1e-4) << dx << " px";
        // ... and within 1% of its value at the pixel's centre.
        const double theta = std::atan(dx / f) / kDeg;
        EXPECT_NEAR(k.at(dx, 0) / pixel_solid_angle_sr(dx - 0.5, -0.5, f) / cie135_gsf(theta, 25, 0.5), 1.0, 0.01);
    }
    // The inner rings hold what the GSF holds there: the 5×5 px centre against the cone it nearly fills.
    double centre = 0;
    for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) centre += k.at(std::abs(dx), std::abs(dy));
    const double inscribed = cie_energy_between(g, 0.0, std::atan(2.5 / f) / kDeg);
    const double circumscribed = cie_energy_between(g, 0.0, std::atan(2.5 * std::numbers::sqrt2 / f) / kDeg);
    EXPECT_GT(centre, inscribed);
    EXPECT_LT(centre, circumscribed);
}

// The share of a centred light's energy that a W×H frame keeps, independently
// of the kernel's quadrature: the disc inscribed in the frame exactly (1 minus
// the raw equation beyond it: every angle there is ≥ 0.1°), the rest of the
// rectangle by a 4×4-per-pixel midpoint rule of the equation times dΩ/dA.
double frame_share(double age, double p, int w, int h, double f) {
    const double r_in = 0.5 * std::min(w, h);
    double share = 1.0 - cie_gsf_energy_between({age, p}, std::atan(r_in / f) / kDeg, 180.0);
    const int s = 4;
    for (int j = 0; j < h * s; ++j)
        for (int i = 0; i < w * s; ++i) {
            const double x = (i + 0.5) / s - 0.5 * w, y = (j + 0.5) / s - 0.5 * h;
            const double r2 = x * x + y * y;
            if (r2 < r_in * r_in) continue;
            const double q = f * f + r2;
            share += cie135_gsf(std::atan(std::sqrt(r2) / f) / kDeg, age, p) * f / (q * std::sqrt(q)) / (s * s);
        }
    return share;
}

TEST(VeilingGlare, OnePixelLightGivesTheCieVeilAndKeepsItsEnergy) {
    // A light of 2 lx in the centre pixel of a 301×201 frame at 12 px per degree
    // (±12.5° × ±8.4°): the veil at 1°, 3° and 10° against the equation.
    const int w = 301, h = 201;
    const double f = 12.0 / kDeg, e_lux = 2.0;
    std::vector<float> rgba(static_cast<std::size_t>(w) * h * 4, 0.0f);
    const int ci = w / 2, cj = h / 2;
    const double omega0 = frame_pixel_solid_angle_sr(ci, cj, w, h, f);
    for (int c = 0; c < 3; ++c)
        rgba[(static_cast<std::size_t>(cj) * w + ci) * 4 + c] = static_cast<float>(e_lux / omega0);
    VeilingGlare veil;
    const glm::dvec3 outside = veil.apply(rgba, w, h, f, {25, 0.5});
    for (int dx : {12, 36, 120}) {
        const double theta = std::atan(dx / f) / kDeg;
        const double l = rgba[(static_cast<std::size_t>(cj) * w + ci + dx) * 4 + 1];
        EXPECT_NEAR(l / e_lux / cie135_gsf(theta, 25, 0.5), 1.0, 0.01) << theta << "°";
        printf("veil at %.3f°: L/E = %.6g sr⁻¹, CIE GSF %.6g sr⁻¹, ratio %.5f\n", theta, l / e_lux,
               cie135_gsf(theta, 25, 0.5), l / e_lux / cie135_gsf(theta, 25, 0.5));
    }
    double sum = 0;
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
            sum += rgba[(static_cast<std::size_t>(j) * w + i) * 4 + 1] * frame_pixel_solid_angle_sr(i, j, w, h, f);
    const double share = frame_share(25, 0.5, w, h, f);
    printf("frame keeps %.6f of the light (independent %.6f), reports %.6f outside\n", sum / e_lux, share, outside.g);
    EXPECT_NEAR(sum / e_lux, 1.0 - outside.g, 1e-4);  // the report is what the frame lost
    EXPECT_NEAR(sum / e_lux, share, 1e-3);            // and that is what the GSF puts beyond the frame
    EXPECT_EQ(outside.r, outside.g);
    EXPECT_EQ(veil.kernel_builds(), 1);
    // A second frame of the same size reuses the kernel; an empty channel reports 0.
    std::vector<float> dark(rgba.size(), 0.0f);
    EXPECT_EQ(veil.apply(dark, w, h, f, {25, 0.5}), glm::dvec3(0.0));
    EXPECT_EQ(veil.kernel_builds(), 1);
}

}  // namespace
}  // namespace atonlab::test
