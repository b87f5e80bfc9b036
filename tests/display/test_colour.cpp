// Colour science (K2012 §3.2-3.3, §4.1). Every expected value here comes from outside this code: CIE
// publications, ITU-R BT.709 / IEC 61966-2-1, the numbers printed in K2012, or an analytic identity.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>

#include "atonlab/display/colour.h"
#include "atonlab/common/input_error.h"

namespace atonlab::display {
namespace {

// Row-major literal (as printed) -> glm column-major, so printed[r][c] == m[c][r].
Mat3 from_rows(const std::array<std::array<double, 3>, 3>& rows) {
    Mat3 m(0.0);
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) m[c][r] = rows[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
    }
    return m;
}

glm::dvec2 xy_of(Vec3 xyz) { return glm::dvec2(xyz.x, xyz.y) / (xyz.x + xyz.y + xyz.z); }

// Rec.709 / sRGB primaries and white as specified (ITU-R BT.709-6 items 1.3, 1.4).
constexpr glm::dvec2 kRed{0.64, 0.33};
constexpr glm::dvec2 kGreen{0.30, 0.60};
constexpr glm::dvec2 kBlue{0.15, 0.06};
constexpr glm::dvec2 kWhite{0.3127, 0.3290};

// K2012 eq 3.11 and 3.12 as printed (rows).
const std::array<std::array<double, 3>, 3> kEq311 = {{
    {0.4124, 0.3576, 0.1805},
    {0.2126, 0.7152, 0.0722},
    {0.0193, 0.1192, 0.9505},
}};
const std::array<std::array<double, 3>, 3> kEq312 = {{
    {3.2405, -1.5371, -0.4985},
    {-0.9693, 1.8760, 0.0416},
    {0.0556, -0.2040, 1.0572},
}};

// ---------------------------------------------------------------------------
// The CIE tables: checks that a transcription error would fail.

TEST(CieTables, YBarIsOneAt555nm) {
    // CIE 1931 y-bar = V(lambda), normalised to 1 at 555 nm (CIE 018:2019).
    EXPECT_DOUBLE_EQ(cie1931_cmf(555.0).y, 1.0);
    // And 555 nm is its maximum over the table.
    for (int nm = 360; nm <= 830; ++nm) EXPECT_LE(cie1931_cmf(nm).y, 1.0) << nm << " nm";
}

TEST(CieTables, D65Is100At560nm) {
    // CIE S 014-2: D65 is normalised to 100 at 560 nm.
    EXPECT_DOUBLE_EQ(cie_d65(560.0), 100.0);
}

TEST(CieTables, PublishedFiveNanometreValues) {
    // Spot values of the CIE 1931 2° observer and of D65 as CIE 15:2004 tabulates them at 5 nm
    // (the observer to 6 decimals, so to within half a unit of the 6th).
    struct Row {
        double nm, x, y, z;
    };
    const Row rows[] = {
        {380.0, 0.001368, 0.000039, 0.006450}, {450.0, 0.336200, 0.038000, 1.772110},
        {520.0, 0.063270, 0.710000, 0.078250}, {600.0, 1.062200, 0.631000, 0.000800},
        {700.0, 0.011359, 0.004102, 0.000000}, {780.0, 0.000042, 0.000015, 0.000000},
    };
    for (const auto& r : rows) {
        const Vec3 c = cie1931_cmf(r.nm);
        EXPECT_NEAR(c.x, r.x, 5e-7 + 1e-12) << r.nm << " nm";
        EXPECT_NEAR(c.y, r.y, 5e-7 + 1e-12) << r.nm << " nm";
        EXPECT_NEAR(c.z, r.z, 5e-7 + 1e-12) << r.nm << " nm";
    }
    struct D65Row {
        double nm, s;
    };
    const D65Row d65[] = {{300.0, 0.0341},  {380.0, 49.9755}, {460.0, 117.812}, {500.0, 109.354},
                          {600.0, 90.0062}, {700.0, 71.6091}, {780.0, 63.3828}, {830.0, 60.3125}};
    for (const auto& r : d65) EXPECT_NEAR(cie_d65(r.nm), r.s, 1e-9) << r.nm << " nm";
}

TEST(CieTables, EqualEnergyWhiteHasEqualTristimulusValues) {
    // The CMFs are scaled so that the equal-energy stimulus E has X = Y = Z (K2012 §3.3.1); at 1 nm,
    // 360..830 nm, each sum is about 106.86 and they agree to better than 1e-3 relative.
    Vec3 sum(0.0);
    for (int nm = 360; nm <= 830; ++nm) sum += cie1931_cmf(nm);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(sum[k], 106.86, 0.05) << "component " << k;
    const double lo = std::min({sum.x, sum.y, sum.z});
    const double hi = std::max({sum.x, sum.y, sum.z});
    EXPECT_LT((hi - lo) / hi, 1e-3);

    // Through the library: a flat spectrum has the chromaticity of illuminant E, (1/3, 1/3).
    const Spectrum flat{360.0, 1.0, std::vector<double>(471, 1.0)};
    const glm::dvec2 xy = xy_of(spectrum_to_xyz(flat));
    EXPECT_NEAR(xy.x, 1.0 / 3.0, 1e-4);
    EXPECT_NEAR(xy.y, 1.0 / 3.0, 1e-4);
}

TEST(CieTables, CmfTableIsSmooth) {
    // The 1 nm CMFs are a smooth interpolation of the 5 nm standard: no second difference exceeds 0.007
    // (z-bar near 420 nm). A mistyped leading digit anywhere would break this.
    for (int nm = 361; nm < 830; ++nm) {
        const Vec3 d2 = cie1931_cmf(nm - 1) - 2.0 * cie1931_cmf(nm) + cie1931_cmf(nm + 1);
        for (int k = 0; k < 3; ++k) EXPECT_LT(std::abs(d2[k]), 0.01) << nm << " nm, component " << k;
    }
}

TEST(CieTables, D65BetweenTenNanometreNodesIsTheirLinearInterpolation) {
    // CIE's 1 nm D65 table is built by linear interpolation between the 10 nm values (CIE 15:2004
    // §11.1, the same construction as the published 5 nm values). Each value has 6 significant figures,
    // so the identity holds to their rounding.
    for (int nm = 300; nm < 830; ++nm) {
        if (nm % 10 == 0) continue;
        const int lo = nm / 10 * 10;
        const double t = (nm - lo) / 10.0;
        const double expected = (1.0 - t) * cie_d65(lo) + t * cie_d65(lo + 10);
        EXPECT_NEAR(cie_d65(nm), expected, 1e-5 * std::abs(expected) + 1e-9) << nm << " nm";
    }
}

TEST(CieTables, InterpolatesLinearlyAndIsZeroOutside) {
    const Vec3 mid = cie1931_cmf(555.5);
    const Vec3 expected = 0.5 * (Vec3(0.5120501, 1.0, 0.005749999) + Vec3(0.5282959, 0.9998567, 0.0053036));
    EXPECT_NEAR(mid.x, expected.x, 1e-12);
    EXPECT_NEAR(mid.y, expected.y, 1e-12);
    EXPECT_NEAR(mid.z, expected.z, 1e-12);
    EXPECT_EQ(cie1931_cmf(359.9), Vec3(0.0));
    EXPECT_EQ(cie1931_cmf(830.1), Vec3(0.0));
    EXPECT_EQ(cie1931_cmf(std::nan("")), Vec3(0.0));
    EXPECT_GT(cie1931_cmf(830.0).y, 0.0);
    EXPECT_NEAR(cie_d65(560.5), 0.5 * (100.0 + 99.6334), 1e-12);
    EXPECT_EQ(cie_d65(299.0), 0.0);
    EXPECT_EQ(cie_d65(831.0), 0.0);
}

TEST(CieTables, SpectralLocusChromaticities) {
    // Chromaticity of monochromatic stimuli (CIE 15:2004, CIE 1931 spectral chromaticity coordinates).
    struct Row {
        double nm, x, y;
    };
    const Row rows[] = {{450.0, 0.15664, 0.01771}, {500.0, 0.00817, 0.53842}, {520.0, 0.07430, 0.83380},
                        {555.0, 0.33736, 0.65885}, {600.0, 0.62704, 0.37249}, {700.0, 0.73469, 0.26531}};
    for (const auto& r : rows) {
        const glm::dvec2 xy = xy_of(cie1931_cmf(r.nm));
        EXPECT_NEAR(xy.x, r.x, 1e-5) << r.nm << " nm";
        EXPECT_NEAR(xy.y, r.y, 1e-5) << r.nm << " nm";
    }
}

TEST(CieTables, D65ThroughTheCmfsIsTheRec709White) {
    // D65 integrated against the CIE 1931 observer gives (0.31272, 0.32903) (CIE 15:2004);
    // Rec.709 specifies the rounded (0.3127, 0.3290).
    EXPECT_EQ(d65_white_xy(), kWhite);
    const Spectrum d65 = d65_spectrum();
    EXPECT_EQ(d65.first_nm, 300.0);
    EXPECT_EQ(d65.step_nm, 1.0);
    EXPECT_EQ(d65.last_nm(), 830.0);
    const glm::dvec2 xy = xy_of(spectrum_to_xyz(d65));
    EXPECT_NEAR(xy.x, 0.3127, 5e-5);
    EXPECT_NEAR(xy.y, 0.3290, 5e-5);
    EXPECT_NEAR(xy.x, 0.31272, 1e-5);
    EXPECT_NEAR(xy.y, 0.32903, 1e-5);
}

// ---------------------------------------------------------------------------
// The Rec.709 matrices (K2012 eq 3.11, 3.12).

TEST(Rec709Matrix, MatchesEq311ToItsPrintedDecimals) {
    const Mat3& m = rec709_rgb_to_xyz();
    const Mat3 printed = from_rows(kEq311);
    for (int c = 0; c < 3; ++c) {
        for (int r = 0; r < 3; ++r) EXPECT_NEAR(m[c][r], printed[c][r], 5e-5 + 1e-12) << r << "," << c;
    }
}

TEST(Rec709Matrix, BluePrimaryTypoInTable34) {
    // K2012 table 3.4 prints the blue primary's x as 0.015. Taken literally, the matrix is far from
    // eq 3.11 (the blue column's X would be 0.0155, not 0.1805); x = 0.15 is what eq 3.11 was made from.
    const Mat3 typo = rgb_to_xyz_matrix(kRed, kGreen, {0.015, 0.06}, kWhite);
    EXPECT_GT(std::abs(typo[2][0] - 0.1805), 0.1);
    const Mat3 right = rgb_to_xyz_matrix(kRed, kGreen, kBlue, kWhite);
    EXPECT_NEAR(right[2][0], 0.1805, 5e-5);
}

TEST(Rec709Matrix, Eq312TakesXYZNotZYX) {
    // K2012 eq 3.12 writes its input as (Z, Y, X). Applied to the D65 white (X, Y, Z) =
    // (0.9505, 1, 1.0890) (eq 3.11's column sums), the printed matrix gives RGB (1, 1, 1) only in
    // X, Y, Z order.
    const Mat3 printed = from_rows(kEq312);
    const Vec3 white_xyz(0.4124 + 0.3576 + 0.1805, 1.0, 0.0193 + 0.1192 + 0.9505);
    const Vec3 right = printed * white_xyz;
    const Vec3 wrong = printed * Vec3(white_xyz.z, white_xyz.y, white_xyz.x);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(right[k], 1.0, 1e-3) << k;
    EXPECT_GT(std::abs(wrong.r - 1.0), 0.1);
    // The library's inverse takes (X, Y, Z) too.
    const Vec3 ours = xyz_to_linear_rgb(white_xyz);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(ours[k], 1.0, 1e-3) << k;
}

TEST(Rec709Matrix, Eq312IsTheInverseForTheTabulatedD65White) {
    // A numerical trap: eq 3.12 is not the inverse of eq 3.11. It is, to every printed digit, the
    // inverse of the matrix whose white is D65 from the CIE tables, XYZ = (0.95047, 1, 1.08883), while
    // eq 3.11 uses the specified (0.3127, 0.3290). Our inverse (specified white) differs from the
    // printed eq 3.12 by up to 4.7e-4.
    const Mat3 printed = from_rows(kEq312);
    const glm::dvec2 tabulated_white = xy_of(Vec3(0.95047, 1.0, 1.08883));
    const Mat3 tabulated_inverse = glm::inverse(rgb_to_xyz_matrix(kRed, kGreen, kBlue, tabulated_white));
    double ours_worst = 0.0;
    for (int c = 0; c < 3; ++c) {
        for (int r = 0; r < 3; ++r) {
            EXPECT_NEAR(tabulated_inverse[c][r], printed[c][r], 5e-5 + 1e-12) << r << "," << c;
            ours_worst = std::max(ours_worst, std::abs(rec709_xyz_to_rgb()[c][r] - printed[c][r]));
        }
    }
    EXPECT_GT(ours_worst, 3e-4);
    EXPECT_LT(ours_worst, 6e-4);
}

TEST(Rec709Matrix, MapsPrimariesAndWhiteToTheirChromaticities) {
    const Mat3& m = rec709_rgb_to_xyz();
    const glm::dvec2 primaries[3] = {kRed, kGreen, kBlue};
    for (int c = 0; c < 3; ++c) {
        const glm::dvec2 xy = xy_of(m[c]);
        EXPECT_NEAR(xy.x, primaries[c].x, 1e-12) << c;
        EXPECT_NEAR(xy.y, primaries[c].y, 1e-12) << c;
    }
    // RGB (1,1,1) -> the white at Y = 1: (x/y, 1, (1-x-y)/y) (K2012 eq 3.10).
    const Vec3 w = linear_rgb_to_xyz(Vec3(1.0));
    EXPECT_NEAR(w.x, 0.3127 / 0.3290, 1e-12);
    EXPECT_NEAR(w.y, 1.0, 1e-12);
    EXPECT_NEAR(w.z, (1.0 - 0.3127 - 0.3290) / 0.3290, 1e-12);
}

TEST(Rec709Matrix, InverseIsTheInverse) {
    const Mat3 product = rec709_rgb_to_xyz() * rec709_xyz_to_rgb();
    for (int c = 0; c < 3; ++c) {
        for (int r = 0; r < 3; ++r) EXPECT_NEAR(product[c][r], c == r ? 1.0 : 0.0, 1e-13);
    }
}

TEST(Rec709Matrix, LuminanceCoefficients) {
    // ITU-R BT.709-6 item 3.2: Y = 0.2126 R + 0.7152 G + 0.0722 B.
    EXPECT_NEAR(luminance_of_linear_rgb({1.0, 0.0, 0.0}), 0.2126, 5e-5);
    EXPECT_NEAR(luminance_of_linear_rgb({0.0, 1.0, 0.0}), 0.7152, 5e-5);
    EXPECT_NEAR(luminance_of_linear_rgb({0.0, 0.0, 1.0}), 0.0722, 5e-5);
    // The white has Y = 1 exactly (by construction of the matrix, SMPTE RP 177).
    EXPECT_NEAR(luminance_of_linear_rgb(Vec3(1.0)), 1.0, 1e-15);
    EXPECT_NEAR(luminance_of_linear_rgb({3.0, 5.0, 7.0}), linear_rgb_to_xyz({3.0, 5.0, 7.0}).y, 1e-13);
}

TEST(Rec709Matrix, RejectsDegeneratePrimaries) {
    EXPECT_THROW(rgb_to_xyz_matrix({0.1, 0.1}, {0.2, 0.2}, {0.3, 0.3}, kWhite), InputError);  // collinear
    EXPECT_THROW(rgb_to_xyz_matrix(kRed, kGreen, {0.15, 0.0}, kWhite), InputError);           // y = 0
    EXPECT_THROW(rgb_to_xyz_matrix(kRed, kGreen, kBlue, {0.7, 0.4}), InputError);             // x + y > 1
}

// ---------------------------------------------------------------------------
// xyY, XYZ and RGB (K2012 eq 3.9, 3.10).

TEST(ColourConversions, XyYKnownValues) {
    // Equal tristimulus values have chromaticity (1/3, 1/3) (K2012 eq 3.9).
    const Vec3 e = xyz_to_xyY({2.0, 2.0, 2.0});
    EXPECT_NEAR(e.x, 1.0 / 3.0, 1e-15);
    EXPECT_NEAR(e.y, 1.0 / 3.0, 1e-15);
    EXPECT_EQ(e.z, 2.0);
    // Eq 3.10 for D65 at Y = 100 cd/m2.
    const Vec3 w = xyY_to_xyz({0.3127, 0.3290, 100.0});
    EXPECT_NEAR(w.x, 100.0 * 0.3127 / 0.3290, 1e-12);
    EXPECT_EQ(w.y, 100.0);
    EXPECT_NEAR(w.z, 100.0 * 0.3583 / 0.3290, 1e-12);
    // Black keeps the white's chromaticity and stays finite.
    const Vec3 black = xyz_to_xyY(Vec3(0.0));
    EXPECT_EQ(black, Vec3(0.3127, 0.3290, 0.0));
    EXPECT_EQ(xyY_to_xyz(black), Vec3(0.0));
}

TEST(ColourConversions, XyYToRgbRoundTripOverTheGamutAndLuminanceRange) {
    std::mt19937_64 rng(20120601);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::uniform_real_distribution<double> log_y(-6.0, 9.0);
    // In-gamut chromaticities as random convex combinations of the primaries' XYZ at Y = 1 (K2012 eq 3.10
    // applied by hand, not through the library).
    const glm::dvec2 prim[3] = {kRed, kGreen, kBlue};
    for (int trial = 0; trial < 2000; ++trial) {
        double w[3] = {u(rng), u(rng), u(rng)};
        Vec3 xyz(0.0);
        for (int k = 0; k < 3; ++k) {
            const glm::dvec2 p = prim[k];
            xyz += w[k] * Vec3(p.x / p.y, 1.0, (1.0 - p.x - p.y) / p.y);
        }
        const glm::dvec2 xy = xy_of(xyz);
        const double lum_cd_m2 = std::pow(10.0, log_y(rng));

        const Vec3 rgb = xyz_to_linear_rgb(xyY_to_xyz(Vec3(xy, lum_cd_m2)));
        for (int k = 0; k < 3; ++k) EXPECT_GE(rgb[k], -1e-9 * lum_cd_m2) << "in-gamut colour went negative";
        EXPECT_NEAR(luminance_of_linear_rgb(rgb), lum_cd_m2, 1e-12 * lum_cd_m2);

        const Vec3 back = xyz_to_xyY(linear_rgb_to_xyz(rgb));
        EXPECT_NEAR(back.x, xy.x, 1e-12);
        EXPECT_NEAR(back.y, xy.y, 1e-12);
        EXPECT_NEAR(back.z, lum_cd_m2, 1e-12 * lum_cd_m2);
    }
}

TEST(ColourConversions, RgbToXyzToRgbRoundTrip) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::uniform_real_distribution<double> log_scale(-6.0, 9.0);
    for (int trial = 0; trial < 2000; ++trial) {
        const double scale = std::pow(10.0, log_scale(rng));
        const Vec3 rgb = scale * Vec3(u(rng), u(rng), u(rng));
        const Vec3 back = xyz_to_linear_rgb(linear_rgb_to_xyz(rgb));
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(back[k], rgb[k], 1e-13 * scale);
    }
    // Exact zero and pure primaries stay exact-ish and finite.
    EXPECT_EQ(xyz_to_linear_rgb(Vec3(0.0)), Vec3(0.0));
    for (int k = 0; k < 3; ++k) {
        Vec3 p(0.0);
        p[k] = 1e9;
        const Vec3 back = xyz_to_linear_rgb(linear_rgb_to_xyz(p));
        for (int j = 0; j < 3; ++j) EXPECT_NEAR(back[j], p[j], 1e-4) << k << "," << j;
    }
}

