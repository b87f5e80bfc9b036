// The PSF's CPU references and the billboard kernel, against analytic optics:
// the Airy pattern of a clear circular pupil (first dark ring at 1.22 λ/D,
// 83.8% of the energy inside it), wavelength scaling, unit sums, window cuts
// and the energy of area layers.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "atonlab/stimuli/glare_kernel.h"
#include "atonlab/stimuli/psf.h"
#include "input_error.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

// Azimuthal mean of a centred PSF at radius r (texels), by bilinear samples.
double radial_mean(const std::vector<double>& v, int n, double r) {
    constexpr int kAngles = 720;
    double s = 0;
    for (int a = 0; a < kAngles; ++a) {
        const double t = 2 * std::numbers::pi * (a + 0.5) / kAngles;
        s += bilinear_zero_border(v, n, n / 2 + r * std::cos(t), n / 2 + r * std::sin(t));
    }
    return s / kAngles;
}

// The first local minimum of the radial profile (texels), found on a 0.02-texel grid.
double first_dark_ring_texels(const MonoPsf& p, double search_to) {
    double prev = radial_mean(p.value, p.n, 0.0), best_r = 0;
    bool falling = false;
    for (double r = 0.02; r < search_to; r += 0.02) {
        const double v = radial_mean(p.value, p.n, r);
        if (v < prev) falling = true;
        if (falling && v > prev) return best_r;
        prev = v;
        best_r = r;
    }
    return -1;
}

// Fraction of the energy in texels whose centres lie within r (texels) of the centre.
double energy_within(const MonoPsf& p, double r) {
    double s = 0;
    for (int y = 0; y < p.n; ++y)
        for (int x = 0; x < p.n; ++x)
            if (std::hypot(x - p.n / 2, y - p.n / 2) < r) s += p.at(x, y);
    return s;
}

EyeModel clear(double d_mm, double plane_mm) {
    EyeModel e = EyeModel::clear_pupil(d_mm);
    e.plane_width_mm = plane_mm;
    return e;
}

TEST(Psf, ClearPupilGivesAiryRingAt1_22LambdaOverD) {
    // D = 3 mm over a 36 mm plane at λ0: texel = λ0/W rad, ring at 1.22 W/D = 14.64 texels.
    const EyeModel eye = clear(3.0, 36.0);
    const MonoPsf p = mono_psf_reference(eye, 512, kReferenceWavelengthNm);
    const double expected_texels = 1.21967 * eye.plane_width_mm / eye.pupil_diameter_mm;  // 1.21967 = j₁,₁/π
    const double ring = first_dark_ring_texels(p, 30);
    EXPECT_NEAR(ring, expected_texels, 1.0);
    // The same in angle: degrees_per_texel is physical (λ0/W) for a clear pupil.
    const double ring_rad = ring * p.degrees_per_texel * kRadPerDeg;
    EXPECT_NEAR(ring_rad / (1.21967 * kReferenceWavelengthNm * 1e-9 / 3e-3), 1.0, 1.0 / expected_texels);
    // 83.8% of the energy inside the first dark ring (Born & Wolf §8.5.2:
    // encircled energy 1 − J0²(x) − J1²(x), x = 3.8317 at the ring). The grid
    // holds the pattern only out to its edge (r_f = n/2 texels; the DFT cannot
    // carry the tail beyond), so the fraction is taken relative to the energy
    // within r_f, as the continuous pattern would have it.
    auto encircled = [](double x) {
        return 1 - std::pow(std::cyl_bessel_j(0.0, x), 2) - std::pow(std::cyl_bessel_j(1.0, x), 2);
    };
    const double r_field = p.n / 2 - 1;
    const double expected = encircled(3.8317) / encircled(3.8317 * r_field / expected_texels);
    const double measured = energy_within(p, expected_texels) / energy_within(p, r_field);
    std::printf(
        "Airy: energy inside the first dark ring %.4f (continuous pattern cut at the grid: %.4f; infinite: 0.8378)\n",
        measured, expected);
    EXPECT_NEAR(measured, expected, 0.01);
    EXPECT_NEAR(measured, 0.838, 0.015);
}

