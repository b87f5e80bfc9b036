// The `wave-optics` glare model (stimuli/src/glare_models/wave_optics/): the
// eye's PSF by FFT of its pupil plane, over the light's spectrum.
// Its two-scale eye (docs/glare.md) against what optics says without it: a
// focused eye's PSF peaks at its centre at every pupil, its core is the
// aperture's Airy pattern at the physical scale, a large defocus gives the
// geometric blur disc p·ΔD/2, the obstacles take from the core what they
// block, and the lenticular halo sits at its configured radius with red
// outside blue (Simpson 1953). The k2012 preset keeps the thesis's ringed core.
// Its anchored spectral path (spectral_path.h, the `spectral_path` key) against
// the exact per-wavelength reference (spectral_psf_exact, FFTW double at every
// sample): the default eye (its Fresnel term E changes the pattern with λ) and a
// clear pupil (only the resampling), at a reduced N.
// Elsewhere: the eye model's parts (pupil plane, geometry, hippus, validate) in
// tests/unit/test_eye_model.cpp, the PSF's shared CPU references and kernels in
// test_psf.cpp, the model on the GPU and in frames in tests/gl/glare_models/wave_optics.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/psf.h"
#include "atonlab/stimuli/spectral_path.h"
#include "input_error.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

constexpr double kPi = std::numbers::pi;
constexpr int kN = 256;       // the spectral paths' reduced size
constexpr int kSamples = 30;  // GlareSettings::spectral_samples

// Index of the largest texel.
std::size_t argmax(const std::vector<double>& v) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < v.size(); ++i)
        if (v[i] > v[best]) best = i;
    return best;
}

// Fraction of a centred PSF's energy in texels whose centres lie within r texels.
double energy_within(const MonoPsf& p, double r) {
    double s = 0;
    for (int y = 0; y < p.n; ++y)
        for (int x = 0; x < p.n; ++x)
            if (std::hypot(x - p.n / 2, y - p.n / 2) < r) s += p.at(x, y);
    return s;
}