// ---------------------------------------------------------------------------
// sRGB transfer function (IEC 61966-2-1, K2012 eq 3.13).

TEST(Srgb, KnownValues) {
    EXPECT_EQ(srgb_encode(0.0), 0.0);
    EXPECT_NEAR(srgb_encode(1.0), 1.0, 1e-15);
    EXPECT_NEAR(srgb_encode(0.5), 0.735356983, 1e-9);         // 1.055 * 0.5^(1/2.4) - 0.055
    EXPECT_NEAR(srgb_encode(0.0031308), 0.040449936, 1e-12);  // 12.92 * 0.0031308, linear segment
    EXPECT_NEAR(srgb_encode(0.001), 0.01292, 1e-15);
    EXPECT_NEAR(srgb_decode(0.5), 0.214041140, 1e-9);
    EXPECT_NEAR(srgb_decode(1.0), 1.0, 1e-15);
    EXPECT_NEAR(srgb_decode(0.04045), 0.04045 / 12.92, 1e-15);
    // 8-bit mid-grey 188/255 is linear 0.5 to within a code value.
    EXPECT_NEAR(srgb_encode(0.5) * 255.0, 187.5, 0.5);
}

TEST(Srgb, ContinuousAtTheBreakpoint) {
    // The two segments meet at 0.0031308 / 0.04045 to within 3e-8 (IEC 61966-2-1's rounded constants).
    const double b = 0.0031308;
    EXPECT_NEAR(srgb_encode(std::nextafter(b, 1.0)), srgb_encode(b), 1e-7);
    EXPECT_NEAR(srgb_encode(std::nextafter(b, 0.0)), srgb_encode(b), 1e-7);
    const double e = 0.04045;
    EXPECT_NEAR(srgb_decode(std::nextafter(e, 1.0)), srgb_decode(e), 1e-8);
}

