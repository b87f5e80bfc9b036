// Numerical stress tests of the display model and encoder (issue 8, display_model.h):
// every display encoding (sRGB, GOG, measured LUT with a flat toe, PQ) at 8, 10 and 16 bits,
// dither on and off: the encoder is non-decreasing in the relative value from exact 0 to
// far above peak (1e30, +inf), the decoder non-decreasing in the code, exact 0 and NaN
// give black, above-peak gives full drive, and the inverse transfer functions never step
// backwards at their breakpoints (swept one ulp at a time; rounding noise of 1e-12 allowed). PQ is swept over
// 0 … 1e9 cd/m². docs/numerical-behaviour.md lists the singular points.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "atonlab/display/display_model.h"

namespace atonlab::display {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::vector<LutPoint> measured_lut(double scale) {
    // A flat toe (two equal readings), uneven spacing: PCHIP keeps it monotone.
    return {{0.0, 0.05 * scale}, {0.05, 0.05 * scale}, {0.1, 0.12 * scale},  {0.25, 1.1 * scale},
            {0.5, 5.0 * scale},  {0.7, 11.0 * scale},  {0.85, 16.5 * scale}, {1.0, 22.0 * scale}};
}

std::vector<DisplayModel> every_kind() {
    return {
        DisplayModel::srgb(100.0, 0.0, "sRGB black 0"),
        DisplayModel::srgb(120.0, 0.2, "sRGB"),
        DisplayModel::gog(
            {GogParams{0.05, 0.04, 4.0, 2.4}, GogParams{0.1, 0.0, 7.0, 2.2}, GogParams{0.02, -0.02, 2.0, 2.3}}, "GOG"),
        DisplayModel::pq(1000.0, 0.005),
        DisplayModel::pq(10000.0, 0.0, "PQ 10000"),
        DisplayModel::lut({measured_lut(1.0), measured_lut(3.3), measured_lut(0.35)}, "LUT")};
}

/// Relative values 0 … 2 (dense), then far above peak; sorted, exact 0 and 1 included.
std::vector<double> relative_sweep(std::uint32_t seed) {
    std::vector<double> v = {0.0, 1.0};
    for (int i = 1; i <= 4000; ++i) v.push_back(std::pow(10.0, -8.0 + 8.3 * i / 4000.0));  // 1e-8 … 2
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.2);
    for (int i = 0; i < 3000; ++i) v.push_back(u(rng));
    for (double big : {10.0, 1e9, 1e30, 1e300, kInf}) v.push_back(big);
    std::sort(v.begin(), v.end());
    return v;
}

TEST(StressDisplayModel, EncodeNonDecreasingFromExactZeroToAbovePeak) {
    // At one pixel and frame the dither threshold is fixed, so the code must follow the
    // value monotonically; exact 0 (and NaN, negatives, -inf) is code 0, >= 1 is full drive.
    const std::vector<double> values = relative_sweep(51);
    long checked = 0;
    for (const DisplayModel& display : every_kind()) {
        ASSERT_NO_THROW(display.validate()) << display.name;
        for (int bits : {8, 10, 16}) {
            for (Dither dither : {Dither::none, Dither::spatiotemporal}) {
                const EncodeSettings settings{bits, dither, 99};
                const int max_code = (1 << bits) - 1;
                for (const glm::ivec2 pixel : {glm::ivec2(0, 0), glm::ivec2(17, 41), glm::ivec2(63, 5)}) {
                    glm::ivec3 prev(0);
                    for (double v : values) {
                        const glm::ivec3 code = encode_pixel(display, glm::dvec3(v), pixel, 7, settings);
                        for (int c = 0; c < 3; ++c) {
                            ASSERT_GE(code[c], prev[c]) << display.name << " " << bits << " bits, value " << v;
                            ASSERT_LE(code[c], max_code);
                        }
                        prev = code;
                        ++checked;
                    }
                    for (double black : {0.0, -0.0, -1.0, -kInf, std::nan("")}) {
                        ASSERT_EQ(encode_pixel(display, glm::dvec3(black), pixel, 7, settings), glm::ivec3(0))
                            << display.name << " " << black;
                    }
                    // At and above 1 the channel's full luminance L(1): full drive, except on PQ,
                    // whose codes are absolute (the code for the display's peak, 1000 cd/m² = 0.75).
                    const glm::ivec3 at_one = encode_pixel(display, glm::dvec3(1.0), pixel, 7, settings);
                    if (!display.channels[0].follows("pq")) {
                        ASSERT_EQ(at_one, glm::ivec3(max_code)) << display.name;
                    }
                    for (double white : {1.0 + 1e-9, 2.0, 1e300, kInf}) {
                        ASSERT_EQ(encode_pixel(display, glm::dvec3(white), pixel, 7, settings), at_one)
                            << display.name << " " << white;
                    }
                }
            }
        }
    }
    std::printf("encoder: %ld code triples non-decreasing in value\n", checked);
}

