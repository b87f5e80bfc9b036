// The display model and encoder (display_model.h): transfer functions and
// their inverses, SMPTE ST 2084 reference points, validation, quantisation and
// the spatio-temporal dither. Expected values come from the standards (ST 2084,
// IEC 61966-2-1) or from analytic identities (an inverse composed with its
// function, the mean of a stratified threshold set).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "atonlab/display/display_encodings.h"
#include "atonlab/display/display_model.h"
#include "input_error.h"
#include "text_contains.h"

namespace atonlab::display {
namespace {

using test::input_error_of;

using ::atonlab::test::contains;

// A measured-looking LUT with a flat toe (two equal readings) and uneven spacing.
std::vector<LutPoint> measured_lut(double scale) {
    return {{0.0, 0.05 * scale}, {0.05, 0.05 * scale}, {0.1, 0.12 * scale},  {0.25, 1.1 * scale},
            {0.5, 5.0 * scale},  {0.7, 11.0 * scale},  {0.85, 16.5 * scale}, {1.0, 22.0 * scale}};
}

DisplayModel gog_display() {
    // A cut-off on blue (b < 0: dark until V = 0.01), an offset on red (b > 0).
    return DisplayModel::gog(
        {GogParams{0.05, 0.04, 4.0, 2.4}, GogParams{0.1, 0.0, 7.0, 2.2}, GogParams{0.02, -0.02, 2.0, 2.3}}, "test GOG");
}

std::vector<DisplayModel> every_kind() {
    return {DisplayModel::srgb(120.0, 0.2), gog_display(), DisplayModel::pq(1000.0, 0.005),
            DisplayModel::lut({measured_lut(1.0), measured_lut(3.3), measured_lut(0.35)}, "test LUT")};
}

/// The exact (unquantised) code value the encoder aims at for channel c.
double target_code(const DisplayModel& d, int c, double relative, int bits) {
    const double L = relative * d.channels[static_cast<std::size_t>(c)].max_cd_m2();
    return d.drive_for_luminance(c, L) * static_cast<double>((1 << bits) - 1);
}

/// The relative input that makes channel c aim at code value q exactly.
double relative_for_code(const DisplayModel& d, int c, double q, int bits) {
    const auto& ch = d.channels[static_cast<std::size_t>(c)];
    return ch.luminance_cd_m2(q / static_cast<double>((1 << bits) - 1)) / ch.max_cd_m2();
}

// ---------------------------------------------------------------------------
// SMPTE ST 2084.

TEST(Pq, ReferencePoints) {
    // ST 2084 signal for 100 cd/m² (the value colour-science's eotf_ST2084 docs use) and the ends.
    EXPECT_NEAR(pq_inverse_eotf(100.0), 0.508078421517399, 1e-12);
    EXPECT_NEAR(pq_eotf_cd_m2(0.508078421517399), 100.0, 1e-9);
    EXPECT_NEAR(pq_inverse_eotf(10000.0), 1.0, 1e-15);
    EXPECT_NEAR(pq_eotf_cd_m2(1.0), 10000.0, 1e-9);
    EXPECT_EQ(pq_eotf_cd_m2(0.0), 0.0);
    // 1000 cd/m² is at 0.7518 (the signal HDR10 mastering displays peak at).
    EXPECT_NEAR(pq_inverse_eotf(1000.0), 0.751827, 1e-6);
    // The inverse EOTF of 0 is c1^m2 (about 7.3e-7), not 0: below half a 10-bit code.
    EXPECT_NEAR(pq_inverse_eotf(0.0), std::pow(0.8359375, 78.84375), 1e-20);
    EXPECT_LT(pq_inverse_eotf(0.0) * 1023.0, 0.5);
    for (double n = 1.0 / 64.0; n <= 1.0; n += 1.0 / 64.0)
        EXPECT_NEAR(pq_inverse_eotf(pq_eotf_cd_m2(n)), n, 1e-12) << n;
}

TEST(Pq, DisplayEncodesTheStandardCodeValues) {
    const auto display = DisplayModel::pq(10000.0);
    ASSERT_NO_THROW(display.validate());
    const EncodeSettings ten{10, Dither::none, 0};
    // Grey at 100 cd/m² on a 10000 cd/m² PQ display: 10-bit full-range code round(0.508078 * 1023) = 520.
    EXPECT_EQ(encode_pixel(display, glm::dvec3(0.01), {0, 0}, 0, ten), glm::ivec3(520));
    EXPECT_EQ(encode_pixel(display, glm::dvec3(1.0), {0, 0}, 0, ten), glm::ivec3(1023));
    EXPECT_EQ(encode_pixel(display, glm::dvec3(0.0), {0, 0}, 0, ten), glm::ivec3(0));
    // A 1000 cd/m² display clips there: its white is code round(0.751827 * 1023) = 769.
    const auto hdr = DisplayModel::pq(1000.0);
    EXPECT_EQ(encode_pixel(hdr, glm::dvec3(1.0), {0, 0}, 0, ten), glm::ivec3(769));
    EXPECT_EQ(encode_pixel(hdr, glm::dvec3(0.1), {0, 0}, 0, ten), glm::ivec3(520));  // 100 cd/m² again
    // What the screen then emits: 100 cd/m² within the half-code quantisation.
    const double L = displayed_luminance_cd_m2(hdr, glm::ivec3(520), 10);
    EXPECT_NEAR(L, 100.0, 100.0 * 0.01);
}

// ---------------------------------------------------------------------------
// Transfer functions and their inverses.

TEST(DisplayModel, FactoriesAreValidAndAddUpToPeakAndBlack) {
    for (const auto& d : every_kind()) {
        SCOPED_TRACE(d.name);
        EXPECT_NO_THROW(d.validate());
        const glm::dvec3 white = displayed_luminance_rgb(d, glm::ivec3(255), 8);
        const glm::dvec3 black = displayed_luminance_rgb(d, glm::ivec3(0), 8);
        EXPECT_NEAR(white.r + white.g + white.b, d.peak_cd_m2, 1e-9 * d.peak_cd_m2);
        EXPECT_NEAR(black.r + black.g + black.b, d.black_cd_m2, 1e-9 * d.peak_cd_m2);
    }
    // sRGB and PQ split peak and black by the Rec.709 weights.
    const auto s = DisplayModel::srgb(100.0, 0.5);
    EXPECT_NEAR(s.channels[0].max_cd_m2(), 21.26, 0.01);
    EXPECT_NEAR(s.channels[1].max_cd_m2(), 71.52, 0.01);
    EXPECT_NEAR(s.channels[2].max_cd_m2(), 7.22, 0.01);
    EXPECT_NEAR(s.channels[1].min_cd_m2(), 0.5 * 0.7152, 1e-4);
}

TEST(DisplayModel, DriveForLuminanceInvertsEveryKind) {
    for (const auto& d : every_kind()) {
        SCOPED_TRACE(d.name);
        for (int c = 0; c < 3; ++c) {
            const auto& ch = d.channels[static_cast<std::size_t>(c)];
            for (int i = 0; i <= 200; ++i) {
                const double v = i / 200.0;
                const double L = ch.luminance_cd_m2(v);
                const double v2 = d.drive_for_luminance(c, L);
                // The luminance is reproduced wherever the curve is defined...
                EXPECT_NEAR(ch.luminance_cd_m2(v2), L, 1e-12 * d.peak_cd_m2) << "c " << c << " V " << v;
                // ...and the drive too where the curve rises (the smallest drive on a flat toe).
                if (L > ch.min_cd_m2() && L < ch.max_cd_m2() && ch.luminance_cd_m2(v - 1e-6) < L) {
                    EXPECT_NEAR(v2, v, 1e-10) << "c " << c << " V " << v;
                }
                if (L <= ch.min_cd_m2()) {
                    EXPECT_EQ(v2, 0.0);
                }
            }
            EXPECT_EQ(d.drive_for_luminance(c, -1.0), 0.0);
            EXPECT_EQ(d.drive_for_luminance(c, std::numeric_limits<double>::quiet_NaN()), 0.0);
            EXPECT_EQ(d.drive_for_luminance(c, 1e12), d.drive_for_luminance(c, ch.max_cd_m2()));
        }
    }
}

TEST(DisplayModel, GogInverseIsTheClosedForm) {
    const GogParams g{0.1, -0.05, 3.0, 2.35};
    const auto d = DisplayModel::gog({g, g, g});
    for (const double v : {0.02, 0.1, 0.37, 0.5, 0.999, 1.0}) {
        const double L = g.a + std::pow(g.b + g.k * v, g.gamma);
        EXPECT_NEAR(d.drive_for_luminance(1, L), v, 1e-14) << v;
    }
    // Below the cut-off V = -b/k the display stays at a: drive 0 is the smallest that gives it.
    EXPECT_EQ(d.drive_for_luminance(1, g.a), 0.0);
    EXPECT_EQ(d.channel_luminance_cd_m2(1, 0.01), g.a);
}

TEST(DisplayModel, LutInterpolationIsMonotoneAndPassesThroughTheKnots) {
    const auto pts = measured_lut(2.0);
    const auto d = DisplayModel::lut({pts, pts, pts});
    const auto& ch = d.channels[0];
    for (const auto& p : pts) EXPECT_DOUBLE_EQ(ch.luminance_cd_m2(p.drive), p.cd_m2);
    double prev = -1.0;
    for (int i = 0; i <= 10000; ++i) {
        const double v = i / 10000.0;
        const double L = ch.luminance_cd_m2(v);
        EXPECT_GE(L, prev) << v;
        prev = L;
        // No overshoot: each segment stays between its knots (PCHIP's promise).
        const auto hi =
            std::upper_bound(pts.begin(), pts.end(), v, [](double x, const LutPoint& p) { return x < p.drive; });
        if (hi != pts.begin() && hi != pts.end()) {
            EXPECT_GE(L, (hi - 1)->cd_m2 - 1e-12);
            EXPECT_LE(L, hi->cd_m2 + 1e-12);
        }
    }
    // The flat toe stays flat.
    EXPECT_DOUBLE_EQ(ch.luminance_cd_m2(0.03), pts[0].cd_m2);
}

// ---------------------------------------------------------------------------
// Validation: bad displays are InputErrors that name the field.

TEST(DisplayValidate, BlackAtOrAbovePeakNamesTheKey) {
    const auto msg = input_error_of([] { DisplayModel::srgb(100.0, 150.0, "office").validate(); });
    EXPECT_TRUE(contains(msg, "key 'black_cd_m2'")) << msg;
    EXPECT_TRUE(contains(msg, "office")) << msg;
    EXPECT_TRUE(contains(msg, "below the peak")) << msg;
    EXPECT_TRUE(contains(input_error_of([] { DisplayModel::srgb(100.0, 100.0).validate(); }), "black_cd_m2"));
    // The location of the definition is kept and prefixes the key.
    const auto located = input_error_of([] {
        DisplayModel::srgb(100.0, 150.0).validate(SourceLocation{"study.toml", 12, 0, "display"});
    });
    EXPECT_TRUE(contains(located, "study.toml:12")) << located;
    EXPECT_TRUE(contains(located, "key 'display.black_cd_m2'")) << located;
}

TEST(DisplayValidate, NonPositivePeakAndNegativeBlack) {
    EXPECT_TRUE(contains(input_error_of([] { DisplayModel::srgb(0.0, 0.0).validate(); }), "key 'peak_cd_m2'"));
    EXPECT_TRUE(contains(input_error_of([] { DisplayModel::srgb(-5.0, 0.0).validate(); }), "key 'peak_cd_m2'"));
    EXPECT_TRUE(contains(input_error_of([] { DisplayModel::srgb(100.0, -0.1).validate(); }), "key 'black_cd_m2'"));
    EXPECT_TRUE(contains(input_error_of([] { DisplayModel::srgb(std::nan(""), 0.1).validate(); }), "peak_cd_m2"));
    EXPECT_TRUE(contains(input_error_of([] { DisplayModel::pq(12000.0).validate(); }), "10000"));
}

TEST(DisplayValidate, LutEntriesThatBreakOrderAreNamed) {
    auto lut = measured_lut(1.0);
    lut[3].drive = lut[2].drive;  // not strictly increasing in drive
    auto msg = input_error_of([&] { DisplayModel::lut({measured_lut(1.0), lut, measured_lut(1.0)}).validate(); });
    EXPECT_TRUE(contains(msg, "key 'green.lut[3].drive'")) << msg;
    EXPECT_TRUE(contains(msg, "increase strictly")) << msg;

    lut = measured_lut(1.0);
    lut[5].cd_m2 = lut[4].cd_m2 * 0.9;  // luminance falls
    msg = input_error_of([&] { DisplayModel::lut({lut, measured_lut(1.0), measured_lut(1.0)}).validate(); });
    EXPECT_TRUE(contains(msg, "key 'red.lut[5].cd_m2'")) << msg;

    lut = measured_lut(1.0);
    lut.back().drive = 0.9;  // does not reach drive 1
    msg = input_error_of([&] { DisplayModel::lut({lut, lut, lut}).validate(); });
    EXPECT_TRUE(contains(msg, "lut[7].drive")) << msg;

    msg = input_error_of([&] { DisplayModel::lut({std::vector<LutPoint>{{0.0, 1.0}}, lut, lut}).validate(); });
    EXPECT_TRUE(contains(msg, "key 'red.lut'")) << msg;
}

TEST(DisplayValidate, GogParametersGivingABadCurve) {
    auto with = [](GogParams g) { return DisplayModel::gog({GogParams{}, g, GogParams{}}); };
    EXPECT_TRUE(contains(input_error_of([&] { with({0.1, 0.0, -2.0, 2.2}).validate(); }), "key 'green.gog.k'"));
    EXPECT_TRUE(contains(input_error_of([&] { with({0.1, 0.0, 2.0, -1.0}).validate(); }), "key 'green.gog.gamma'"));
    EXPECT_TRUE(contains(input_error_of([&] {
                             with({0.1, 0.0, 2.0, std::nan("")}).validate();
                         }),
                         "key 'green.gog.gamma'"));
    EXPECT_TRUE(contains(input_error_of([&] { with({0.1, -3.0, 2.0, 2.2}).validate(); }), "key 'green.gog.b'"));
    EXPECT_TRUE(contains(input_error_of([&] { with({-1.0, 0.0, 2.0, 2.2}).validate(); }), "key 'green.gog.a'"));
}

// ---------------------------------------------------------------------------
// The encoder.

TEST(Encoder, SrgbRoundTripIsWithinHalfACodeStep) {
    const auto d = DisplayModel::srgb(100.0, 0.1);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (const int bits : {8, 10}) {
        const int max_code = (1 << bits) - 1;
        const EncodeSettings s{bits, Dither::none, 0};
        for (int i = 0; i < 3000; ++i) {
            const glm::dvec3 rel(u(rng), u(rng), u(rng));
            const glm::ivec3 code = encode_pixel(d, rel, {i, 0}, 0, s);
            for (int c = 0; c < 3; ++c) {
                const auto& ch = d.channels[static_cast<std::size_t>(c)];
                // Targets below the channel's black clip to it.
                const double target = std::max(rel[c] * ch.max_cd_m2(), ch.min_cd_m2());
                // The target lies between the luminances half a code below and above the code sent.
                const double lo = ch.luminance_cd_m2((code[c] - 0.5) / max_code);
                const double hi = ch.luminance_cd_m2((code[c] + 0.5) / max_code);
                EXPECT_LE(lo, target * (1 + 1e-12)) << bits << " bits, c " << c << " rel " << rel[c];
                EXPECT_GE(hi, target * (1 - 1e-12)) << bits << " bits, c " << c << " rel " << rel[c];
            }
        }
    }
}

TEST(Encoder, OutOfRangeInputsNeverLeaveTheCodeRange) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    for (const auto& d : every_kind()) {
        SCOPED_TRACE(d.name);
        for (const int bits : {8, 10}) {
            const int max_code = (1 << bits) - 1;
            for (const Dither dither : {Dither::none, Dither::spatiotemporal}) {
                const EncodeSettings s{bits, dither, 3};
                for (const double x : {nan, -inf, -1.0, -1e-300, 0.0, 1.0, 1.0000001, 1.2, 1e30, inf}) {
                    for (int px = 0; px < 64; ++px) {
                        const glm::ivec3 code = encode_pixel(d, glm::dvec3(x), {px, 3 * px}, 7u * px, s);
                        for (int c = 0; c < 3; ++c) {
                            ASSERT_GE(code[c], 0);
                            ASSERT_LE(code[c], max_code);
                        }
                        // NaN and everything at or below 0 is black; 1 and above is the white code,
                        // whatever the dither (its threshold is in [0, 1)): full drive except on a PQ
                        // display, whose white is its peak's PQ code.
                        if (std::isnan(x) || x <= 0.0) {
                            EXPECT_EQ(code, glm::ivec3(0)) << x;
                        }
                        if (x >= 1.0 && !d.channels[0].follows("pq")) {
                            EXPECT_EQ(code, glm::ivec3(max_code)) << x;
                        }
                        if (x >= 1.0) {
                            EXPECT_EQ(code, encode_pixel(d, glm::dvec3(1.0), {px, 3 * px}, 7u * px, s)) << x;
                        }
                    }
                }
            }
        }
    }
}

TEST(Encoder, BitsOutsideOneToSixteenAreAnInputError) {
    const auto d = DisplayModel::srgb(100.0, 0.1);
    for (const int bits : {0, 17, -8}) {
        const auto msg = input_error_of([&] { encode_pixel(d, glm::dvec3(0.5), {0, 0}, 0, EncodeSettings{bits}); });
        EXPECT_TRUE(contains(msg, "key 'bits'")) << msg;
    }
}

TEST(Encoder, DitherNoneRoundsToNearestEverywhere) {
    const auto d = DisplayModel::srgb(100.0, 0.1);
    const EncodeSettings s{8, Dither::none, 0};
    const glm::dvec3 rel(0.2, 0.5, 0.8);
    const glm::ivec3 first = encode_pixel(d, rel, {0, 0}, 0, s);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(first[c], static_cast<int>(std::lround(target_code(d, c, rel[c], 8))));
    for (int i = 0; i < 500; ++i) EXPECT_EQ(encode_pixel(d, rel, {i * 7, i * 3}, static_cast<unsigned>(i), s), first);
}

// ---------------------------------------------------------------------------
// The spatio-temporal dither.

TEST(Dither, EveryTileHoldsEachStratumOnce) {
    // Any 64×64 window, any frame, channel and seed: floor(threshold · 4096) is a permutation of 0..4095.
    for (const auto& [x0, y0, frame, channel, seed] : std::vector<std::tuple<int, int, unsigned, int, unsigned>>{
             {0, 0, 0, 0, 0}, {17, -5, 1, 1, 9}, {1000, 333, 77, 2, 123456}}) {
        std::vector<int> seen(4096, 0);
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                const double t = dither_threshold({x0 + x, y0 + y}, frame, channel, seed);
                ASSERT_GE(t, 0.0);
                ASSERT_LT(t, 1.0);
                ++seen[static_cast<std::size_t>(t * 4096.0)];
            }
        EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), 4096);
    }
}