TEST(Psf, RingScalesWithWavelength) {
    const EyeModel eye = clear(3.0, 36.0);
    const MonoPsf blue = mono_psf_reference(eye, 256, 450.0);
    const MonoPsf red = mono_psf_reference(eye, 256, 650.0);
    const double rb = first_dark_ring_texels(blue, 30), rr = first_dark_ring_texels(red, 30);
    EXPECT_NEAR(rb, 1.21967 * 36.0 / 3.0 * 450.0 / kReferenceWavelengthNm, 1.0);
    EXPECT_NEAR(rr / rb, 650.0 / 450.0, 0.03);
    // The fast path's eq 4.9 lookup puts the red ring at the same place.
    const MonoPsf ref = mono_psf_reference(eye, 256, kReferenceWavelengthNm);
    MonoPsf scaled = ref;
    const double ratio = kReferenceWavelengthNm / 650.0;
    for (int y = 0; y < ref.n; ++y)
        for (int x = 0; x < ref.n; ++x)
            scaled.value[static_cast<std::size_t>(y) * ref.n + x] =
                bilinear_zero_border(ref.value, ref.n, 128 + (x - 128) * ratio, 128 + (y - 128) * ratio);
    EXPECT_NEAR(first_dark_ring_texels(scaled, 30), rr, 0.5);
}

TEST(Psf, MonoPsfSumsToOne) {
    const MonoPsf p = mono_psf_reference(clear(4.0, 18.0), 128, 500.0);
    double s = 0;
    for (double v : p.value) s += v;
    EXPECT_NEAR(s, 1.0, 1e-12);
}

TEST(Psf, SpectralSamplesWeighCmfTimesSpd) {
    const SpectralSamples s = spectral_samples(d65_spectrum(), 40);
    ASSERT_EQ(s.wavelength_nm.size(), 40u);
    EXPECT_DOUBLE_EQ(s.wavelength_nm.front(), 385.0);  // bins of 10 nm from 380 nm, sampled at centres
    double y = 0;
    glm::dvec3 xyz{0.0};
    for (const auto& w : s.xyz_weight) {
        y += w.y;
        xyz += w;
    }
    EXPECT_NEAR(y, 1.0, 1e-12);
    // D65 integrates to the D65 white: x, y chromaticity (0.3127, 0.3290) within the sampling error.
    EXPECT_NEAR(xyz.x / (xyz.x + xyz.y + xyz.z), 0.3127, 2e-3);
    EXPECT_NEAR(xyz.y / (xyz.x + xyz.y + xyz.z), 0.3290, 2e-3);
    EXPECT_NE(input_error_of([] { spectral_samples(d65_spectrum(), 0); }).find("spectral_samples"), std::string::npos);
}

TEST(Psf, RgbPsfLuminanceSumsToOneAndD65IsWhite) {
    const EyeModel eye = clear(4.0, 18.0);
    const MonoPsf mono = mono_psf_reference(eye, 128, kReferenceWavelengthNm);
    const RgbPsf rgb = spectral_psf_resampled(mono, spectral_samples(d65_spectrum(), 30));
    EXPECT_NEAR(rgb.luminance_sum(), 1.0, 1e-12);
    // A D65 spectrum integrates to white: equal channel sums (K2012 §4.2.4).
    const glm::dvec3 c = rgb.channel_sums();
    EXPECT_NEAR(c.r, 1.0, 0.02);
    EXPECT_NEAR(c.g, 1.0, 0.02);
    EXPECT_NEAR(c.b, 1.0, 0.02);
}

TEST(Psf, ResampledSpectralIntegrationApproachesExactReference) {
    // Eq 4.9 ignores E's wavelength dependence; with E off (clear pupil) the
    // only differences are resampling and grid edges, so the two must agree closely.
    // The Airy ring spans ~15 texels here, so bilinear resampling is accurate.
    const EyeModel eye = clear(3.0, 36.0);
    const SpectralSamples samples = spectral_samples(d65_spectrum(), 16);
    const RgbPsf exact = spectral_psf_exact(eye, 128, samples);
    const RgbPsf fast = spectral_psf_resampled(mono_psf_reference(eye, 128, kReferenceWavelengthNm), samples);
    const double e = relative_l2(fast, exact);
    std::printf("clear pupil, n=128, 16 samples: relative L2 (fast vs exact) = %.3g\n", e);
    EXPECT_LT(e, 0.02);
}

RgbPsf delta_psf(int n, double dpt) {
    RgbPsf p;
    p.n = n;
    p.degrees_per_texel = dpt;
    p.rgb.assign(static_cast<std::size_t>(n) * n, glm::dvec3(0.0));
    p.rgb[static_cast<std::size_t>(n / 2) * n + n / 2] = glm::dvec3(1.0);
    return p;
}