TEST(Srgb, RoundTripAndMonotonic) {
    double prev_enc = -1.0;
    double prev_dec = -1.0;
    for (int i = 0; i <= 100000; ++i) {
        const double v = i / 100000.0;
        // IEC 61966-2-1's rounded breakpoints (0.0031308 linear, 0.04045 encoded) do not quite map onto
        // each other, so right at the switch a round trip is off by up to 3e-8; elsewhere it is exact.
        const bool at_switch = std::abs(v - 0.0031308) < 1e-4 || std::abs(v - 0.04045) < 1e-4;
        const double tol = at_switch ? 5e-8 : 1e-12;
        EXPECT_NEAR(srgb_decode(srgb_encode(v)), v, tol) << v;
        EXPECT_NEAR(srgb_encode(srgb_decode(v)), v, tol) << v;
        EXPECT_GT(srgb_encode(v), prev_enc);
        EXPECT_GT(srgb_decode(v), prev_dec);
        prev_enc = srgb_encode(v);
        prev_dec = srgb_decode(v);
    }
}

TEST(Srgb, ClampsOutOfRangeInput) {
    EXPECT_EQ(srgb_encode(-1.0), 0.0);
    EXPECT_NEAR(srgb_encode(1e9), 1.0, 1e-15);
    EXPECT_EQ(srgb_decode(-0.5), 0.0);
    EXPECT_NEAR(srgb_decode(2.0), 1.0, 1e-15);
    EXPECT_EQ(srgb_encode(std::nan("")), 0.0);
    EXPECT_EQ(srgb_decode(std::nan("")), 0.0);
}

