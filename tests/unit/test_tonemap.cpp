// Tone mapping and adaptation (K2012 §4.4): every equation against values computed by hand
// from the papers, the thesis's typos pinned, and the invariant of docs/architecture.md ("Physical invariants") "every operator is
// finite and monotonic in luminance over 0 … 1e9 cd/m², including exact zero and pure
// primaries" swept over adaptation, hue preservation and blueshift.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/tonemap.h"
#include "blueshift_modes.h"

namespace atonlab::stimuli {
using namespace atonlab::display;  // colour science, the tone-mapping CPU reference (display/)
namespace {

constexpr std::array<ToneOperator, 6> kOperators = {ToneOperator::empirical, ToneOperator::perceptual,
                                                    ToneOperator::reinhard,  ToneOperator::kakimoto,
                                                    ToneOperator::linear,    ToneOperator::clamp};
constexpr std::array<HuePreservation, 3> kHues = {HuePreservation::none, HuePreservation::xyY, HuePreservation::rgb};

glm::dvec2 xy_of_rgb(glm::dvec3 rgb) {
    const glm::dvec3 xyz = linear_rgb_to_xyz(rgb);
    return glm::dvec2(xyz.x, xyz.y) / (xyz.x + xyz.y + xyz.z);
}

bool finite_non_negative(glm::dvec3 v) {
    return std::isfinite(v.r) && std::isfinite(v.g) && std::isfinite(v.b) && v.r >= 0.0 && v.g >= 0.0 && v.b >= 0.0;
}

ToneMapSettings plain(ToneOperator op) {
    ToneMapSettings s;
    s.tone_operator = op;
    s.blueshift = false;
    s.hue_preservation = HuePreservation::none;
    return s;
}

TEST(ToneMapNames, RoundTripAndUnknown) {
    for (ToneOperator op : kOperators) EXPECT_EQ(tone_operator_from_name(tone_operator_name(op)), op);
    for (HuePreservation h : kHues) EXPECT_EQ(hue_preservation_from_name(hue_preservation_name(h)), h);
    EXPECT_EQ(tone_operator_name(ToneOperator::empirical), "empirical");
    EXPECT_EQ(tone_operator_name(ToneOperator::clamp), "clamp");
    EXPECT_EQ(hue_preservation_name(HuePreservation::xyY), "xyY");
    EXPECT_FALSE(tone_operator_from_name("Empirical"));
    EXPECT_FALSE(hue_preservation_from_name("xyz"));
    EXPECT_EQ(tone_operator_names().size(), 6u);
    EXPECT_EQ(hue_preservation_names().size(), 3u);
}

TEST(RodSensitivity, Eq427) {
    EXPECT_DOUBLE_EQ(rod_sensitivity(0.04), 0.5);
    EXPECT_DOUBLE_EQ(rod_sensitivity(0.0), 1.0);
    EXPECT_DOUBLE_EQ(rod_sensitivity(0.12), 0.25);
    EXPECT_NEAR(rod_sensitivity(1e4), 4e-6, 1e-9);
}

TEST(Tvi, HandComputedValues) {
    // K2012 eq 4.24 middle branch at log L = 0: (0.65)^2.7 - 0.72.
    EXPECT_NEAR(log10_tvi_cone(0.0), std::pow(0.65, 2.7) - 0.72, 1e-15);
    EXPECT_NEAR(log10_tvi_cone(0.0), -0.40748845717556, 1e-12);
    EXPECT_DOUBLE_EQ(log10_tvi_cone(-5.0), -0.72);
    EXPECT_DOUBLE_EQ(log10_tvi_cone(3.0), 3.0 - 1.255);
    // Eq 4.23 middle branch at log L = -2: (0.405·(-2) + 1.6)^2.18 - 2.86 = 0.79^2.18 - 2.86.
    EXPECT_NEAR(log10_tvi_rod(-2.0), std::pow(0.79, 2.18) - 2.86, 1e-15);
    EXPECT_DOUBLE_EQ(log10_tvi_rod(-6.0), -2.86);
    EXPECT_DOUBLE_EQ(log10_tvi_rod(1.0), 1.0 - 0.395);
}

TEST(Tvi, DiscontinuitiesAtTheBranchesMeasured) {
    // Eq 4.23/4.24 are not continuous. The jump is the value just above the boundary minus the
    // value just below, in log10 units. By hand, from the printed branches:
    //   rods  -3.94: ((0.405·-3.94 + 1.6)^2.18 - 2.86) - (-2.86) = (0.0043)^2.18            = +6.934e-6
    //   rods  -1.44: (-1.44 - 0.395) - ((0.405·-1.44 + 1.6)^2.18 - 2.86) = -1.835 + 1.823013 = -0.011987
    //   cones -2.60: ((0.249·-2.6 + 0.65)^2.7 - 0.72) - (-0.72) = (0.0026)^2.7               = +1.048e-7
    //   cones  1.90: (1.9 - 1.255) - ((0.249·1.9 + 0.65)^2.7 - 0.72) = 0.645 - 0.648138      = -0.003138
    // So the rod threshold drops by 2.8% (10^-0.012) as the adaptation rises through
    // 10^-1.44 = 0.0363 cd/m², and m_R of the perceptual operator jumps up by 2.8% there; the
    // cone threshold drops by 0.7% at 10^1.9 = 79 cd/m². The other two joins are continuous
    // to 1e-5 log units.
    struct Edge {
        const char* what;
        double (*f)(double);
        double at;
        double expected;
        double tol;
    };
    const Edge edges[] = {
        {"rods  log L = -3.94", log10_tvi_rod, -3.94, 6.933639108641643e-06, 1e-12},
        {"rods  log L = -1.44", log10_tvi_rod, -1.44, -0.011987381756638271, 1e-9},
        {"cones log L = -2.60", log10_tvi_cone, -2.6, 1.0481611034673932e-07, 1e-12},
        {"cones log L =  1.90", log10_tvi_cone, 1.9, -0.0031375210955872923, 1e-9},
    };
    for (const Edge& e : edges) {
        const double jump = e.f(std::nextafter(e.at, 10.0)) - e.f(std::nextafter(e.at, -10.0));
        std::printf("TVI jump at %s: %+.6e log10 units (x%.5f in threshold)\n", e.what, jump, std::pow(10.0, jump));
        EXPECT_NEAR(jump, e.expected, e.tol) << e.what;
    }
}

TEST(ScotopicLuminance, LarsonRushmeierPiatkoNotTheThesisTypo) {
    // LRP97: V = Y (1.33 (1 + (Y+Z)/X) - 1.68). XYZ = (2, 1, 3): (Y+Z)/X = 2, V = 1.33·3 - 1.68 = 2.31.
    // The thesis's (X+Y)/Z would give 1.33·2 - 1.68 = 0.98.
    EXPECT_NEAR(scotopic_luminance({2.0, 1.0, 3.0}), 2.31, 1e-14);
    EXPECT_GT(std::abs(scotopic_luminance({2.0, 1.0, 3.0}) - 0.98), 1.0);
    // Scales with Y at fixed chromaticity.
    EXPECT_NEAR(scotopic_luminance({20.0, 10.0, 30.0}), 23.1, 1e-12);
    // D65 white: V/Y = 1.33 (1 + (1 + 1.08883)/0.95047) - 1.68 = 2.573.
    const glm::dvec3 white = linear_rgb_to_xyz({1.0, 1.0, 1.0});
    EXPECT_NEAR(scotopic_luminance(white) / white.y, 2.573, 1e-3);
    // Black, X = 0 and negative brackets stay finite and >= 0.
    EXPECT_EQ(scotopic_luminance({0.0, 0.0, 0.0}), 0.0);
    EXPECT_EQ(scotopic_luminance({1.0, 0.0, 1.0}), 0.0);
    EXPECT_NEAR(scotopic_luminance({0.0, 1.0, 0.5}), 1.33 * (1.0 + kMaxScotopicRatio) - 1.68, 1e-9);
    EXPECT_EQ(scotopic_luminance({1.0, 0.1, 0.0}), 0.0);  // 1.33·1.1 - 1.68 < 0: clamped
    EXPECT_EQ(scotopic_luminance({-1.0, -1.0, -1.0}), 0.0);
    EXPECT_TRUE(std::isfinite(scotopic_luminance({std::numeric_limits<double>::denorm_min(), 1e9, 1e9})));
}

TEST(ScotopicLuminance, CapLiesBeyondEveryRealColour) {
    // (Y+Z)/X over the CIE 1931 spectral locus: the cap must never touch a real colour.
    double worst = 0.0, at = 0.0;
    for (double nm = 360.0; nm <= 830.0; nm += 1.0) {
        const glm::dvec3 c = cie1931_cmf(nm);
        if (c.x <= 0.0) continue;
        const double r = (c.y + c.z) / c.x;
        if (r > worst) {
            worst = r;
            at = nm;
        }
    }
    std::printf("largest (Y+Z)/X on the spectral locus: %.1f at %.0f nm (cap %.0f)\n", worst, at, kMaxScotopicRatio);
    EXPECT_LT(worst, kMaxScotopicRatio);
}

TEST(KrawczykKey, PaperFormWithThePlusOne) {
    // Krawczyk et al. 2005 eq 11 has log10(L + 1); K2012 eq 4.19 changes 1.03 to 1.002 and drops the + 1.
    EXPECT_NEAR(krawczyk_key(1.0), 1.002 - 2.0 / (2.0 + std::log10(2.0)), 1e-15);
    EXPECT_NEAR(krawczyk_key(1.0), 0.13282402064781273, 1e-15);
    EXPECT_NEAR(krawczyk_key(0.0), 0.002, 1e-18);
    EXPECT_NEAR(krawczyk_key(1e10), 1.002 - 2.0 / 12.0, 1e-12);
    // Without the + 1 the thesis's form divides by 2 + log10(0.01) = 0 at 0.01 cd/m² (and is
    // negative below): ours is finite and small there.
    EXPECT_EQ(2.0 + std::log10(0.01), 0.0);
    EXPECT_NEAR(krawczyk_key(0.01), 1.002 - 2.0 / (2.0 + std::log10(1.01)), 1e-15);
    EXPECT_NEAR(krawczyk_key(0.01), 0.004156028389043831, 1e-15);
    // Positive and increasing over the whole range.
    double prev = 0.0;
    for (double l = 1e-9; l <= 1e10; l *= 1.5) {
        const double a = krawczyk_key(l);
        EXPECT_GT(a, prev) << l;
        prev = a;
    }
}

TEST(TemporalAdaptation, TimeConstantEq417) {
    EXPECT_DOUBLE_EQ(adaptation_time_constant_s(0.0), 0.4);
    EXPECT_DOUBLE_EQ(adaptation_time_constant_s(0.04), 0.25);
    EXPECT_NEAR(adaptation_time_constant_s(1e6), 0.1 + 0.3 * 0.04 / (1e6 + 0.04), 1e-16);
}

TEST(TemporalAdaptation, ReachesSixtyThreePercentAfterTauAtEveryFrameRate) {
    // Iterate eq 4.16 at the frame rate. Because τ depends on the target only, frame k has
    // covered exactly 1 - exp(-k Δt/τ) of the step whatever the frame rate; and the time at
    // which 1 - 1/e = 63.2% is covered (found between the two frames that bracket it, where
    // the model is exponential, by interpolating ln of the remaining fraction) is τ(target).
    struct Step {
        double from, to;
    };
    for (Step st : {Step{1.0, 1000.0}, Step{1000.0, 1e-3}, Step{1e-3, 0.04}}) {
        const double tau = adaptation_time_constant_s(st.to);
        for (double hz : {10.0, 60.0, 144.0, 1000.0}) {
            const double dt = 1.0 / hz;
            double l = st.from, crossing = -1.0, worst_frame = 0.0;
            for (int k = 0; k < 100000 && crossing < 0.0; ++k) {
                const double next = temporal_adaptation(l, st.to, dt);
                const double left = (st.to - l) / (st.to - st.from);  // remaining fraction at frame k
                const double left_next = (st.to - next) / (st.to - st.from);
                worst_frame =
                    std::max(worst_frame, std::abs(left_next - std::exp(-static_cast<double>(k + 1) * dt / tau)));
                if (left_next <= std::exp(-1.0)) {
                    crossing = dt * (k + (-1.0 - std::log(left)) / (std::log(left_next) - std::log(left)));
                }
                l = next;
            }
            EXPECT_LT(worst_frame, 1e-12) << st.from << " -> " << st.to << " at " << hz << " Hz";
            EXPECT_NEAR(crossing / tau, 1.0, 0.02) << st.from << " -> " << st.to << " at " << hz << " Hz";
            std::printf("step %g -> %g cd/m2 at %4g Hz: 63.2%% after %.6f s, tau %.6f s\n", st.from, st.to, hz,
                        crossing, tau);
        }
    }
}

TEST(TemporalAdaptation, ZeroAndHugeStepsAndBadInput) {
    EXPECT_EQ(temporal_adaptation(0.1, 1e9, 0.0), 0.1);
    EXPECT_EQ(temporal_adaptation(1e9, 0.1, 0.0), 1e9);
    EXPECT_EQ(temporal_adaptation(0.1, 1e9, 1e6), 1e9);
    EXPECT_EQ(temporal_adaptation(1e9, 0.1, 1e6), 0.1);
    EXPECT_EQ(temporal_adaptation(3.0, 3.0, 0.5), 3.0);
    EXPECT_THROW(temporal_adaptation(1.0, 2.0, -1e-3), InputError);
    EXPECT_THROW(temporal_adaptation(1.0, 2.0, std::nan("")), InputError);
    EXPECT_THROW(temporal_adaptation(1.0, 2.0, std::numeric_limits<double>::infinity()), InputError);
    EXPECT_THROW(temporal_adaptation(-1.0, 2.0, 0.1), InputError);
    EXPECT_THROW(temporal_adaptation(1.0, std::nan(""), 0.1), InputError);
}

// The log-average in long double with Kahan summation: the reference for eq 4.15.
long double reference_log_average(const ImageRGBA32F& img, long double eps) {
    const glm::dvec3 yrow(luminance_of_linear_rgb({1, 0, 0}), luminance_of_linear_rgb({0, 1, 0}),
                          luminance_of_linear_rgb({0, 0, 1}));
    long double sum = 0.0L, c = 0.0L;
    const std::size_t n = static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height);
    for (std::size_t i = 0; i < n; ++i) {
        const float* p = &img.rgba[i * 4];
        const long double y = static_cast<long double>(yrow.x) * std::max(p[0], 0.0f) +
                              static_cast<long double>(yrow.y) * std::max(p[1], 0.0f) +
                              static_cast<long double>(yrow.z) * std::max(p[2], 0.0f);
        const long double term = std::log(y + eps) - c;
        const long double t = sum + term;
        c = (t - sum) - term;
        sum = t;
    }
    return std::exp(sum / static_cast<long double>(n));
}

ImageRGBA32F image_of(int w, int h, glm::vec3 rgb) {
    ImageRGBA32F img;
    img.width = w;
    img.height = h;
    img.rgba.assign(static_cast<std::size_t>(w * h) * 4, 1.0f);
    for (int i = 0; i < w * h; ++i) {
        for (int c = 0; c < 3; ++c) img.rgba[static_cast<std::size_t>(i) * 4 + static_cast<std::size_t>(c)] = rgb[c];
    }
    return img;
}

TEST(LogAverageLuminance, MatchesLongDoubleKahanReference) {
    struct Case {
        const char* what;
        ImageRGBA32F img;
    };
    std::vector<Case> cases;
    cases.push_back({"all zeros", image_of(64, 48, {0, 0, 0})});
    ImageRGBA32F one_sun = image_of(640, 480, {0, 0, 0});
    one_sun.pixel(320, 240)[0] = one_sun.pixel(320, 240)[1] = one_sun.pixel(320, 240)[2] = 1e9f;
    cases.push_back({"zeros and one 1e9 pixel", one_sun});
    cases.push_back({"uniform starlight 1e-3", image_of(640, 480, {1e-3f, 1e-3f, 1e-3f})});
    cases.push_back({"uniform daylight 1e4 (green)", image_of(300, 200, {0.0f, 1e4f, 0.0f})});
    ImageRGBA32F random = image_of(512, 512, {0, 0, 0});
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> lg(-9.0, 9.0);
    for (std::size_t i = 0; i < random.rgba.size(); i += 4) {
        for (std::size_t c = 0; c < 3; ++c) random.rgba[i + c] = static_cast<float>(std::pow(10.0, lg(rng)));
        if (i % 40 == 0) random.rgba[i] = -5.0f;  // negative components are clipped first
    }
    cases.push_back({"random 1e-9 .. 1e9 with negatives", random});
    for (const Case& c : cases) {
        for (double eps : {kLogAverageEpsilonCdM2, 1e-4}) {
            const double got = log_average_luminance(c.img, eps);
            const long double ref = reference_log_average(c.img, static_cast<long double>(eps));
            const double rel = static_cast<double>(std::abs((static_cast<long double>(got) - ref) / ref));
            EXPECT_LT(rel, 1e-12) << c.what << " eps " << eps;
            std::printf("log-average %-36s eps %g: %.9g cd/m2 (relative error %.2g)\n", c.what, eps, got, rel);
        }
    }
    // A uniform field L gives L + ε: the bias ε adds to a starlight scene.
    EXPECT_NEAR(log_average_luminance(image_of(8, 8, {1e-3f, 1e-3f, 1e-3f})),
                static_cast<double>(1e-3f) * luminance_of_linear_rgb({1, 1, 1}) + 1e-6, 1e-15);
    EXPECT_NEAR(log_average_luminance(image_of(8, 8, {0, 0, 0})), kLogAverageEpsilonCdM2, 1e-20);
    EXPECT_THROW(log_average_luminance(ImageRGBA32F{}), InputError);
    EXPECT_THROW(log_average_luminance(image_of(2, 2, {1, 1, 1}), 0.0), InputError);
    EXPECT_THROW(log_average_luminance(image_of(2, 2, {1, 1, 1}), std::nan("")), InputError);
}

TEST(ToneCurves, ReinhardAtOneIsHalfTimesOnePlusInverseWhiteSquared) {
    // Reinhard et al. 2002 eq 2 and 4: L = a L_w / L̄_w, L_d = L (1 + L/L_white²)/(1 + L). L = 1:
    ToneMapSettings s = plain(ToneOperator::reinhard);
    s.reinhard_white_relative = 3.0;
    const double lwa = 7.0;
    EXPECT_NEAR(tone_curve(lwa / s.reinhard_key, 0.0, lwa, s), 0.5 * (1.0 + 1.0 / 9.0), 1e-15);
    s.reinhard_white_relative = std::numeric_limits<double>::infinity();  // eq 3: L/(1 + L)
    EXPECT_NEAR(tone_curve(lwa / s.reinhard_key, 0.0, lwa, s), 0.5, 1e-15);
    EXPECT_NEAR(tone_curve(3.0 * lwa / s.reinhard_key, 0.0, lwa, s), 0.75, 1e-15);
}

TEST(ToneCurves, EmpiricalEq418To420) {
    // L_w = L_wa: L_r = α(L_wa), L_d = α (1 + α/4)/(1 + α) with L_white = 2.
    const ToneMapSettings s = plain(ToneOperator::empirical);
    for (double lwa : {1e-3, 1.0, 250.0}) {
        const double a = 1.002 - 2.0 / (2.0 + std::log10(lwa + 1.0));
        EXPECT_NEAR(tone_curve(lwa, 0.0, lwa, s), a * (1.0 + a / 4.0) / (1.0 + a), 1e-14) << lwa;
    }
    // L_r = L_white gives L_d = 1 (the definition of the white point).
    const double lwa = 1.0;
    EXPECT_NEAR(tone_curve(2.0 * lwa / krawczyk_key(lwa), 0.0, lwa, s), 1.0, 1e-14);
}

TEST(ToneCurves, KakimotoSigmoidRescaled) {
    // Kakimoto et al. 2005 eq 7 with D = 640, k = 20, g = 0.465, x = L_w/L_wa, then
    // (sig(x) - D/k)/(D - D/k).
    const ToneMapSettings s = plain(ToneOperator::kakimoto);
    const double D = 640.0, k = 20.0, g = 0.465;
    const auto sig = [&](double x) { return D * (std::pow(x, g) + 1.0) / (std::pow(x, g) + k); };
    for (double x : {0.01, 1.0, 3.7, 1e6}) {
        const double expected = (sig(x) - D / k) / (D - D / k);
        EXPECT_NEAR(tone_curve(x * 2.5, 0.0, 2.5, s), expected, 1e-14) << x;
    }
    EXPECT_NEAR(tone_curve(2.5, 0.0, 2.5, s), 1.0 / 21.0, 1e-15);
    EXPECT_EQ(tone_curve(0.0, 0.0, 2.5, s), 0.0);
    EXPECT_LT(tone_curve(1e30, 0.0, 1e-7, s), 1.0);
}

TEST(ToneCurves, PerceptualEq421To426ByHand) {
    ToneMapSettings s = plain(ToneOperator::perceptual);
    // L_wa = 100 cd/m²: log 2 >= 1.9 (cones) and >= -1.44 (rods): ε_C = 10^(2 - 1.255),
    // ε_R = 10^(2 - 0.395). L_da = 50: log ε_C(50) = (0.249·log 50 + 0.65)^2.7 - 0.72.
    const double eps_display = std::pow(10.0, std::pow(0.249 * std::log10(50.0) + 0.65, 2.7) - 0.72);
    const double m_c = eps_display / std::pow(10.0, 2.0 - 1.255);
    const double m_r = eps_display / std::pow(10.0, 2.0 - 0.395);
    const double sigma = 0.04 / 100.04;
    const double lw = 80.0, vw = 150.0;
    EXPECT_NEAR(tone_curve(lw, vw, 100.0, s), (m_c * lw + sigma * m_r * vw) / 100.0, 1e-14);
    // Starlight, L_wa = 1e-3 (log -3): cones at the floor -0.72, rods in the middle branch.
    const double m_c2 = eps_display / std::pow(10.0, -0.72);
    const double m_r2 = eps_display / std::pow(10.0, std::pow(0.405 * -3.0 + 1.6, 2.18) - 2.86);
    const double sigma2 = 0.04 / 0.041;
    EXPECT_NEAR(tone_curve(2e-3, 5e-3, 1e-3, s), (m_c2 * 2e-3 + sigma2 * m_r2 * 5e-3) / 100.0, 1e-14);
    // The display's own adaptation, set explicitly.
    s.display_adaptation_cd_m2 = 20.0;
    const double eps20 = std::pow(10.0, std::pow(0.249 * std::log10(20.0) + 0.65, 2.7) - 0.72);
    EXPECT_NEAR(tone_curve(lw, 0.0, 100.0, s), eps20 / std::pow(10.0, 2.0 - 1.255) * lw / 100.0, 1e-14);
}

TEST(ToneCurves, LinearAndClampExposure) {
    ToneMapSettings s = plain(ToneOperator::linear);
    // Default white: L_wa · L_dmax / L_da = 2 L_wa: the adaptation level shows at half the peak.
    EXPECT_NEAR(tone_curve(3.0, 0.0, 3.0, s), 0.5, 1e-15);
    s.white_cd_m2 = 300.0;
    EXPECT_NEAR(tone_curve(150.0, 0.0, 1e-3, s), 0.5, 1e-15);
    // clamp limits luminance at white first and gives up chroma (docs/tone-mapping.md "Adding
    // light never darkens"): (600, 150, 30)/300 = (2, 0.5, 0.1) has Y = 0.790 (hand), kept, with
    // the red channel at 1 and the others on the line to grey; Y above 1 is white.
    s.tone_operator = ToneOperator::clamp;
    const glm::dvec3 out = tonemap_pixel({600.0, 150.0, 30.0}, 1.0, s);
    const double y = 0.2126 * 2.0 + 0.7152 * 0.5 + 0.0722 * 0.1, t = (1.0 - y) / (2.0 - y);
    EXPECT_NEAR(out.r, 1.0, 1e-12);
    EXPECT_NEAR(out.g, y + t * (0.5 - y), 1e-4);  // the weights rounded to 4 digits here
    EXPECT_NEAR(out.b, y + t * (0.1 - y), 1e-4);
    EXPECT_NEAR(luminance_of_linear_rgb(out), luminance_of_linear_rgb(glm::dvec3(2.0, 0.5, 0.1)), 1e-14);
    EXPECT_EQ(tonemap_pixel({900.0, 150.0, 30.0}, 1.0, s), glm::dvec3(1.0));  // Y = 1.0026
}

TEST(HuePreservation, NoneScalesRgbByLdOverLw) {
    ToneMapSettings s = plain(ToneOperator::empirical);
    const glm::dvec3 rgb(30.0, 2.0, 0.5);
    const double lw = luminance_of_linear_rgb(rgb);
    const double ld = tone_curve(lw, 0.0, 4.0, s);
    const glm::dvec3 out = tonemap_pixel(rgb, 4.0, s);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[c], rgb[c] * ld / lw, 1e-14 * rgb[c] * ld / lw);
}