TEST(Dither, FlatPatchMeanEqualsTheTarget) {
    // Over a flat 128×64 patch (two 64×64 tiles) the mean code equals the unquantised
    // target: each tile's thresholds are stratified, so the error is at most 1/4096 code.
    double worst = 0.0;
    for (const auto& d : every_kind()) {
        for (const int bits : {8, 10}) {
            const EncodeSettings s{bits, Dither::spatiotemporal, 42};
            for (const double rel : {0.0021, 0.18, 0.731, 0.9977}) {
                for (const unsigned frame : {0u, 1001u}) {
                    glm::dvec3 sum(0.0);
                    for (int y = 0; y < 64; ++y) {
                        for (int x = 0; x < 128; ++x)
                            sum += glm::dvec3(encode_pixel(d, glm::dvec3(rel), {x + 5, y - 17}, frame, s));
                    }
                    for (int c = 0; c < 3; ++c) {
                        const double err = std::abs(sum[c] / (128.0 * 64.0) - target_code(d, c, rel, bits));
                        worst = std::max(worst, err);
                        EXPECT_LE(err, 1e-3) << d.name << " " << bits << " bits, rel " << rel << ", c " << c;
                    }
                }
            }
        }
    }
    std::printf("flat-patch mean code error, worst over displays/levels/frames: %.2e codes\n", worst);
}