TEST(StressDisplayModel, DecodeNonDecreasingInTheCode) {
    // What the screen emits never falls as the code rises, at 8, 10 and 16 bits.
    for (const DisplayModel& display : every_kind()) {
        for (int bits : {8, 10, 16}) {
            const int max_code = (1 << bits) - 1;
            glm::dvec3 prev(-1.0);
            for (int q = 0; q <= max_code; ++q) {
                const glm::dvec3 L = displayed_luminance_rgb(display, glm::ivec3(q), bits);
                for (int c = 0; c < 3; ++c) {
                    ASSERT_TRUE(std::isfinite(L[c])) << display.name;
                    ASSERT_GE(L[c], prev[c]) << display.name << " " << bits << " bits, code " << q;
                }
                prev = L;
            }
            EXPECT_NEAR(displayed_luminance_cd_m2(display, glm::ivec3(0), bits), display.black_cd_m2,
                        1e-12 * display.peak_cd_m2)
                << display.name;
            EXPECT_NEAR(displayed_luminance_cd_m2(display, glm::ivec3(max_code), bits), display.peak_cd_m2,
                        1e-12 * display.peak_cd_m2)
                << display.name;
        }
    }
}

TEST(StressDisplayModel, InverseTransferNeverStepsBackAtItsBreakpoints) {
    // drive_for(L) at consecutive doubles around the sRGB toe (IEC 61966-2-1's rounded
    // breakpoint), the GOG cut-off, the LUT's flat toe and knots, and PQ's black/peak clips.
    auto sweep_around = [](const ChannelEncoding& ch, double L0, const std::string& what) {
        double L = L0;
        for (int i = 0; i < 3000; ++i) L = std::nextafter(L, -kInf);
        double prev = ch.drive_for(L);
        for (int i = 0; i < 6000; ++i) {
            L = std::nextafter(L, kInf);
            const double v = ch.drive_for(L);
            ASSERT_TRUE(std::isfinite(v) && v >= 0.0 && v <= 1.0) << what;
            // Steps back of ~1e-14 come from rounding in pow (PQ's m2 = 78.8 amplifies it) and the
            // LUT's Newton solve (a 16-bit code is 1.5e-5 wide); more is a real break.
            ASSERT_GE(v, prev - 1e-12) << what << " at L = " << L << ": " << v << " after " << prev;
            prev = v;
        }
    };
    const DisplayModel srgb = DisplayModel::srgb(100.0, 0.0);
    const ChannelEncoding& g = srgb.channels[1];
    // The decoder's switch at V = 0.04045 lies at L = white · 0.04045 / 12.92.
    sweep_around(g, g.white_cd_m2 * (0.04045 / 12.92), "sRGB toe");
    sweep_around(g, g.white_cd_m2 * 0.0031308, "sRGB IEC breakpoint");
    sweep_around(g, 0.0, "sRGB black");
    sweep_around(g, g.white_cd_m2, "sRGB white");
    const DisplayModel lut = DisplayModel::lut({measured_lut(1.0), measured_lut(3.3), measured_lut(0.35)});
    for (const LutPoint& k : lut.channels[0].lut) sweep_around(lut.channels[0], k.cd_m2, "LUT knot");
    const DisplayModel pq = DisplayModel::pq(1000.0, 0.005);
    sweep_around(pq.channels[1], pq.channels[1].black_cd_m2, "PQ black");
    sweep_around(pq.channels[1], pq.channels[1].white_cd_m2, "PQ peak");
    const DisplayModel gog = DisplayModel::gog(
        {GogParams{0.05, 0.04, 4.0, 2.4}, GogParams{0.1, 0.0, 7.0, 2.2}, GogParams{0.02, -0.02, 2.0, 2.3}});
    sweep_around(gog.channels[2], gog.channels[2].min_cd_m2(), "GOG cut-off");
}

TEST(StressDisplayModel, PqOverZeroToOneE9CdPerSquareMetre) {
    // ST 2084 is absolute to 10000 cd/m²; beyond, the inverse EOTF clips to signal 1.
    // Non-decreasing and finite from exact 0 to 1e9, and the EOTF over every 16-bit code.
    double prev = -1.0;
    std::vector<double> Ls = {0.0, std::numeric_limits<double>::denorm_min(), 1e-300, 10000.0, 1e9, kInf};
    for (int i = 0; i <= 6000; ++i) Ls.push_back(std::pow(10.0, -9.0 + 18.0 * i / 6000.0));
    std::sort(Ls.begin(), Ls.end());
    for (double L : Ls) {
        const double n = pq_inverse_eotf(L);
        ASSERT_TRUE(std::isfinite(n) && n >= 0.0 && n <= 1.0) << L;
        ASSERT_GE(n, prev) << L;
        prev = n;
    }
    EXPECT_NEAR(pq_inverse_eotf(0.0), 7.3e-7, 1e-7);  // ST 2084 maps 0 to (c1)^m2, not exactly 0
    EXPECT_EQ(pq_inverse_eotf(1e9), pq_inverse_eotf(10000.0));
    EXPECT_EQ(pq_inverse_eotf(std::nan("")), pq_inverse_eotf(0.0));
    double prev_L = -1.0;
    for (int q = 0; q <= 65535; ++q) {
        const double L = pq_eotf_cd_m2(q / 65535.0);
        ASSERT_TRUE(std::isfinite(L) && L >= 0.0 && L <= 10000.0 * (1 + 1e-12)) << q;
        ASSERT_GE(L, prev_L) << q;
        prev_L = L;
    }
    EXPECT_EQ(pq_eotf_cd_m2(0.0), 0.0);
}

}  // namespace
}  // namespace atonlab::display
