// Numerical stress tests of adaptation and tone mapping on the CPU (issue 8, tonemap.h),
// extending test_tonemap.cpp's invariant (output luminance monotonic at 25 adaptation
// levels for 9 colours) to the whole domains:
//  - every output *channel* non-decreasing in luminance over 0 … 1e9 cd/m² for random
//    (fixed-seed) chromaticities, pure primaries and random adaptation 1e-6 … 1e6 cd/m²;
//  - the tone curve non-increasing in the adaptation luminance (a brighter-adapted eye
//    sees the same luminance as no brighter), except the perceptual operator's measured
//    TVI jumps (test_tonemap.cpp, Tvi.DiscontinuitiesAtTheBranchesMeasured);
//  - adaptation -> 0 and -> ∞, L = 0, the scotopic V over its range;
//  - temporal adaptation (eq 4.16-4.17) over Δt = 0 … 10 s between 0 and 1e9 cd/m²;
//  - the log-average (eq 4.15) of frames full of zeros, of 1e9 and of non-finite values.
// docs/numerical-behaviour.md lists the singular points and what each does there.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/tonemap.h"
#include "blueshift_modes.h"

namespace atonlab::stimuli {
using namespace atonlab::display;  // colour science, the tone-mapping CPU reference (display/)
namespace {

constexpr std::array<ToneOperator, 6> kOperators = {ToneOperator::empirical, ToneOperator::perceptual,
                                                    ToneOperator::reinhard,  ToneOperator::kakimoto,
                                                    ToneOperator::linear,    ToneOperator::clamp};
constexpr std::array<HuePreservation, 3> kHues = {HuePreservation::none, HuePreservation::xyY, HuePreservation::rgb};
constexpr double kInf = std::numeric_limits<double>::infinity();

bool finite_non_negative(glm::dvec3 v) {
    return std::isfinite(v.r) && std::isfinite(v.g) && std::isfinite(v.b) && v.r >= 0.0 && v.g >= 0.0 && v.b >= 0.0;
}

/// Luminances: exact 0, then 1e-9 … 1e9 log-uniform (n points), sorted.
std::vector<double> luminance_sweep(int n) {
    std::vector<double> l = {0.0};
    for (int i = 0; i < n; ++i) l.push_back(std::pow(10.0, -9.0 + 18.0 * i / (n - 1)));
    return l;
}

TEST(StressTonemap, EveryChannelNonDecreasingOverFullLuminanceRange) {
    // Property-based: 300 random (chromaticity, adaptation) pairs per setting — every
    // fifth chromaticity a pure primary or secondary, the rest random and often extreme —
    // each swept over 0 … 1e9 cd/m² at 90 luminances. Every channel of the display-relative
    // output is finite, >= 0, exactly 0 at L = 0, and never decreases as L grows (a relative
    // 1e-12 allowance where eq 4.28/4.30 hold a channel constant); with the per-pixel
    // blueshift, the output luminance never decreases.
    const std::array<glm::dvec3, 7> pure = {
        {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}, {1, 0, 1}, {1, 1, 1}}};
    const std::vector<double> lums = luminance_sweep(90);
    long checked = 0;
    for (ToneOperator op : kOperators) {
        for (HuePreservation h : kHues) {
            for (const int blue : atonlab::test::kBlueshiftModes) {
                ToneMapSettings s;
                s.tone_operator = op;
                s.hue_preservation = h;
                atonlab::test::set_blueshift(s, blue);
                std::mt19937 rng(1000u + static_cast<unsigned>(op) * 10u + static_cast<unsigned>(h) * 3u +
                                 static_cast<unsigned>(blue));
                std::uniform_real_distribution<double> u(0.0, 1.0);
                for (int k = 0; k < 300; ++k) {
                    glm::dvec3 colour = k % 5 == 0
                                            ? pure[static_cast<std::size_t>(k / 5) % pure.size()]
                                            : glm::dvec3(std::pow(10.0, -6.0 * u(rng)), std::pow(10.0, -6.0 * u(rng)),
                                                         std::pow(10.0, -6.0 * u(rng)));
                    colour /= luminance_of_linear_rgb(colour);
                    const double lwa = std::pow(10.0, -6.0 + 12.0 * u(rng));
                    glm::dvec3 prev(0.0);
                    for (double l : lums) {
                        const glm::dvec3 out = tonemap_pixel(colour * l, lwa, s);
                        ++checked;
                        ASSERT_TRUE(finite_non_negative(out))
                            << tone_operator_name(op) << " " << hue_preservation_name(h) << " L " << l;
                        if (l == 0.0) {
                            ASSERT_EQ(out, glm::dvec3(0.0));
                        }
                        // Per pixel (mode 2) the hue moves with the light's own luminance:
                        // a channel may fall as weight moves between channels (a dim red
                        // light is drawn blue-white, a bright one red). What must not fall
                        // there is the output luminance.
                        if (blue == 2) {
                            ASSERT_GE(luminance_of_linear_rgb(out), luminance_of_linear_rgb(prev) * (1.0 - 1e-12))
                                << tone_operator_name(op) << " " << hue_preservation_name(h) << " L " << l << " Lwa "
                                << lwa << " colour " << colour.r << "," << colour.g << "," << colour.b;
                            prev = out;
                            continue;
                        }
                        for (int c = 0; c < 3; ++c) {
                            ASSERT_GE(out[c], prev[c] * (1.0 - 1e-12))
                                << tone_operator_name(op) << " " << hue_preservation_name(h) << " blueshift "
                                << atonlab::test::blueshift_label(blue) << " channel " << c << " L " << l << " Lwa "
                                << lwa << " colour " << colour.r << "," << colour.g << "," << colour.b;
                        }
                        prev = out;
                    }
                }
            }
        }
    }
    std::printf("tone mapping: %ld pixels, every channel finite and non-decreasing in luminance\n", checked);
}

TEST(StressTonemap, ToneCurveNonIncreasingInAdaptationOverOneE12) {
    // At fixed scene luminance, adaptation 1e-6 … 1e6 cd/m² at 2401 levels: the display
    // luminance never grows as the eye adapts to more light. Empirical (α(L)/L falls: eq
    // 4.18-4.19), Reinhard, Kakimoto, linear and clamp exactly; the perceptual operator
    // except across the two TVI joins where the threshold drops as L rises (rods at
    // 10^-1.44 by x0.9728, cones at 10^1.9 by x0.99280), where it may rise by that factor.
    const double rod_jump = 1.0 / std::pow(10.0, -0.011987381756638271);
    const double cone_jump = 1.0 / std::pow(10.0, -0.0031375210955872923);
    std::vector<double> levels;
    for (int i = 0; i <= 2400; ++i) levels.push_back(std::pow(10.0, -6.0 + 12.0 * i / 2400.0));
    int perceptual_rises = 0;
    for (ToneOperator op : kOperators) {
        ToneMapSettings s;
        s.tone_operator = op;
        for (double l : {1e-9, 1e-3, 1.0, 1e3, 1e9}) {
            // The perceptual operator's rods see V = 2.573 Y for D65 white (tonemap.h).
            const double v = 2.573 * l;
            double prev = tone_curve(l, v, levels.front(), s);
            for (std::size_t i = 1; i < levels.size(); ++i) {
                const double ld = tone_curve(l, v, levels[i], s);
                ASSERT_TRUE(std::isfinite(ld) && ld >= 0.0) << tone_operator_name(op);
                if (ld > prev * (1.0 + 1e-12)) {
                    ASSERT_EQ(op, ToneOperator::perceptual)
                        << tone_operator_name(op) << " rises at L " << l << " from Lwa " << levels[i - 1] << " to "
                        << levels[i] << ": " << prev << " -> " << ld;
                    const double lo = std::log10(levels[i - 1]), hi = std::log10(levels[i]);
                    const bool rod = lo < -1.44 && hi >= -1.44, cone = lo < 1.9 && hi >= 1.9;
                    ASSERT_TRUE(rod || cone) << "perceptual rises away from a TVI join at Lwa " << levels[i];
                    ASSERT_LE(ld / prev, (rod ? rod_jump : cone_jump) * (1.0 + 1e-9)) << levels[i];
                    ++perceptual_rises;
                }
                prev = ld;
            }
        }
    }
    std::printf("perceptual: %d rises, each across a documented TVI join\n", perceptual_rises);
}

TEST(StressTonemap, AdaptationLimitsAreTheDocumentedClamp) {
    // L_wa -> 0 (0, denormals, 1e-300, NaN, negative) behaves as 1e-7 cd/m², L_wa -> ∞ as
    // 1e10 cd/m² (tonemap.h kMin/kMaxAdaptationCdM2); the result is finite for every pixel.
    std::mt19937 rng(41);
    std::uniform_real_distribution<double> u(-9.0, 9.0);
    for (ToneOperator op : kOperators) {
        for (HuePreservation h : kHues) {
            ToneMapSettings s;
            s.tone_operator = op;
            s.hue_preservation = h;
            for (int i = 0; i < 200; ++i) {
                const glm::dvec3 rgb(std::pow(10.0, u(rng)), std::pow(10.0, u(rng)), std::pow(10.0, u(rng)));
                const glm::dvec3 dark = tonemap_pixel(rgb, kMinAdaptationCdM2, s);
                const glm::dvec3 bright = tonemap_pixel(rgb, kMaxAdaptationCdM2, s);
                ASSERT_TRUE(finite_non_negative(dark) && finite_non_negative(bright));
                for (double lwa : {0.0, -0.0, std::numeric_limits<double>::denorm_min(), 1e-300, -1.0, std::nan("")})
                    ASSERT_EQ(tonemap_pixel(rgb, lwa, s), dark) << tone_operator_name(op) << " Lwa " << lwa;
                for (double lwa : {1e20, 1e300, kInf}) ASSERT_EQ(tonemap_pixel(rgb, lwa, s), bright);
            }
        }
    }
}

TEST(StressTonemap, PerceptualNonDecreasingInScotopicLuminance) {
    // Eq 4.26 adds σ(L_wa)·m_R·V: non-decreasing in V over 0 … the cap, at every adaptation.
    ToneMapSettings s;
    s.tone_operator = ToneOperator::perceptual;
    for (double lwa : {1e-6, 1e-3, 0.04, 1.0, 1e6}) {
        for (double l : {0.0, 1e-6, 1.0, 1e9}) {
            double prev = -1.0;
            for (double v : luminance_sweep(200)) {
                const double ld = tone_curve(l, v * 1e6, lwa, s);
                ASSERT_TRUE(std::isfinite(ld));
                ASSERT_GE(ld, prev) << "V " << v * 1e6 << " Lwa " << lwa;
                prev = ld;
            }
        }
    }
}

// ---------------------------------------------------------------------------
// Temporal adaptation, K2012 eq 4.16-4.17.

TEST(StressTemporalAdaptation, DeltaTFromZeroToTenSecondsBetweenZeroAndOneE9) {
    // Every (current, target) pair of 0, 1e-6 … 1e9 cd/m², Δt over 0 … 10 s (1001 steps):
    // finite, between current and target, monotonic towards the target as Δt grows; Δt = 0
    // is the current level exactly, Δt = 10 s (25 τ_rod) within 1e-10 of the gap.
    const std::vector<double> levels = {0.0, 1e-6, 1e-3, 0.04, 1.0, 1e3, 1e6, 1e9};
    for (double current : levels) {
        for (double target : levels) {
            double prev = current;
            for (int i = 0; i <= 1000; ++i) {
                const double dt = 10.0 * i / 1000.0;
                const double a = temporal_adaptation(current, target, dt);
                ASSERT_TRUE(std::isfinite(a)) << current << " -> " << target << " dt " << dt;
                ASSERT_GE(a, std::min(current, target)) << current << " -> " << target << " dt " << dt;
                ASSERT_LE(a, std::max(current, target)) << current << " -> " << target << " dt " << dt;
                if (target >= current) {
                    ASSERT_GE(a, prev);
                } else {
                    ASSERT_LE(a, prev);
                }
                prev = a;
            }
            EXPECT_EQ(temporal_adaptation(current, target, 0.0), current);
            EXPECT_NEAR(temporal_adaptation(current, target, 10.0), target, 1e-10 * std::abs(target - current));
        }
    }
}

TEST(StressTemporalAdaptation, ManySmallStepsEqualOneLargeStep) {
    // For a fixed target, eq 4.16 composes: n steps of Δt/n land where one step of Δt does
    // (e^-a e^-b = e^-(a+b)), so the frame rate does not change the adapted level. 1 s at
    // 1000 Hz against one 1 s step, dark to bright and bright to dark.
    for (const auto& [from, to] : std::vector<std::pair<double, double>>{{1e-3, 1e3}, {1e6, 1e-6}, {0.0, 1e9}}) {
        double a = from;
        for (int i = 0; i < 1000; ++i) a = temporal_adaptation(a, to, 1e-3);
        const double b = temporal_adaptation(from, to, 1.0);
        EXPECT_NEAR(a, b, 1e-9 * std::abs(to - from)) << from << " -> " << to;
    }
}

// ---------------------------------------------------------------------------
// The log-average, K2012 eq 4.15.

ImageRGBA32F uniform_image(int w, int h, float v) {
    ImageRGBA32F img;
    img.width = w;
    img.height = h;
    img.rgba.assign(static_cast<std::size_t>(w) * h * 4, v);
    return img;
}

TEST(StressLogAverage, AllZeroFrameIsEpsilon) {
    // A black frame: exp(mean(ln ε)) = ε exactly in exact arithmetic; the adaptation it
    // drives (ε = 1e-6) is then clamped to 1e-7 … 1e10 by the tone mapper, never 0.
    for (double eps : {1e-6, 1e-4, 1e-12}) {
        const double l = log_average_luminance(uniform_image(97, 61, 0.0f), eps);
        EXPECT_NEAR(l, eps, 1e-12 * eps);
    }
}

TEST(StressLogAverage, ZerosAndOneE9InOneFrame) {
    // Half the pixels 0, half 1e9 cd/m²: the geometric mean sqrt(ε (1e9 + ε)) (31.6 cd/m²).
    // And monotone: raising any one pixel never lowers the log-average.
    ImageRGBA32F img = uniform_image(64, 64, 0.0f);
    for (std::size_t i = 0; i < img.rgba.size() / 2; ++i) img.rgba[i] = 1e9f;
    const double eps = kLogAverageEpsilonCdM2;
    EXPECT_NEAR(log_average_luminance(img, eps), std::sqrt(eps * (1e9 + eps)), 1e-9 * std::sqrt(eps * 1e9));
    std::mt19937 rng(42);
    std::uniform_int_distribution<std::size_t> pick(0, 64 * 64 - 1);
    std::uniform_real_distribution<double> u(-9.0, 9.0);
    double prev = log_average_luminance(img, eps);
    for (int i = 0; i < 200; ++i) {
        const std::size_t p = pick(rng);
        const float raised = std::max(img.rgba[p * 4 + 1], static_cast<float>(std::pow(10.0, u(rng))));
        img.rgba[p * 4] = img.rgba[p * 4 + 1] = img.rgba[p * 4 + 2] = raised;
        const double l = log_average_luminance(img, eps);
        ASSERT_TRUE(std::isfinite(l));
        ASSERT_GE(l, prev * (1.0 - 1e-13));
        prev = l;
    }
}

TEST(StressLogAverage, NonFinitePixelsAreClippedNotPropagated) {
    // Documented: components clipped to >= 0 with NaN -> 0, and capped at 1e15 cd/m², so
    // NaN, ±inf and FLT_MAX pixels leave a finite log-average equal to that of the clipped frame.
    ImageRGBA32F img = uniform_image(16, 16, 1.0f);
    ImageRGBA32F clipped = img;
    const float specials[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                              -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::max(), -1.0f};
    const float as_clipped[] = {0.0f, 1e15f, 0.0f, 1e15f, 0.0f};
    for (std::size_t k = 0; k < 5; ++k) {
        for (int c = 0; c < 3; ++c) {
            img.rgba[(k * 7) * 4 + static_cast<std::size_t>(c)] = specials[k];
            clipped.rgba[(k * 7) * 4 + static_cast<std::size_t>(c)] = as_clipped[k];
        }
    }
    const double l = log_average_luminance(img);
    EXPECT_TRUE(std::isfinite(l));
    // 1e15f is 1e15 - 1.3e1 (fp32): the clipped frame's own log-average differs by 1e-10.
    EXPECT_NEAR(l, log_average_luminance(clipped), 1e-9 * l);
}

}  // namespace
}  // namespace atonlab::stimuli