// ---------------------------------------------------------------------------
// Spectra.

TEST(Spectra, GaussianHasItsPeakAndHalfWidth) {
    const Spectrum s = gaussian_spectrum(600.0, 30.0);
    EXPECT_EQ(s.first_nm, 360.0);
    EXPECT_EQ(s.step_nm, 1.0);
    EXPECT_EQ(s.values.size(), 471u);
    EXPECT_NEAR(s.at(600.0), 1.0, 1e-15);
    EXPECT_NEAR(s.at(585.0), 0.5, 1e-12);  // half maximum at peak -+ FWHM/2
    EXPECT_NEAR(s.at(615.0), 0.5, 1e-12);
    EXPECT_NEAR(s.at(630.0), 1.0 / 16.0, 1e-12);  // exp(-4 ln 2 (x/FWHM)^2) at x = FWHM
    EXPECT_THROW(gaussian_spectrum(600.0, 0.0), InputError);
    EXPECT_THROW(gaussian_spectrum(600.0, -5.0), InputError);
    EXPECT_THROW(gaussian_spectrum(std::nan(""), 20.0), InputError);
}

TEST(Spectra, AtInterpolatesAndIsZeroOutside) {
    const Spectrum s{400.0, 10.0, {1.0, 3.0, 2.0}};
    EXPECT_EQ(s.last_nm(), 420.0);
    EXPECT_DOUBLE_EQ(s.at(405.0), 2.0);
    EXPECT_DOUBLE_EQ(s.at(417.5), 2.25);
    EXPECT_DOUBLE_EQ(s.at(420.0), 2.0);
    EXPECT_EQ(s.at(399.9), 0.0);
    EXPECT_EQ(s.at(420.1), 0.0);
    EXPECT_EQ(Spectrum{}.at(500.0), 0.0);
}