// The radius (texels) within which a centred PSF holds `fraction` of its
// energy, by bisection on energy_within (monotone in r).
double radius_holding(const MonoPsf& p, double fraction) {
    double lo = 0, hi = p.n / 2.0;
    for (int i = 0; i < 40; ++i) {
        const double mid = 0.5 * (lo + hi);
        (energy_within(p, mid) < fraction ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

// Mean of f(x, y) over texels whose centre lies in the ring [r, r + 1) texels.
template <class F>
std::vector<double> ring_means(int n, F f) {
    std::vector<double> sum(static_cast<std::size_t>(n / 2), 0.0), count(sum.size(), 0.0);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const auto k = static_cast<std::size_t>(std::hypot(x - n / 2, y - n / 2));
            if (k >= sum.size()) continue;
            sum[k] += f(x, y);
            count[k] += 1;
        }
    for (std::size_t k = 0; k < sum.size(); ++k) sum[k] = count[k] > 0 ? sum[k] / count[k] : 0.0;
    return sum;
}

// The ring (texels) of the largest mean at or beyond from_texels.
double peak_ring(const std::vector<double>& profile, double from_texels) {
    std::size_t best = static_cast<std::size_t>(std::ceil(from_texels));
    for (std::size_t k = best; k < profile.size(); ++k)
        if (profile[k] > profile[best]) best = k;
    return static_cast<double>(best) + 0.5;  // the ring's middle
}

TEST(EyePsf, FocusedDefaultEyePeaksAtTheCentreTexelForPupils2To8mm) {
    // The default eye at the default N: the core (diffraction-limited, ~1
    // arcminute) is the brightest thing in the PSF at every pupil.
    const int n = 512;
    for (double p : {2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0}) {
        EyeModel eye;
        eye.pupil_diameter_mm = p;
        const MonoPsf psf = mono_psf_reference(eye, n, kReferenceWavelengthNm);
        const std::size_t centre = static_cast<std::size_t>(n / 2) * n + n / 2;
        EXPECT_EQ(argmax(psf.value), centre) << p << " mm";
        double sum = 0;
        for (double v : psf.value) sum += v;
        EXPECT_NEAR(sum, 1.0, 1e-12) << p << " mm";
        std::printf("default eye, %.0f mm: centre texel %.4f of the energy (%.5f°/texel)\n", p, psf.value[centre],
                    psf.degrees_per_texel);
    }
}

TEST(EyePsf, DefaultEyesCoreIsTheAiryPatternAtThePhysicalScale) {
    // 4 mm pupil with gratings and particles: the core part is the aperture's
    // diffraction, first dark ring at 1.21967 λ0/D (j₁,₁/π), on a grid of λ0/W
    // rad: 1.21967 × 18/4 = 5.49 texels.
    EyeModel eye;
    eye.pupil_diameter_mm = 4.0;
    const MonoPsfParts parts = mono_psf_parts(eye, 512, kReferenceWavelengthNm);
    EXPECT_NEAR(parts.core.degrees_per_texel, kReferenceWavelengthNm * 1e-6 / 18.0 * 180 / kPi, 1e-15);
    const double ring = 1.21967 * 18.0 / 4.0;
    const std::vector<double> profile = ring_means(parts.core.n, [&](int x, int y) { return parts.core.at(x, y); });
    // The first local minimum of the ring means.
    std::size_t k = 1;
    while (k + 1 < profile.size() && !(profile[k] < profile[k - 1] && profile[k] <= profile[k + 1])) ++k;
    EXPECT_NEAR(static_cast<double>(k) + 0.5, ring, 1.0);
    // 83.8% of the core's energy inside the ring (Born & Wolf §8.5.2), texel
    // centres within the ring: within 3% at 5.5 texels per ring radius.
    const double inside = energy_within(parts.core, ring);
    std::printf("core of the default 4 mm eye: dark ring at %.1f texels (Airy %.2f), %.3f of its energy inside\n",
                static_cast<double>(k) + 0.5, ring, inside);
    EXPECT_NEAR(inside, 0.838, 0.03);
}

TEST(EyePsf, LargeDefocusGivesTheGeometricBlurDisc) {
    // ΔD diopters on a clear pupil p: a uniform disc of radius p·ΔD/2 rad
    // (geometric optics), whose encircled energy is (r/R)². With several waves
    // of defocus (W020 = ΔD (p/2)²/2 = 7.8 and 7.0 λ0 here), diffraction only
    // rounds its edge: R from the 50% and 90% radii within 10%.
    struct Case {
        double p_mm, dd;
    };
    for (const Case c : {Case{6.0, 1.0}, Case{6.0, -1.0}, Case{8.0, 0.5}}) {
        EyeModel eye = EyeModel::clear_pupil(c.p_mm);
        eye.defocus_diopters = c.dd;
        const MonoPsf psf = mono_psf_reference(eye, 256, kReferenceWavelengthNm);
        const double rad_per_texel = psf.degrees_per_texel * kPi / 180;
        const double geometric = c.p_mm * 1e-3 * std::abs(c.dd) / 2;  // rad
        const double from50 = radius_holding(psf, 0.5) / std::sqrt(0.5) * rad_per_texel;
        const double from90 = radius_holding(psf, 0.9) / std::sqrt(0.9) * rad_per_texel;
        std::printf("defocus %.1f D, %.0f mm: blur radius %.3g rad geometric, %.3g (50%%), %.3g (90%%)\n", c.dd, c.p_mm,
                    geometric, from50, from90);
        EXPECT_NEAR(from50 / geometric, 1.0, 0.1) << c.dd << " D";
        EXPECT_NEAR(from90 / geometric, 1.0, 0.1) << c.dd << " D";
    }
}

TEST(EyePsf, ObstaclesTakeFromTheCoreWhatTheyBlock) {
    // Opaque discs blocking a fraction f of the pupil leave it the mean
    // transmittance t = 1 − f, so the core keeps t² Σ A² / Σ P² ≈ 1 − f of
    // the light: what they block, they take from the core (and scatter).
    // f is measured on the pupil planes themselves (1 − Σ P / Σ A, the drawn
    // area, whatever the discs' overlaps). The discs are 1 mm wide (28
    // texels), so their scatter (λ/d = 0.03°) lies well inside the grid and
    // the partly covered texels at their rims (≈ h/(3r) = 2% of f) are the
    // only difference: within 5% of f.
    EyeModel eye = EyeModel::clear_pupil(6.0);
    eye.halo_radius_deg = 4.0;
    eye.gratings.enabled = true;
    eye.gratings.opacity = 0.0;  // present for the scale only: they block nothing
    eye.lens_particles = Particles{true, 4, 1000.0, 0.0, 1.0, 1.9};
    ASSERT_TRUE(has_two_scales(eye));
    const int n = 512;
    const auto p = pupil_plane(eye, n, kReferenceWavelengthNm, eye.plane_width_mm);
    const auto a = pupil_plane(EyeModel::clear_pupil(6.0), n, kReferenceWavelengthNm, eye.plane_width_mm);
    double sp = 0, sa = 0;
    for (std::size_t i = 0; i < p.data.size(); ++i) {
        sp += p.data[i].real();
        sa += a.data[i].real();
    }
    const double f = 1 - sp / sa;
    const MonoPsfParts parts = mono_psf_parts(eye, n, kReferenceWavelengthNm);
    std::printf("4 discs of 1 mm block %.5f of the pupil (4 (0.5)² / 3² = %.5f without overlap); core fraction %.5f\n",
                f, 4 * 0.25 / 9, parts.core_fraction);
    EXPECT_GT(f, 0.05);
    EXPECT_NEAR(parts.core_fraction, 1 - f, 0.05 * f);
    double scatter = 0;
    for (double v : parts.scatter.value) scatter += v;
    EXPECT_NEAR(parts.core_fraction + scatter, 1.0, 1e-12);
    // The composed PSF holds the same energy.
    double total = 0;
    for (double v : mono_psf_reference(eye, n, kReferenceWavelengthNm).value) total += v;
    EXPECT_NEAR(total, 1.0, 1e-12);
}

TEST(EyePsf, HaloPeaksAtItsRadiusWithRedOutsideBlue) {
    // The default eye's gratings, 6 mm pupil, D65: the lenticular halo's
    // brightest ring at λ0 is moved to halo_radius_deg = 4°; each channel's
    // ring sits at 4°·λ/λ0 for its wavelengths, so red lies outside blue
    // (Simpson 1953). The ring means are per texel, i.e. per steradian. The
    // particles are off: in the default eye their corona, falling from the
    // centre, is brighter than the halo at 4° (which adds a bump of ~30% to it;
    // docs/glare.md), so the halo has no maximum of its own there.
    EyeModel eye;
    eye.pupil_diameter_mm = 6.0;
    eye.lens_particles.enabled = false;
    eye.vitreous_particles.enabled = false;
    const int n = 512;
    const RgbPsf psf = spectral_psf_resampled(mono_psf_reference(eye, n, kReferenceWavelengthNm),
                                              spectral_samples(d65_spectrum(), 30));
    const double dpt = psf.degrees_per_texel;
    const double from = 2.0 / dpt;  // past the core and the particles' corona
    auto channel = [&](int c) { return ring_means(n, [&](int x, int y) { return psf.at(x, y)[c]; }); };
    const double red = peak_ring(channel(0), from) * dpt, green = peak_ring(channel(1), from) * dpt,
                 blue = peak_ring(channel(2), from) * dpt;
    const double lum =
        peak_ring(ring_means(n, [&](int x, int y) { return luminance_of_linear_rgb(psf.at(x, y)); }), from) * dpt;
    std::printf("halo peaks: luminance %.2f°, red %.2f°, green %.2f°, blue %.2f° (configured 4°)\n", lum, red, green,
                blue);
    EXPECT_NEAR(lum, 4.0, 0.4);
    EXPECT_GT(red, blue + dpt);
}

TEST(EyePsf, K2012PresetKeepsTheThesisRingedCore) {
    // The preset stretches the defocused core with the halo (one scale): at the
    // pupil of 0.001 cd/m² (eq 3.15: 6.89 mm) its centre is darker than its
    // ring, the look the default eye no longer has.
    EyeModel eye = EyeModel::k2012();
    eye.pupil_diameter_mm = pupil_diameter_mm_from_adaptation(0.001);
    const MonoPsf psf = mono_psf_reference(eye, 512, kReferenceWavelengthNm);
    const double centre = psf.at(256, 256), peak = psf.value[argmax(psf.value)];
    std::printf("k2012 preset, %.2f mm: centre / maximum = %.2f\n", eye.pupil_diameter_mm, centre / peak);
    EXPECT_LT(centre / peak, 0.5);
    // And it is one FFT of P·E: the same as transforming the pupil plane.
    ComplexImage<double> field = pupil_plane(eye, 512, kReferenceWavelengthNm, eye.plane_width_mm);
    fftw_forward(field);
    const MonoPsf single = mono_psf_from_spectrum(field, psf_degrees_per_texel(eye), kReferenceWavelengthNm);
    EXPECT_EQ(single.value, psf.value);
}

// ---- The spectral paths ---------------------------------------------------------------

TEST(SpectralPath, AnchorsSitWhereTheLightIs) {
    const SpectralSamples s = spectral_samples(d65_spectrum(), kSamples);
    const std::vector<double> a = spectral_anchor_wavelengths(s, 6);
    ASSERT_EQ(a.size(), 6u);
    EXPECT_TRUE(std::is_sorted(a.begin(), a.end()));
    // D65 × CMFs: the 1% and 99% quantiles lie inside the visible band's tails.
    EXPECT_GT(a.front(), 400.0);
    EXPECT_LT(a.back(), 700.0);
    // A narrow red LED spectrum pulls them all into the red.
    const std::vector<double> red =
        spectral_anchor_wavelengths(spectral_samples(*named_spectrum("led-red"), kSamples), 4);
    for (double l : red) EXPECT_GT(l, 580.0);
    EXPECT_NE(input_error_of([&] { spectral_anchor_wavelengths(s, 0); }).find("spectral_anchors"), std::string::npos);
}

TEST(SpectralPath, DefaultEyeAndClearPupilWithinOnePercentOfTheExactPath) {
    const SpectralSamples samples = spectral_samples(d65_spectrum(), kSamples);
    EyeModel current;  // the default eye (focused, two scales), night pupil (as bench/ measures it)
    current.pupil_diameter_mm = 6.0;
    EyeModel k2012 = EyeModel::k2012();  // the thesis's single scale with its defocus
    k2012.pupil_diameter_mm = 6.0;
    const EyeModel clear = EyeModel::clear_pupil(6.0);
    for (const auto& [name, eye] :
         {std::pair{"default", current}, std::pair{"k2012", k2012}, std::pair{"clear pupil", clear}}) {
        const RgbPsf exact = spectral_psf_exact(eye, kN, samples);
        const RgbPsf anchored = spectral_psf_anchored(eye, kN, samples, 6);
        const RgbPsf rescaled = spectral_psf_resampled(mono_psf_reference(eye, kN, kReferenceWavelengthNm), samples);
        const double e_anchored = relative_l2(anchored, exact), e_rescaled = relative_l2(rescaled, exact);
        std::printf("%-12s N=%d: anchored (6) %.4f, eq 4.9 rescaled %.4f relative L2 vs exact\n", name, kN, e_anchored,
                    e_rescaled);
        EXPECT_LT(e_anchored, 1e-2) << name;
        EXPECT_NEAR(anchored.luminance_sum(), 1.0, 1e-12);
    }
}

}  // namespace
}  // namespace atonlab::test