TEST(HuePreservation, Eq428IsMinOfOneNotMax) {
    // K2012 eq 4.28 prints Y_d = max(1, L_d) and calls it "rudimentary hue preservation";
    // max would turn every pixel at least white. It is min(1, L_d): a dim pixel keeps L_d,
    // a bright one is limited to Y = 1 at its own chromaticity.
    ToneMapSettings s = plain(ToneOperator::linear);
    s.hue_preservation = HuePreservation::xyY;
    s.white_cd_m2 = 100.0;
    const glm::dvec3 dim = tonemap_pixel({25.0, 25.0, 25.0}, 1.0, s);
    EXPECT_NEAR(luminance_of_linear_rgb(dim), 0.25, 1e-14);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(dim[c], 0.25, 1e-14);
    const glm::dvec3 bright = tonemap_pixel({500.0, 500.0, 500.0}, 1.0, s);
    EXPECT_NEAR(luminance_of_linear_rgb(bright), 1.0, 1e-14);
    // Chromaticity kept for a saturated colour, luminance limited to 1.
    const glm::dvec3 orange(800.0, 200.0, 10.0);
    const glm::dvec3 out = tonemap_pixel(orange, 1.0, s);
    EXPECT_NEAR(luminance_of_linear_rgb(out), 1.0, 1e-13);
    EXPECT_NEAR(glm::length(xy_of_rgb(out) - xy_of_rgb(orange)), 0.0, 1e-13);
    EXPECT_GT(out.r, 1.0);  // eq 4.28 limits Y, not the channels
}