TEST(GlareKernel, ResamplingConservesEnergyAndWindowCutIsReported) {
    // A uniform PSF over a square of ±1°: the pixel grid (30 px/deg) receives all of it.
    RgbPsf p;
    p.n = 64;
    p.degrees_per_texel = 2.0 / 64;
    p.rgb.assign(64 * 64, glm::dvec3(1.0 / (64 * 64)));
    const GlareKernel none = glare_kernel_from_psf(p, 30.0, 2.0, GlareWindow::none);
    // Nothing outside the radius-2° disc is lost: the square of ±1° fits inside.
    EXPECT_NEAR(none.window_cut.g, 0.0, 1e-12);
    // A radius of 1° cuts the square's corners: 1 − π/4.
    const GlareKernel cut = glare_kernel_from_psf(p, 30.0, 1.0, GlareWindow::none);
    EXPECT_NEAR(cut.window_cut.g, 1.0 - std::numbers::pi / 4, 0.02);
    // Epanechnikov on a uniform disc keeps ∫(1 − ρ²) / ∫1 = 1/2 of it.
    const GlareKernel ep = glare_kernel_from_psf(p, 30.0, 1.0, GlareWindow::epanechnikov);
    EXPECT_NEAR(ep.window_cut.g, 1.0 - 0.5 * std::numbers::pi / 4, 0.02);
    // Silverman: ∫(1 − ρ²)² = 1/3.
    const GlareKernel si = glare_kernel_from_psf(p, 30.0, 1.0, GlareWindow::silverman);
    EXPECT_NEAR(si.window_cut.g, 1.0 - std::numbers::pi / 4 / 3, 0.02);
    for (const GlareKernel* k : {&none, &cut, &ep, &si}) {
        glm::dvec3 s{0.0};
        for (const auto& v : k->rgba) s += glm::dvec3(v);
        EXPECT_NEAR(s.r, 1.0, 1e-5);
        EXPECT_NEAR(s.g, 1.0, 1e-5);
        EXPECT_NEAR(s.b, 1.0, 1e-5);
    }
}

TEST(GlareKernel, DeltaPsfLandsInTheCentrePixel) {
    const GlareKernel k = glare_kernel_from_psf(delta_psf(64, 0.01), 40.0, 0.3, GlareWindow::silverman);
    EXPECT_EQ(k.size, 2 * 12 + 1);
    EXPECT_NEAR(k.at(k.half(), k.half()).g, 1.0f, 1e-6f);
}

TEST(GlareKernel, AreaLayersKeepUnitSumAndSpreadAsDiscs) {
    const GlareKernel k = glare_kernel_from_psf(delta_psf(64, 0.02), 30.0, 0.5, GlareWindow::none);
    const AreaLayers L = build_area_layers(k, 6.0, 4);
    ASSERT_EQ(L.layers, 4);
    EXPECT_DOUBLE_EQ(L.radius_step_px, 2.0);
    EXPECT_EQ(L.size, k.size + 12);
    for (int layer = 0; layer < L.layers; ++layer) {
        glm::dvec3 s{0.0};
        double second_moment = 0;
        for (int j = 0; j < L.size; ++j)
            for (int i = 0; i < L.size; ++i) {
                const auto& v = L.rgba[(static_cast<std::size_t>(layer) * L.size + j) * L.size + i];
                s += glm::dvec3(v);
                second_moment += v.g * (std::pow(i - L.half(), 2) + std::pow(j - L.half(), 2));
            }
        EXPECT_NEAR(s.g, 1.0, 1e-5) << layer;
        // A uniform disc of radius r has E[ρ²] = r²/2 (plus the pixel's 1/6 for the box sampling).
        const double r = layer * L.radius_step_px;
        EXPECT_NEAR(second_moment, r * r / 2 + (layer ? 1.0 / 6 : 0.0), 0.05 + 0.02 * r * r) << layer;
    }
    // A scene that needs no layer gets only the kernel.
    EXPECT_EQ(build_area_layers(k, 0.0, 16).layers, 1);
}

TEST(GlareKernel, RadialGaussianMatchesItsAnalyticCut) {
    // A Gaussian of σ = 0.2° cut at 2σ keeps 1 − e^{-2} of its energy (no window).
    const SpectralSamples s = spectral_samples(d65_spectrum(), 8);
    const double sigma = 0.2;
    const GlareKernel k =
        glare_kernel_from_radial([sigma](double t, double) { return std::exp(-0.5 * t * t / (sigma * sigma)); }, s,
                                 60.0, 2 * sigma, GlareWindow::none);
    EXPECT_NEAR(k.window_cut.g, std::exp(-2.0), 0.01);
    EXPECT_NE(
        input_error_of([&] { glare_kernel_from_psf(delta_psf(8, 0.1), 30, 0, GlareWindow::none); }).find("radius_deg"),
        std::string::npos);
    EXPECT_NE(input_error_of([] { glare_window_from_name("box"); }).find("window"), std::string::npos);
}

}  // namespace
}  // namespace atonlab::test