TEST(Spectra, NarrowGaussianApproachesTheSpectralLocus) {
    // A 2 nm wide line at 520 nm is nearly monochromatic: CIE 15 locus point (0.07430, 0.83380).
    const glm::dvec2 xy = xy_of(spectrum_to_xyz(gaussian_spectrum(520.0, 2.0)));
    EXPECT_NEAR(xy.x, 0.07430, 2e-3);
    EXPECT_NEAR(xy.y, 0.83380, 2e-3);
}

TEST(Spectra, EveryNamedSpectrumGivesAUnitLuminanceColour) {
    const auto names = spectrum_names();
    EXPECT_EQ(names.size(), 10u);  // d65, led-white, four led-* dies, four iala-* dies (docs/glare.md)
    for (const auto& name : names) {
        const auto spd = named_spectrum(name);
        ASSERT_TRUE(spd.has_value()) << name;
        const Vec3 rgb = normalised_rgb_from_spectrum(*spd);
        for (int k = 0; k < 3; ++k) {
            EXPECT_TRUE(std::isfinite(rgb[k])) << name;
            EXPECT_GE(rgb[k], 0.0) << name << " must be clipped into the gamut";
        }
        // BT.709's 4-decimal coefficients, to within their rounding.
        const double rounding = 5e-5 * (rgb.r + rgb.g + rgb.b);
        EXPECT_NEAR(0.2126 * rgb.r + 0.7152 * rgb.g + 0.0722 * rgb.b, 1.0, rounding) << name;
        EXPECT_NEAR(luminance_of_linear_rgb(rgb), 1.0, 1e-9) << name;
    }
    EXPECT_FALSE(named_spectrum("led-purple").has_value());
    EXPECT_FALSE(named_spectrum("").has_value());
}