TEST(HuePreservation, Eq430KeepsTheLuminanceInsteadOfDividingByTheLargestChannel) {
    // K2012 eq 4.30 divides (2, 0.2, 0.01) by 2: (1, 0.1, 0.005), Y = 0.2841 of the 0.5689
    // asked for. Luminance wins here: Y stays 0.5689, red at 1, chroma given up towards grey.
    ToneMapSettings s = plain(ToneOperator::linear);
    s.hue_preservation = HuePreservation::rgb;
    s.white_cd_m2 = 100.0;
    const glm::dvec3 out = tonemap_pixel({200.0, 20.0, 1.0}, 1.0, s);
    const double y = luminance_of_linear_rgb(glm::dvec3(2.0, 0.2, 0.01));
    EXPECT_NEAR(y, 0.2126 * 2.0 + 0.7152 * 0.2 + 0.0722 * 0.01, 1e-4);  // 0.5689
    EXPECT_NEAR(out.r, 1.0, 1e-12);
    EXPECT_NEAR(luminance_of_linear_rgb(out), y, 1e-14);
    EXPECT_GT(luminance_of_linear_rgb(out), 1.9 * luminance_of_linear_rgb(glm::dvec3(1.0, 0.1, 0.005)));  // eq 4.30 keeps half
    EXPECT_LE(std::max(out.g, out.b), 1.0);
    EXPECT_EQ(tonemap_pixel({800.0, 200.0, 10.0}, 1.0, s), glm::dvec3(1.0));  // Y = 3.14: white
    const glm::dvec3 dim = tonemap_pixel({80.0, 20.0, 1.0}, 1.0, s);  // max < 1: untouched
    EXPECT_NEAR(dim.r, 0.8, 1e-15);
}

