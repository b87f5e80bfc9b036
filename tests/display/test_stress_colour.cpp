// Numerical stress tests of the colour stage (issue 8, colour.h): xy and SPDs to
// normalised linear RGB over the whole chromaticity triangle (pure, saturated and
// out-of-gamut colours, y -> 0), every narrow-band SPD from 360 to 830 nm, black and
// huge luminances through xyY/XYZ/RGB, and the sRGB transfer functions at the ulp
// level around their breakpoints. Fixed seeds; docs/numerical-behaviour.md lists
// the singular points.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "atonlab/display/colour.h"
#include "atonlab/common/input_error.h"

namespace atonlab::display {
namespace {

bool finite(const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

TEST(StressColour, XyToRgbOverTheWholeChromaticityTriangle) {
    // Every valid xy (x >= 0, y > 0, x + y <= 1), real or imaginary: unclipped RGB is finite
    // with Y = 1 exactly; clipped RGB is finite, non-negative, Y = 1, and equals the
    // unclipped one inside the gamut. A fixed-seed sample plus a grid reaching the edges.
    std::mt19937 rng(71);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<glm::dvec2> xys;
    for (int i = 0; i <= 100; ++i)
        for (int j = 1; j <= 100 - i; ++j) xys.emplace_back(i / 100.0, j / 100.0);
    for (int i = 0; i < 20000; ++i) {
        const double x = u(rng), y = u(rng);
        if (x + y <= 1.0 && y > 0.0) xys.emplace_back(x, y);
    }
    // The corners and edges of the triangle, and y just above 0 on the purple side.
    for (double y : {1e-3, 1e-9, 1e-100}) {
        xys.emplace_back(0.0, y);
        xys.emplace_back(1.0 - y, y);
        xys.emplace_back(0.5, y);
    }
    xys.emplace_back(0.0, 1.0);
    long in_gamut = 0;
    for (const glm::dvec2& xy : xys) {
        const Vec3 raw = normalised_rgb_from_xy(xy, false);
        ASSERT_TRUE(finite(raw)) << xy.x << ", " << xy.y;
        const double scale = std::max({std::abs(raw.r), std::abs(raw.g), std::abs(raw.b), 1.0});
        ASSERT_NEAR(luminance_of_linear_rgb(raw), 1.0, 1e-13 * scale) << xy.x << ", " << xy.y;
        const Vec3 clipped = normalised_rgb_from_xy(xy, true);
        ASSERT_TRUE(finite(clipped)) << xy.x << ", " << xy.y;
        for (int k = 0; k < 3; ++k) ASSERT_GE(clipped[k], 0.0) << xy.x << ", " << xy.y;
        ASSERT_NEAR(luminance_of_linear_rgb(clipped), 1.0, 1e-13) << xy.x << ", " << xy.y;
        if (raw.r >= 0 && raw.g >= 0 && raw.b >= 0) {
            ++in_gamut;
            for (int k = 0; k < 3; ++k) ASSERT_NEAR(clipped[k], raw[k], 1e-13 * scale);
        }
    }
    std::printf("xy -> RGB: %zu chromaticities finite, %ld of them in the Rec.709 gamut\n", xys.size(), in_gamut);
}

TEST(StressColour, XyWithYDownToTheSmallestDoubleClipsFinite) {
    // y -> 0: the unclipped RGB grows as 1/y (documented to overflow below ~1e-307); the
    // clipped colour the scene file uses stays finite, because clipping is scale-free.
    for (double y : {1e-300, 1e-310, std::numeric_limits<double>::denorm_min()}) {
        for (double x : {0.0, 0.2, 0.5, 1.0 - y}) {
            const Vec3 c = normalised_rgb_from_xy({x, y}, true);
            ASSERT_TRUE(finite(c)) << x << ", " << y;
            ASSERT_NEAR(luminance_of_linear_rgb(c), 1.0, 1e-13) << x << ", " << y;
        }
    }
    // y = 0 exactly is not a colour: an InputError, never a NaN.
    EXPECT_THROW(normalised_rgb_from_xy({0.3, 0.0}, true), InputError);
}

TEST(StressColour, EveryNarrowBandSpectrumFrom360To830Nm) {
    // Narrow Gaussians (1 nm and 10 nm FWHM) at every nm: each has a colour on or near the
    // spectral locus, far outside the gamut for most; the clipped RGB is finite, >= 0, Y = 1.
    // Where the CMFs give no luminance the documented InputError comes instead.
    long coloured = 0, refused = 0;
    for (double fwhm : {1.0, 10.0}) {
        for (int nm = 360; nm <= 830; ++nm) {
            try {
                const Vec3 c = normalised_rgb_from_spectrum(gaussian_spectrum(nm, fwhm));
                ASSERT_TRUE(finite(c)) << nm;
                for (int k = 0; k < 3; ++k) ASSERT_GE(c[k], 0.0) << nm;
                ASSERT_NEAR(luminance_of_linear_rgb(c), 1.0, 1e-12) << nm;
                ++coloured;
            } catch (const InputError&) {
                ++refused;
            }
        }
    }
    EXPECT_EQ(refused, 0);  // ȳ > 0 over the whole 360..830 nm table
    std::printf("narrow-band SPDs: %ld coloured, %ld refused\n", coloured, refused);
}

TEST(StressColour, BlackAndHugeLuminancesThroughXyYAndXyz) {
    // Black has no chromaticity: documented as D65's xy with Y = 0 (finite). xyY -> XYZ ->
    // RGB -> XYZ -> xyY keeps pure primaries and out-of-gamut colours over 1e-300 … 1e300.
    const Vec3 black = xyz_to_xyY(Vec3(0.0));
    EXPECT_EQ(black.z, 0.0);
    EXPECT_EQ(glm::dvec2(black), d65_white_xy());
    EXPECT_EQ(xyY_to_xyz(Vec3(0.3, 0.0, 5.0)), Vec3(0.0));  // y = 0: no luminance
    const std::vector<Vec3> rgbs = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}, {-0.5, 1.2, 0.1}, {2, -0.3, -0.1}};
    for (const Vec3& rgb : rgbs) {
        for (double scale : {1e-300, 1e-30, 1.0, 1e9, 1e30, 1e300}) {
            const Vec3 in = rgb * scale;
            const Vec3 xyY = xyz_to_xyY(linear_rgb_to_xyz(in));
            ASSERT_TRUE(finite(xyY)) << scale;
            const Vec3 back = xyz_to_linear_rgb(xyY_to_xyz(xyY));
            ASSERT_TRUE(finite(back)) << scale;
            for (int k = 0; k < 3; ++k) ASSERT_NEAR(back[k], in[k], 1e-12 * scale) << rgb.r << " " << scale;
        }
    }
}

TEST(StressColour, SrgbEncodeNonDecreasingAtTheUlpLevelAroundItsBreakpoints) {
    // IEC 61966-2-1's linear/power switch (0.0031308 linear, 0.04045 encoded) and the ends:
    // 2000 consecutive doubles either side of each, plus 0, denormals and 1.
    auto sweep = [](double centre, double (*f)(double)) {
        double v = centre;
        for (int i = 0; i < 2000; ++i) v = std::nextafter(v, 0.0);
        double prev = f(v);
        for (int i = 0; i < 4000; ++i) {
            v = std::nextafter(v, 2.0);
            const double y = f(v);
            ASSERT_TRUE(std::isfinite(y));
            ASSERT_GE(y, prev) << "at " << v;
            prev = y;
        }
    };
    sweep(0.0031308, srgb_encode);
    sweep(0.0031308049535603713, srgb_encode);
    sweep(0.04045, srgb_decode);
    sweep(1.0, srgb_encode);
    sweep(1.0, srgb_decode);
    EXPECT_EQ(srgb_encode(0.0), 0.0);
    EXPECT_EQ(srgb_encode(-0.0), 0.0);
    EXPECT_GT(srgb_encode(std::numeric_limits<double>::denorm_min()), 0.0);
    EXPECT_NEAR(srgb_encode(1.0), 1.0, 1e-15);
    EXPECT_NEAR(srgb_encode(std::numeric_limits<double>::infinity()), 1.0, 1e-15);
    EXPECT_EQ(srgb_encode(-std::numeric_limits<double>::infinity()), 0.0);
}

}  // namespace
}  // namespace atonlab::display