TEST(Spectra, ColourIsIndependentOfSpectralScale) {
    Spectrum s = white_led_spectrum();
    const Vec3 a = normalised_rgb_from_spectrum(s);
    for (double& v : s.values) v *= 1234.5;
    const Vec3 b = normalised_rgb_from_spectrum(s);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], 1e-12);
    EXPECT_THROW(normalised_rgb_from_spectrum(Spectrum{360.0, 1.0, std::vector<double>(471, 0.0)}),
                 InputError);
}

TEST(Spectra, D65IsWhite) {
    // D65 through the CMFs is within 3e-5 of the Rec.709 white in xy, so its RGB is (1,1,1) to ~1e-3.
    const Vec3 rgb = normalised_rgb_from_spectrum(d65_spectrum());
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(rgb[k], 1.0, 1.5e-3) << k;
}

TEST(Spectra, NarrowBandLedsHaveTheirHues) {
    const Vec3 red = normalised_rgb_from_spectrum(*named_spectrum("led-red"));
    EXPECT_GT(red.r, 4.0);  // a saturated red needs ~1/0.2126 of R for unit luminance
    EXPECT_LT(red.g, 0.05 * red.r);
    EXPECT_LT(red.b, 0.05 * red.r);

    const Vec3 green = normalised_rgb_from_spectrum(*named_spectrum("led-green"));
    EXPECT_GT(green.g, 10.0 * green.r);
    EXPECT_GT(green.g, 10.0 * green.b);

    const Vec3 blue = normalised_rgb_from_spectrum(*named_spectrum("led-blue"));
    EXPECT_GT(blue.b, 10.0);  // a saturated blue needs ~1/0.0722 of B
    EXPECT_LT(blue.r, 0.05 * blue.b);
    EXPECT_LT(blue.g, 0.05 * blue.b);

    const Vec3 yellow = normalised_rgb_from_spectrum(*named_spectrum("led-yellow"));
    EXPECT_GT(yellow.r, yellow.g);
    EXPECT_GT(yellow.g, 0.1 * yellow.r);  // amber: red plus some green, no blue
    EXPECT_LT(yellow.b, 0.01);

    // The narrow-band LEDs sit near the spectral locus at their peaks (CIE 15:2004).
    const glm::dvec2 red_xy = xy_of(spectrum_to_xyz(*named_spectrum("led-red")));
    EXPECT_NEAR(red_xy.x, 0.70, 0.02);  // locus at 625 nm: (0.7006, 0.2993)
    EXPECT_NEAR(red_xy.y, 0.30, 0.02);
}