TEST(Blueshift, DerivedFromXyAndTheThesisConstants) {
    // The eq 4.29 constant derived from (0.3, 0.3) through the colour module: Y = 1 and xy = (0.3, 0.3).
    const glm::dvec3 b = blueshift_rgb({0.3, 0.3});
    EXPECT_NEAR(luminance_of_linear_rgb(b), 1.0, 1e-14);
    EXPECT_NEAR(glm::length(xy_of_rgb(b) - glm::dvec2(0.3, 0.3)), 0.0, 1e-14);
    EXPECT_NEAR(b.r, 1.038772, 1e-6);
    EXPECT_NEAR(b.g, 0.962131, 1e-6);
    EXPECT_NEAR(b.b, 1.260948, 1e-6);
    // The thesis prints (1.016784, 0.983176, 1.107126): Y = 0.99927 but xy = (0.3073, 0.3163),
    // roughly 43% of the way from D65 to (0.3, 0.3). It does not reproduce from (0.3, 0.3).
    const glm::dvec3 thesis(1.016784, 0.983176, 1.107126);
    const glm::dvec2 txy = xy_of_rgb(thesis);
    std::printf("blueshift RGB for xy (0.3, 0.3): (%.6f, %.6f, %.6f); thesis's triple has xy (%.4f, %.4f), Y %.5f\n",
                b.r, b.g, b.b, txy.x, txy.y, luminance_of_linear_rgb(thesis));
    EXPECT_NEAR(txy.x, 0.3073, 1e-4);
    EXPECT_NEAR(txy.y, 0.3163, 1e-4);
    EXPECT_GT(glm::length(b - thesis), 0.1);
}

