// The anchored spectral path (spectral_path.h) against the exact per-wavelength
// reference (spectral_psf_exact, FFTW double at every sample): the default eye
// (its Fresnel term E changes the pattern with λ) and a clear pupil (only the
// resampling), at a reduced N.
#include <gtest/gtest.h>

#include <cstdio>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/psf.h"
#include "atonlab/stimuli/spectral_path.h"
#include "input_error.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

constexpr int kN = 256;
constexpr int kSamples = 30;  // GlareSettings::spectral_samples

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