TEST(Spectra, WhiteLedIsACoolWhite) {
    const Spectrum led = white_led_spectrum();
    // Two bands: the blue pump (local maximum near 450 nm) and the phosphor (near 565 nm).
    EXPECT_GT(led.at(450.0), led.at(430.0));
    EXPECT_GT(led.at(450.0), led.at(480.0));
    EXPECT_GT(led.at(560.0), led.at(500.0));
    EXPECT_GT(led.at(560.0), led.at(650.0));
    const glm::dvec2 xy = xy_of(spectrum_to_xyz(led));
    // McCamy (1992) correlated colour temperature, a published closed-form approximation.
    const double n = (xy.x - 0.3320) / (0.1858 - xy.y);
    const double cct_k = 449.0 * n * n * n + 3525.0 * n * n + 6823.3 * n + 5520.33;
    EXPECT_GT(cct_k, 5500.0);
    EXPECT_LT(cct_k, 7000.0);
    EXPECT_LT(glm::length(xy - kWhite), 0.01);
}

// ---------------------------------------------------------------------------
// Light colours: normalised RGB and K2012 table 4.1.

TEST(NormalisedRgb, UnitLuminanceAndClipping) {
    // In gamut: clipping changes nothing.
    const Vec3 a = normalised_rgb_from_xy({0.35, 0.40}, false);
    const Vec3 b = normalised_rgb_from_xy({0.35, 0.40}, true);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], 1e-15);
    EXPECT_NEAR(luminance_of_linear_rgb(a), 1.0, 1e-12);

    // The 520 nm locus point (CIE 15: 0.07430, 0.83380) is far outside the gamut: negative R unclipped.
    const Vec3 raw = normalised_rgb_from_xy({0.07430, 0.83380}, false);
    EXPECT_LT(raw.r, -0.5);
    EXPECT_NEAR(luminance_of_linear_rgb(raw), 1.0, 1e-12);
    const Vec3 clipped = normalised_rgb_from_xy({0.07430, 0.83380}, true);
    for (int k = 0; k < 3; ++k) EXPECT_GE(clipped[k], 0.0);
    EXPECT_NEAR(luminance_of_linear_rgb(clipped), 1.0, 1e-12);
}

TEST(NormalisedRgb, RejectsNonColours) {
    EXPECT_THROW(normalised_rgb_from_xy({0.3, 0.0}), InputError);
    EXPECT_THROW(normalised_rgb_from_xy({0.7, 0.5}), InputError);
    EXPECT_THROW(normalised_rgb_from_xy({-0.1, 0.5}), InputError);
    EXPECT_THROW(normalised_rgb_from_xy({std::nan(""), 0.3}), InputError);
}

struct Table41Row {
    const char* name;
    double x2, y2;  // "Closest sRGB xy" as printed (2 decimals)
    Vec3 rgb;       // "Normalized linear RGB" as printed (4 decimals)
};
// K2012 table 4.1.
// clang-format off
const Table41Row kTable41[] = {
    {"white", 0.31, 0.33, {1.0000, 1.0000, 1.0000}},
    {"red", 0.64, 0.33, {4.7021, 0.0000, 0.0000}},
    {"red-optimum", 0.62, 0.32, {4.6478, 0.0059, 0.1020}},
    {"green", 0.28, 0.52, {0.0160, 1.3701, 0.2326}},
    {"blue", 0.15, 0.06, {0.0000, 0.0000, 13.8552}},
    {"yellow", 0.54, 0.41, {2.6700, 0.6045, 0.0000}},
};
// clang-format on