TEST(Blueshift, DarkAdaptationTurnsEveryColourTowardsTheBlueshiftHue) {
    ToneMapSettings s;
    s.tone_operator = ToneOperator::empirical;
    for (HuePreservation h : kHues) {
        s.hue_preservation = h;
        // σ(1e-6) = 0.999975: the red light's own chromaticity has weight 2.5e-5.
        const glm::dvec3 dark = tonemap_pixel({5e-6, 0.0, 0.0}, 1e-6, s);
        EXPECT_NEAR(glm::length(xy_of_rgb(dark) - glm::dvec2(0.3, 0.3)), 0.0, 2e-4) << hue_preservation_name(h);
        // Daylight: σ(1e4) = 4e-6, colour kept (dim enough that no channel exceeds 1).
        const glm::dvec3 rgb(5e3, 1e2, 0.0);
        const glm::dvec3 day = tonemap_pixel(rgb, 1e4, s);
        EXPECT_NEAR(glm::length(xy_of_rgb(day) - xy_of_rgb(rgb)), 0.0, 1e-4) << hue_preservation_name(h);
    }
    // Off: no shift at any adaptation.
    s.blueshift = false;
    s.hue_preservation = HuePreservation::xyY;
    const glm::dvec3 off = tonemap_pixel({5e-6, 0.0, 0.0}, 1e-6, s);
    EXPECT_NEAR(glm::length(xy_of_rgb(off) - glm::dvec2(0.64, 0.33)), 0.0, 1e-12);
    // The blueshift keeps the luminance (eq 4.29: b has Y = 1).
    s.blueshift = true;
    s.hue_preservation = HuePreservation::none;
    const glm::dvec3 rgb(3e-3, 1e-3, 2e-4);
    const double ld = tone_curve(luminance_of_linear_rgb(rgb), 0.0, 0.04, s);
    EXPECT_NEAR(luminance_of_linear_rgb(tonemap_pixel(rgb, 0.04, s)), ld, 1e-14 * ld);
}