TEST(Dither, TemporalSequenceHasLittleLowFrequencyPower) {
    // At one pixel, the code sent over N frames. For white noise the fluctuation
    // power below a frequency f (cycles/frame) is the fraction 2 f of the total;
    // the golden-ratio shift pushes power up in frequency (~ f² at low f), so each
    // band must hold less than a fifth of white noise's share. At 60 Hz the bands
    // are 0-3 Hz and 0-1.2 Hz, where flicker would be seen.
    const auto d = DisplayModel::srgb(100.0, 0.1);
    constexpr int N = 4096;
    constexpr int bands[2] = {N / 20, N / 50};  // 0.05 and 0.02 cycles/frame
    double worst[2] = {0.0, 0.0}, worst_mean = 0.0;
    std::vector<std::complex<double>> twiddle(N);
    for (int t = 0; t < N; ++t) twiddle[static_cast<std::size_t>(t)] = std::polar(1.0, -2.0 * std::numbers::pi * t / N);
    for (const double frac : {0.1, 0.25, 0.5, 0.618, 0.9}) {
        for (const glm::ivec2 px : {glm::ivec2(0, 0), glm::ivec2(13, 40), glm::ivec2(63, 7)}) {
            const double rel = relative_for_code(d, 1, 100.0 + frac, 8);
            std::vector<double> seq(N);
            double mean = 0.0;
            for (int f = 0; f < N; ++f) {
                seq[static_cast<std::size_t>(f)] = encode_pixel(d, glm::dvec3(rel), px, static_cast<unsigned>(f), {}).g;
                mean += seq[static_cast<std::size_t>(f)] / N;
            }
            worst_mean = std::max(worst_mean, std::abs(mean - target_code(d, 1, rel, 8)));
            double total = 0.0;
            for (auto& v : seq) {
                v -= mean;
                total += v * v;
            }
            // Parseval: Σ_k |X_k|² = N Σ e²; a band is k = 1..K and its mirror image.
            double low = 0.0;
            for (int k = 1; k <= bands[0]; ++k) {
                std::complex<double> X = 0.0;
                for (int t = 0; t < N; ++t)
                    X += seq[static_cast<std::size_t>(t)] * twiddle[static_cast<std::size_t>((k * t) % N)];
                low += 2.0 * std::norm(X);
                for (int b = 0; b < 2; ++b) {
                    if (k != bands[b]) continue;
                    const double fraction = low / (N * total);
                    const double white = 2.0 * bands[b] / N;
                    worst[b] = std::max(worst[b], fraction / white);
                    EXPECT_LT(fraction, 0.2 * white) << "frac " << frac << " pixel " << px.x << "," << px.y;
                }
            }
        }
    }
    std::printf(
        "temporal power below 0.05 / 0.02 cycles/frame: worst %.3f / %.3f of white noise's; "
        "worst %d-frame mean error %.2e codes\n",
        worst[0], worst[1], N, worst_mean);
    // The per-pixel mean over time converges too (golden-ratio sequence: discrepancy ~ log N / N).
    EXPECT_LT(worst_mean, 2e-3);
}

// ---------------------------------------------------------------------------
// GPU parameters.

TEST(GpuParams, PackTheModelAndTheLutKnots) {
    const auto d = DisplayModel::lut({measured_lut(1.0), measured_lut(3.3), measured_lut(0.35)});
    const auto p = gpu_display_params(d, EncodeSettings{10, Dither::spatiotemporal, 5});
    const auto knots = gpu_display_lut(d);
    ASSERT_EQ(knots.size(), 3u * 3u * 8u);
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(p.channel[c].kind, display_encoding_index(display_encoding("lut")));
        EXPECT_EQ(p.channel[c].lut_first, 8 * c);
        EXPECT_EQ(p.channel[c].lut_count, 8);
        EXPECT_DOUBLE_EQ(p.channel[c].white_cd_m2, d.channels[static_cast<std::size_t>(c)].max_cd_m2());
    }
    EXPECT_EQ(p.bits, 10);
    EXPECT_EQ(p.seed, 5u);
    EXPECT_EQ(gpu_display_lut(DisplayModel::srgb(100, 0.1)).size(), 3u);  // a dummy knot to bind
    EXPECT_THROW(gpu_display_params(DisplayModel::srgb(100, 200), {}), InputError);
}

}  // namespace
}  // namespace atonlab::display
