// Display calibration (calibration.h): readers for CSV and ArgyllCMS .ti3,
// monotonicity checks, GOG fits and the display model they define. The fits
// are checked against synthetic readings of known displays with seeded 1 %
// noise; the tolerances come from the noise itself (the fit's standard errors).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "atonlab/display/calibration.h"
#include "input_error.h"
#include "text_contains.h"

namespace atonlab::display {
namespace {

using test::input_error_of;

using ::atonlab::test::contains;

std::string data_path(const std::string& name) {
    return std::string(ATONLAB_SOURCE_DIR) + "/tests/data/calibration/" + name;
}

double gog_L(const GogParams& g, double v) {
    const double base = g.b + g.k * v;
    return base > 0.0 ? g.a + std::pow(base, g.gamma) : g.a;
}

constexpr double kNoise = 0.01;   // 1 % (one standard deviation) in luminance
constexpr int kLevels = 52;       // drive 0, 5, 10, ..., 255 of 255: an 8-bit ramp in steps of 5
constexpr int kBlackRepeats = 4;  // black read 4 times, as a calibration does to average the meter's noise

double level_of(int i) {
    return i < kBlackRepeats ? 0.0 : 5.0 * (i - kBlackRepeats + 1) / 255.0;
}
constexpr int kReadings = kBlackRepeats + kLevels - 1;

/// Readings of a GOG ramp at kLevels levels with multiplicative Gaussian noise
/// (Box–Muller on mt19937_64, so the numbers do not depend on the standard library).
std::vector<Measurement> synthetic_ramp(const GogParams& g, Channel ch, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    auto uniform = [&] { return (static_cast<double>(rng() >> 11) + 0.5) * 0x1p-53; };
    std::vector<Measurement> out;
    for (int i = 0; i < kReadings; ++i) {
        const double v = level_of(i);
        const double n = std::sqrt(-2.0 * std::log(uniform())) * std::cos(2.0 * std::numbers::pi * uniform());
        out.push_back(Measurement{v, ch, gog_L(g, v) * (1.0 + kNoise * n), i + 2, {}, "synthetic.csv"});
    }
    return out;
}

/// Covariance of (a, b, k, gamma) for a least-squares fit in log10 L with
/// residual sd sigma = 0.01 / ln 10 at the levels above: sigma² (JᵀJ)⁻¹.
glm::dmat4 covariance(const GogParams& g) {
    const double sigma = kNoise / std::numbers::ln10;
    glm::dmat4 jtj(0.0);
    for (int i = 0; i < kReadings; ++i) {
        const double v = level_of(i);
        glm::dvec4 row;
        for (int j = 0; j < 4; ++j) {
            GogParams lo = g, hi = g;
            double* plo = j == 0 ? &lo.a : j == 1 ? &lo.b : j == 2 ? &lo.k : &lo.gamma;
            double* phi = j == 0 ? &hi.a : j == 1 ? &hi.b : j == 2 ? &hi.k : &hi.gamma;
            const double h = 1e-6 * std::max(std::abs(*plo), 1e-2);
            *plo -= h;
            *phi += h;
            row[j] = (std::log10(gog_L(hi, v)) - std::log10(gog_L(lo, v))) / (2.0 * h);
        }
        jtj += glm::outerProduct(row, row);
    }
    return glm::inverse(jtj) * (sigma * sigma);
}

glm::dvec4 standard_errors(const GogParams& g) {
    const glm::dmat4 cov = covariance(g);
    return {std::sqrt(cov[0][0]), std::sqrt(cov[1][1]), std::sqrt(cov[2][2]), std::sqrt(cov[3][3])};
}

GogFit as_fit(const GogParams& g) {
    return GogFit{g.a, g.b, g.k, g.gamma, 0.0, 0};
}

/// Standard error of effective_gamma by the delta method: sqrt(∇ᵀ Σ ∇).
double effective_gamma_se(const GogParams& g) {
    glm::dvec4 grad;
    for (int j = 0; j < 4; ++j) {
        GogParams lo = g, hi = g;
        double* plo = j == 0 ? &lo.a : j == 1 ? &lo.b : j == 2 ? &lo.k : &lo.gamma;
        double* phi = j == 0 ? &hi.a : j == 1 ? &hi.b : j == 2 ? &hi.k : &hi.gamma;
        const double h = 1e-5 * std::max(std::abs(*plo), 1e-2);
        *plo -= h;
        *phi += h;
        grad[j] = (effective_gamma(as_fit(hi)) - effective_gamma(as_fit(lo))) / (2.0 * h);
    }
    return std::sqrt(glm::dot(grad, covariance(g) * grad));
}

// ---------------------------------------------------------------------------
// GOG fits.

TEST(GogFit, RecoversKnownParametersFromNoisyReadings) {
    // Four displays' ramps: an offset (b > 0), a cut-off (b < 0), none (b = 0).
    const std::vector<GogParams> truths = {
        {0.10, 0.03, 4.0, 2.4}, {0.20, 0.05, 6.5, 2.2}, {0.10, -0.05, 4.0, 2.3}, {0.25, 0.0, 9.0, 2.2}};
    std::uint64_t seed = 1;
    for (const auto& truth : truths) {
        const auto ramp = synthetic_ramp(truth, Channel::grey, seed++);
        const GogFit fit = fit_gog(ramp);
        const glm::dvec4 se = standard_errors(truth);
        std::printf(
            "truth a=%.4f b=%+.4f k=%.4f gamma=%.4f | fit a=%.4f b=%+.4f k=%.4f gamma=%.4f | "
            "SE %.4f %.4f %.4f %.4f | rmse %.5f | eff gamma %.4f vs %.4f (SE %.4f)\n",
            truth.a, truth.b, truth.k, truth.gamma, fit.a, fit.b, fit.k, fit.gamma, se[0], se[1], se[2], se[3],
            fit.rmse_log10, effective_gamma(fit), effective_gamma(as_fit(truth)), effective_gamma_se(truth));
        // Each parameter within 4 standard errors (a two-sided 4-sigma band: 6e-5 chance per parameter).
        EXPECT_NEAR(fit.a, truth.a, 4.0 * se[0]);
        EXPECT_NEAR(fit.b, truth.b, 4.0 * se[1]);
        EXPECT_NEAR(fit.k, truth.k, 4.0 * se[2]);
        EXPECT_NEAR(fit.gamma, truth.gamma, 4.0 * se[3]);
        // The residual is the noise: sd 0.01 / ln 10 = 0.00434 in log10, less the 4 fitted degrees of freedom.
        const double sigma = kNoise / std::numbers::ln10;
        EXPECT_GT(fit.rmse_log10, 0.6 * sigma);
        EXPECT_LT(fit.rmse_log10, 1.4 * sigma);
        EXPECT_EQ(fit.n, kReadings);
        // Effective gamma within 0.02, which is at least 4 of its standard errors for these ramps
        // (a 4-level ramp of a 25:1 channel would not do: its SE is ~0.02).
        EXPECT_LE(4.0 * effective_gamma_se(truth), 0.02);
        EXPECT_NEAR(effective_gamma(fit), effective_gamma(as_fit(truth)), 0.02);
    }
}

TEST(GogFit, EffectiveGammaOfAPurePowerIsItsExponent) {
    EXPECT_NEAR(effective_gamma(GogFit{0.3, 0.0, 5.0, 2.2, 0.0, 0}), 2.2, 1e-12);
    EXPECT_NEAR(effective_gamma(GogFit{0.0, 0.0, 1.0, 1.8, 0.0, 0}), 1.8, 1e-12);
}

TEST(GogFit, TooFewLevelsIsAnInputError) {
    const std::vector<Measurement> ramp = {{0.0, Channel::red, 0.1, 3, {}, "f.csv"},
                                           {0.5, Channel::red, 5.0, 4, {}, "f.csv"},
                                           {1.0, Channel::red, 20.0, 5, {}, "f.csv"}};
    const auto msg = input_error_of([&] { fit_gog(ramp); });
    EXPECT_TRUE(contains(msg, "f.csv:3")) << msg;
    EXPECT_TRUE(contains(msg, "4 or more distinct levels")) << msg;
}

TEST(Calibration, SyntheticDisplayRoundTripsThroughTheModel) {
    // R, G, B ramps of an additive display: each ramp reads its channel plus the others' black.
    const GogParams r{0.2, 0.03, 3.0, 2.4}, g{0.2, 0.05, 6.5, 2.2}, b{0.2, -0.02, 2.0, 2.3};
    std::vector<Measurement> all;
    for (const auto& [p, ch, seed] :
         {std::tuple{r, Channel::red, 11u}, {g, Channel::green, 12u}, {b, Channel::blue, 13u}}) {
        const auto ramp = synthetic_ramp(p, ch, seed);
        all.insert(all.end(), ramp.begin(), ramp.end());
    }
    const auto report = fit_calibration(all);
    ASSERT_EQ(report.ramps.size(), 3u);
    EXPECT_NEAR(report.black_cd_m2, 0.2, 0.2 * 3.0 * kNoise);
    const double true_white = gog_L(r, 1) + gog_L(g, 1) + gog_L(b, 1) - 2.0 * 0.2;
    EXPECT_NEAR(report.white_cd_m2, true_white, true_white * 3.0 * kNoise);
    EXPECT_NEAR(report.contrast_ratio, report.white_cd_m2 / report.black_cd_m2, 1e-9);

    const auto display = display_from_calibration(report, "synthetic");
    EXPECT_NO_THROW(display.validate());
    EXPECT_NEAR(display.peak_cd_m2, true_white, true_white * 0.01);
    EXPECT_NEAR(display.black_cd_m2, report.black_cd_m2, report.black_cd_m2 * 0.05);
    // Each model channel is its ramp less the other channels' share of black.
    for (int c = 0; c < 3; ++c) {
        const auto& truth = c == 0 ? r : c == 1 ? g : b;
        for (const double v : {0.25, 0.5, 1.0})
            EXPECT_NEAR(display.channel_luminance_cd_m2(c, v) - display.channel_luminance_cd_m2(c, 0.0),
                        gog_L(truth, v) - gog_L(truth, 0.0), 0.02 * gog_L(truth, v));
    }
}

// ---------------------------------------------------------------------------
// ArgyllCMS .ti3.

TEST(Ti3, ReadsTheHandWrittenFile) {
    const auto m = read_argyll_ti3(data_path("display.ti3"));
    ASSERT_EQ(m.size(), 25u);
    int counts[5] = {};
    for (const auto& x : m) ++counts[static_cast<int>(x.channel)];
    EXPECT_EQ(counts[static_cast<int>(Channel::grey)], 11);  // black, 10 % ... 100 %
    EXPECT_EQ(counts[static_cast<int>(Channel::red)], 4);
    EXPECT_EQ(counts[static_cast<int>(Channel::green)], 4);
    EXPECT_EQ(counts[static_cast<int>(Channel::blue)], 4);
    EXPECT_EQ(counts[static_cast<int>(Channel::other)], 2);
    // Y normalised to 100 for white, scaled by LUMINANCE_XYZ_CDM2's Y = 120 cd/m².
    EXPECT_EQ(m.front().line, 32);
    EXPECT_EQ(m.front().level, 0.0);
    EXPECT_NEAR(m.front().luminance_cd_m2, 0.15, 1e-12);
    EXPECT_EQ(m[10].channel, Channel::grey);
    EXPECT_EQ(m[10].level, 1.0);
    EXPECT_NEAR(m[10].luminance_cd_m2, 120.0, 1e-12);
    EXPECT_EQ(m[13].channel, Channel::red);
    EXPECT_NEAR(m[13].level, 0.75, 1e-15);
    EXPECT_EQ(m[24].rgb, glm::dvec3(0.5, 0.25, 0.75));
    EXPECT_EQ(m[24].level, 0.75);

    const auto report = fit_calibration(m);
    EXPECT_NEAR(report.white_cd_m2, 120.0, 1e-9);
    EXPECT_NEAR(report.black_cd_m2, 0.15, 1e-9);
    EXPECT_NEAR(report.contrast_ratio, 800.0, 1e-6);
    EXPECT_EQ(report.n_other, 2);
    ASSERT_EQ(report.ramps.size(), 4u);
    const auto* grey = report.ramp(Channel::grey);
    ASSERT_NE(grey, nullptr);
    // The file was written for channel gammas 2.15-2.25 with 0.2 % noise.
    EXPECT_NEAR(grey->effective_gamma, 2.2, 0.05);
    EXPECT_LT(grey->fit.rmse_log10, 0.01);
    const auto display = display_from_calibration(report, "ti3 LCD");
    EXPECT_NEAR(display.peak_cd_m2, 120.0, 120.0 * 0.02);
    EXPECT_NEAR(display.black_cd_m2, 0.15, 0.15 * 0.05);
}

TEST(Ti3, MalformedFilesNameTheLine) {
    auto msg = input_error_of([] { read_argyll_ti3(data_path("missing_end_data.ti3")); });
    EXPECT_TRUE(contains(msg, "missing_end_data.ti3:31")) << msg;
    EXPECT_TRUE(contains(msg, "END_DATA")) << msg;

    msg = input_error_of([] { read_argyll_ti3(data_path("wrong_field_count.ti3")); });
    EXPECT_TRUE(contains(msg, "wrong_field_count.ti3:40")) << msg;
    EXPECT_TRUE(contains(msg, "6 values")) << msg;

    msg = input_error_of([] { read_argyll_ti3(data_path("not_a_number.ti3")); });
    EXPECT_TRUE(contains(msg, "not_a_number.ti3:45")) << msg;
    EXPECT_TRUE(contains(msg, "key 'XYZ_Y'")) << msg;
    EXPECT_TRUE(contains(msg, "'11.2O2507' is not a number")) << msg;

    msg = input_error_of([] { read_argyll_ti3(data_path("no_such_file.ti3")); });
    EXPECT_TRUE(contains(msg, "cannot be opened")) << msg;
}

TEST(Ti3, KeywordsAndLayoutErrors) {
    const std::string head = "CTI3\nDEVICE_CLASS \"DISPLAY\"\n";
    const std::string format =
        "NUMBER_OF_FIELDS 5\nBEGIN_DATA_FORMAT\nRGB_R RGB_G RGB_B XYZ_Y SAMPLE_NAME\nEND_DATA_FORMAT\n";
    const std::string data =
        "NUMBER_OF_SETS 2\nBEGIN_DATA\n0 0 0 0.2 \"black patch\"\n100 100 100 150.0 white\nEND_DATA\n";
    // Without NORMALIZED_TO_Y_100, XYZ are absolute cd/m².
    auto m = parse_argyll_ti3(head + format + data, "abs.ti3");
    ASSERT_EQ(m.size(), 2u);
    EXPECT_EQ(m[1].luminance_cd_m2, 150.0);
    EXPECT_EQ(m[0].line, 9);

    auto msg =
        input_error_of([&] { parse_argyll_ti3(head + "NORMALIZED_TO_Y_100 \"YES\"\n" + format + data, "n.ti3"); });
    EXPECT_TRUE(contains(msg, "n.ti3:3")) << msg;
    EXPECT_TRUE(contains(msg, "key 'LUMINANCE_XYZ_CDM2'")) << msg;

    msg = input_error_of([&] { parse_argyll_ti3("CGATS.17\n" + format + data, "x.ti3"); });
    EXPECT_TRUE(contains(msg, "x.ti3:1")) << msg;
    EXPECT_TRUE(contains(msg, "CTI3")) << msg;

    msg = input_error_of([&] { parse_argyll_ti3("CTI3\nDEVICE_CLASS \"OUTPUT\"\n" + format + data, "p.ti3"); });
    EXPECT_TRUE(contains(msg, "key 'DEVICE_CLASS'")) << msg;

    msg = input_error_of([&] {
        parse_argyll_ti3(head + "BEGIN_DATA_FORMAT\nRGB_R RGB_G XYZ_Y\nEND_DATA_FORMAT\nBEGIN_DATA\n0 0 0\nEND_DATA\n",
                         "f.ti3");
    });
    EXPECT_TRUE(contains(msg, "f.ti3:3")) << msg;
    EXPECT_TRUE(contains(msg, "RGB_B")) << msg;

    std::string three_sets = data;
    three_sets.replace(three_sets.find("SETS 2"), 6, "SETS 3");
    msg = input_error_of([&] { parse_argyll_ti3(head + format + three_sets, "s.ti3"); });
    EXPECT_TRUE(contains(msg, "key 'NUMBER_OF_SETS'")) << msg;

    std::string over = data;
    over.replace(over.find("100 100 100"), 11, "100 100 101");
    msg = input_error_of([&] { parse_argyll_ti3(head + format + over, "r.ti3"); });
    EXPECT_TRUE(contains(msg, "r.ti3:10")) << msg;
    EXPECT_TRUE(contains(msg, "key 'RGB_B'")) << msg;
}

// ---------------------------------------------------------------------------
// CSV.

TEST(Csv, ReadsAGreyRamp) {
    const auto m = read_calibration_csv(data_path("grey_ramp.csv"));
    ASSERT_EQ(m.size(), 10u);
    EXPECT_EQ(m.front().channel, Channel::grey);  // "black"
    EXPECT_EQ(m.front().level, 0.0);
    EXPECT_EQ(m.front().line, 5);
    EXPECT_EQ(m.back().channel, Channel::grey);  // "white", with a trailing comment
    EXPECT_EQ(m.back().level, 1.0);
    EXPECT_EQ(m.back().luminance_cd_m2, 100.1);
    const auto report = fit_calibration(m);
    EXPECT_NEAR(report.black_cd_m2, 0.2, 1e-12);
    EXPECT_NEAR(report.white_cd_m2, 100.1, 1e-12);
    ASSERT_NE(report.ramp(Channel::grey), nullptr);
    // The file is an sRGB curve: the GOG fit's effective gamma is that of sRGB decoding over 0.1..1
    // (about 2.0, not 2.2: the 2.4 power's offset flattens it), to within the 4-digit rounding.
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int i = 0; i <= 45; ++i) {
        const double lv = -1.0 + i / 45.0, v = std::pow(10.0, lv);
        const double y = std::log10(std::pow((v + 0.055) / 1.055, 2.4));
        sx += lv;
        sy += y;
        sxx += lv * lv;
        sxy += lv * y;
    }
    const double srgb_gamma = (46 * sxy - sx * sy) / (46 * sxx - sx * sx);
    EXPECT_NEAR(report.ramp(Channel::grey)->effective_gamma, srgb_gamma, 0.03);
    std::printf("sRGB effective gamma over 0.1..1: %.4f; fitted: %.4f\n", srgb_gamma,
                report.ramp(Channel::grey)->effective_gamma);
    // Grey only: the channels are the grey ramp split by Rec.709 weight.
    const auto display = display_from_calibration(report, "csv monitor");
    EXPECT_NEAR(display.channel_luminance_cd_m2(1, 1.0) / display.peak_cd_m2, 0.7152, 1e-3);
    EXPECT_NEAR(display.peak_cd_m2, report.ramp(Channel::grey)->white_cd_m2, 1e-9);
}

TEST(Csv, MalformedRowsNameLineAndColumn) {
    auto msg = input_error_of([] { read_calibration_csv(data_path("bad_channel.csv")); });
    EXPECT_TRUE(contains(msg, "bad_channel.csv:5")) << msg;
    EXPECT_TRUE(contains(msg, "key 'channel'")) << msg;
    EXPECT_TRUE(contains(msg, "yellow")) << msg;

    msg = input_error_of([] { read_calibration_csv(data_path("not_a_number.csv")); });
    EXPECT_TRUE(contains(msg, "not_a_number.csv:5")) << msg;
    EXPECT_TRUE(contains(msg, "key 'cd_m2'")) << msg;

    msg = input_error_of([] { parse_calibration_csv("level,channel\n0,grey\n", "h.csv"); });
    EXPECT_TRUE(contains(msg, "h.csv:1")) << msg;
    EXPECT_TRUE(contains(msg, "key 'cd_m2'")) << msg;

    msg = input_error_of([] { parse_calibration_csv("level,channel,cd_m2\n0,grey\n", "n.csv"); });
    EXPECT_TRUE(contains(msg, "n.csv:2")) << msg;
    EXPECT_TRUE(contains(msg, "2 fields")) << msg;

    msg = input_error_of([] { parse_calibration_csv("level,channel,cd_m2\n1.5,grey,3\n", "l.csv"); });
    EXPECT_TRUE(contains(msg, "l.csv:2")) << msg;
    EXPECT_TRUE(contains(msg, "key 'level'")) << msg;

    msg = input_error_of([] { parse_calibration_csv("level,channel,cd_m2\n0.5,white,3\n", "w.csv"); });
    EXPECT_TRUE(contains(msg, "key 'level'")) << msg;

    msg = input_error_of([] { parse_calibration_csv("level,channel,cd_m2\n0.5,grey,-3\n", "m.csv"); });
    EXPECT_TRUE(contains(msg, "negative")) << msg;

    msg = input_error_of([] { parse_calibration_csv("# nothing\n\n", "e.csv"); });
    EXPECT_TRUE(contains(msg, "e.csv")) << msg;
}

// ---------------------------------------------------------------------------
// Monotonicity.

TEST(CheckMonotonic, NamesTheFirstReadingThatFalls) {
    const auto m = read_calibration_csv(data_path("non_monotonic.csv"));
    auto msg = input_error_of([&] { check_monotonic(m); });
    EXPECT_TRUE(contains(msg, "non_monotonic.csv:7")) << msg;
    EXPECT_TRUE(contains(msg, "not monotonic")) << msg;
    EXPECT_TRUE(contains(msg, "key 'cd_m2'")) << msg;
    // fit_calibration checks first.
    msg = input_error_of([&] { fit_calibration(m); });
    EXPECT_TRUE(contains(msg, "non_monotonic.csv:7")) << msg;
}

TEST(CheckMonotonic, BlackCountsInEveryRampAndSmallDipsAreNoise) {
    // A red reading at level 0.1 below black (line 4) breaks the red ramp.
    std::vector<Measurement> m = {{0.0, Channel::grey, 0.5, 2, {}, "r.ti3"},
                                  {0.2, Channel::red, 0.9, 3, {}, "r.ti3"},
                                  {0.1, Channel::red, 0.3, 4, {}, "r.ti3"}};
    const auto msg = input_error_of([&] { check_monotonic(m); });
    EXPECT_TRUE(contains(msg, "r.ti3:4")) << msg;
    EXPECT_TRUE(contains(msg, "key 'XYZ_Y'")) << msg;
    // A dip of 0.5 % between neighbouring levels is within the default 5 % tolerance...
    m[2] = {0.3, Channel::red, 0.9 * 0.995, 4, {}, "r.ti3"};
    EXPECT_NO_THROW(check_monotonic(m));
    // ...but not within a strict one.
    EXPECT_THROW(check_monotonic(m, 0.0), InputError);
    // Repeated readings at one level may scatter either way.
    m[2] = {0.2, Channel::red, 0.85, 4, {}, "r.ti3"};
    EXPECT_NO_THROW(check_monotonic(m, 0.0));
}

TEST(Calibration, MissingBlackOrWhiteIsAnInputError) {
    std::vector<Measurement> m;
    for (int i = 1; i <= 5; ++i) m.push_back({i / 5.0, Channel::grey, 100.0 * std::pow(i / 5.0, 2.2), i, {}, "g.csv"});
    EXPECT_TRUE(contains(input_error_of([&] { fit_calibration(m); }), "no black"));
    m.back().level = 0.9;
    m.push_back({0.0, Channel::grey, 0.1, 9, {}, "g.csv"});
    EXPECT_TRUE(contains(input_error_of([&] { fit_calibration(m); }), "no white"));
}

}  // namespace
}  // namespace atonlab::display