TEST(ToneMapInvariant, EveryOperatorFiniteAndMonotonicFromZeroToOneE9) {
    // docs/architecture.md: every operator finite and monotonic in luminance over 0 … 1e9 cd/m², exact
    // zero and pure primaries included, at adaptation 1e-6 … 1e6 cd/m² (25 levels), for
    // blueshift on/off and each hue mode. Monotonic: the output luminance never decreases as
    // the input luminance grows at fixed chromaticity (a relative 1e-12 allowance for
    // rounding where eq 4.28/4.30 hold the output constant).
    const std::array<glm::dvec3, 9> colours = {{
        {1, 1, 1},  // D65 white
        {1, 0, 0},  // the primaries, pure
        {0, 1, 0},
        {0, 0, 1},
        {1, 1e-9, 0},    // very saturated
        {0, 1, 1},       // cyan (on the gamut edge)
        {1, 0, 1},       // magenta
        {0.2, 1, 0.05},  // a green light
        {1, 0.6, 0.02},  // a yellow light
    }};
    std::vector<double> lums = {0.0};
    for (int i = 0; i < 199; ++i) lums.push_back(std::pow(10.0, -9.0 + 18.0 * i / 198.0));
    long checked = 0;
    for (ToneOperator op : kOperators) {
        for (HuePreservation h : kHues) {
            for (const int blue : atonlab::test::kBlueshiftModes) {
                ToneMapSettings s;
                s.tone_operator = op;
                s.hue_preservation = h;
                atonlab::test::set_blueshift(s, blue);
                for (int a = 0; a < 25; ++a) {
                    const double lwa = std::pow(10.0, -6.0 + 12.0 * a / 24.0);
                    for (const glm::dvec3& col : colours) {
                        const glm::dvec3 unit = col / luminance_of_linear_rgb(col);
                        double prev = -1.0;
                        for (double l : lums) {
                            const glm::dvec3 out = tonemap_pixel(unit * l, lwa, s);
                            ++checked;
                            ASSERT_TRUE(finite_non_negative(out))
                                << tone_operator_name(op) << " " << hue_preservation_name(h) << " blueshift "
                                << atonlab::test::blueshift_label(blue) << " L " << l << " Lwa " << lwa;
                            const double y = luminance_of_linear_rgb(out);
                            if (l == 0.0) {
                                ASSERT_EQ(y, 0.0);
                            }
                            ASSERT_GE(y, prev * (1.0 - 1e-12))
                                << tone_operator_name(op) << " " << hue_preservation_name(h) << " blueshift "
                                << atonlab::test::blueshift_label(blue) << " L " << l << " Lwa " << lwa << " colour "
                                << col.r << "," << col.g << "," << col.b;
                            prev = y;
                        }
                    }
                }
            }
        }
    }
    std::printf("monotonic and finite: %ld pixels checked\n", checked);
}