TEST(IalaColours, Table41IsReproduced) {
    for (const auto& row : kTable41) {
        const auto rgb = iala_colour_rgb(row.name);
        ASSERT_TRUE(rgb.has_value()) << row.name;
        const double largest = std::max({row.rgb.r, row.rgb.g, row.rgb.b});
        for (int k = 0; k < 3; ++k) {
            // Printed zeros must come out zero to 1e-3 absolute; the rest to 1e-3 of the largest.
            const double tol = row.rgb[k] == 0.0 ? 1e-3 : 1e-3 * largest;
            EXPECT_NEAR((*rgb)[k], row.rgb[k], tol) << row.name << " component " << k;
        }
        EXPECT_NEAR(luminance_of_linear_rgb(*rgb), 1.0, 1e-12) << row.name;
        // K2012 §4.1 chose every point inside the sRGB gamut or on its edge ("gamut mapping" of fig 4.3),
        // so the stored xy must reproduce the table without the help of clipping.
        const Vec3 unclipped = normalised_rgb_from_xy(*iala_colour_xy(row.name), false);
        for (int k = 0; k < 3; ++k) {
            const double tol = row.rgb[k] == 0.0 ? 1e-3 : 1e-3 * largest;
            EXPECT_NEAR(unclipped[k], row.rgb[k], tol) << row.name << " component " << k << ", unclipped";
        }
    }
}

TEST(IalaColours, ChromaticitiesRoundToTheTable) {
    for (const auto& row : kTable41) {
        const auto xy = iala_colour_xy(row.name);
        ASSERT_TRUE(xy.has_value()) << row.name;
        EXPECT_NEAR(xy->x, row.x2, 0.005 + 1e-12) << row.name;
        EXPECT_NEAR(xy->y, row.y2, 0.005 + 1e-12) << row.name;
    }
    // White is D65 itself, red and blue are the Rec.709 primaries.
    EXPECT_EQ(*iala_colour_xy("white"), kWhite);
    EXPECT_EQ(*iala_colour_xy("red"), kRed);
    EXPECT_EQ(*iala_colour_xy("blue"), kBlue);
    const Vec3 white = *iala_colour_rgb("white");
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(white[k], 1.0, 1e-12);
    EXPECT_NEAR(iala_colour_rgb("red")->r, 1.0 / 0.2126, 1e-3 / 0.2126);
    EXPECT_NEAR(iala_colour_rgb("blue")->b, 1.0 / 0.0722, 1e-3 / 0.0722);
}

TEST(IalaColours, PrintedYellowXyIsOutsideTheGamut) {
    // Why yellow is not stored as the printed (0.54, 0.41): that point is just beyond the red-green
    // edge of the gamut and gives B = -0.0018, where the table has 0.0000 (the thesis put yellow on
    // the edge, K2012 §4.1). The stored point reproduces B = 0 to 1e-3.
    EXPECT_LT(normalised_rgb_from_xy({0.54, 0.41}, false).b, -1e-3);
    EXPECT_NEAR(normalised_rgb_from_xy(*iala_colour_xy("yellow"), false).b, 0.0, 1e-3);
}

TEST(IalaColours, NamesAndChartLetters) {
    const auto names = iala_colour_names();
    EXPECT_EQ(names, (std::vector<std::string>{"white", "red", "red-optimum", "green", "blue", "yellow"}));
    EXPECT_FALSE(iala_colour_xy("purple").has_value());
    EXPECT_FALSE(iala_colour_rgb("White").has_value());

    EXPECT_EQ(iala_colour_from_chart_letter("W"), "white");
    EXPECT_EQ(iala_colour_from_chart_letter("R"), "red");
    EXPECT_EQ(iala_colour_from_chart_letter("G"), "green");
    EXPECT_EQ(iala_colour_from_chart_letter("Bu"), "blue");
    EXPECT_EQ(iala_colour_from_chart_letter("Y"), "yellow");
    // On charts "B" is not blue (blue is "Bu"); letters are case-sensitive.
    EXPECT_FALSE(iala_colour_from_chart_letter("B").has_value());
    EXPECT_FALSE(iala_colour_from_chart_letter("w").has_value());
    EXPECT_FALSE(iala_colour_from_chart_letter("").has_value());
}

}  // namespace
}  // namespace atonlab::display