TEST(ToneMapInvariant, HostileInputsStayFiniteAndNonNegative) {
    const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
    const std::array<glm::dvec3, 10> inputs = {{
        {1e9, 0, 0},
        {0, 0, 5},
        {-1, 2, -3},
        {nan, 1, 1},
        {inf, 0, 0},
        {-inf, -inf, -inf},
        {1e300, 1e300, 1e300},
        {std::numeric_limits<double>::denorm_min(), 0, 0},
        {0, 0, 0},
        {1e-30, 1e9, 1e-30},
    }};
    for (ToneOperator op : kOperators) {
        for (HuePreservation h : kHues) {
            for (const int blue : atonlab::test::kBlueshiftModes) {
                ToneMapSettings s;
                s.tone_operator = op;
                s.hue_preservation = h;
                atonlab::test::set_blueshift(s, blue);
                for (const glm::dvec3& in : inputs) {
                    for (double lwa : {0.0, -1.0, nan, inf, 1e-12, 1e-6, 1.0, 1e6, 1e20}) {
                        EXPECT_TRUE(finite_non_negative(tonemap_pixel(in, lwa, s)))
                            << tone_operator_name(op) << " " << hue_preservation_name(h) << " " << in.r << "," << in.g
                            << "," << in.b << " at " << lwa;
                    }
                }
            }
        }
    }
    // Negative components are clipped to 0 first: (-1, 2, -3) is the pure green (0, 2, 0).
    ToneMapSettings s = plain(ToneOperator::reinhard);
    const glm::dvec3 a = tonemap_pixel({-1, 2, -3}, 1.0, s), b = tonemap_pixel({0, 2, 0}, 1.0, s);
    EXPECT_EQ(a, b);
}

TEST(ToneMapSettingsValidation, EachBadValueNamesItsKey) {
    const auto key_of = [](const ToneMapSettings& s) -> std::string {
        try {
            validate_tonemap_settings(s);
        } catch (const InputError& e) {
            return e.where() ? e.where()->key : "(no location)";
        }
        return "";
    };
    EXPECT_EQ(key_of(ToneMapSettings{}), "");
    ToneMapSettings s;
    s.white_relative = 0.0;
    EXPECT_EQ(key_of(s), "tonemap.white_relative");
    s = {};
    s.reinhard_key = std::nan("");
    EXPECT_EQ(key_of(s), "tonemap.reinhard_key");
    s = {};
    s.reinhard_white_relative = -1.0;
    EXPECT_EQ(key_of(s), "tonemap.reinhard_white_relative");
    s = {};
    s.kakimoto_g = 0.0;
    EXPECT_EQ(key_of(s), "tonemap.kakimoto_g");
    s = {};
    s.kakimoto_k = 1.0;
    EXPECT_EQ(key_of(s), "tonemap.kakimoto_k");
    s = {};
    s.white_cd_m2 = -5.0;
    EXPECT_EQ(key_of(s), "tonemap.white_cd_m2");
    s = {};
    s.display_peak_cd_m2 = std::numeric_limits<double>::infinity();
    EXPECT_EQ(key_of(s), "tonemap.display_peak_cd_m2");
    s = {};
    s.display_adaptation_cd_m2 = 0.0;
    EXPECT_EQ(key_of(s), "tonemap.display_adaptation_cd_m2");
    s = {};
    s.blueshift_xy = {0.1, 0.8};  // a real colour, outside Rec.709
    EXPECT_EQ(key_of(s), "tonemap.blueshift_xy");
    s.blueshift_xy = {0.5, 0.6};  // not a colour
    EXPECT_EQ(key_of(s), "tonemap.blueshift_xy");
    EXPECT_THROW(tonemap_gpu_params(s), InputError);
    EXPECT_DOUBLE_EQ(display_adaptation_cd_m2(ToneMapSettings{}), 50.0);
}

TEST(ToneMapImage, MatchesThePixelFunctionAndKeepsAlpha) {
    ImageRGBA32F img = image_of(4, 3, {0.5f, 2.0f, 0.1f});
    img.pixel(1, 1)[3] = 0.25f;
    img.pixel(2, 2)[0] = 1e6f;
    const ToneMapSettings s;
    const ImageRGBA32F out = tonemap_image(img, 1.0, s);
    ASSERT_EQ(out.rgba.size(), img.rgba.size());
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 4; ++x) {
            const float* p = img.pixel(x, y);
            const glm::dvec3 ref = tonemap_pixel({p[0], p[1], p[2]}, 1.0, s);
            for (int c = 0; c < 3; ++c) EXPECT_EQ(out.pixel(x, y)[c], static_cast<float>(ref[c]));
            EXPECT_EQ(out.pixel(x, y)[3], p[3]);
        }
    }
}

}  // namespace
}  // namespace atonlab::stimuli
