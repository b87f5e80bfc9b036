// Observers: the brightness of displayed images against analytic sums; the
// model observer answering exactly by brightness without noise, half the time
// at its PSE with noise, with the psychometric slope its Gaussian noise
// implies, with its lapses; its true PSE and threshold against closed forms;
// and the scripted observer reading and refusing answer files.
#include <gtest/gtest.h>

#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "atonlab/protocols/adjustment.h"
#include "atonlab/protocols/observer.h"

namespace {

using namespace atonlab::protocols;  // NOLINT: the test exercises the whole namespace

constexpr double kDegToRad = std::numbers::pi / 180.0;

double normal_cdf(double z) {
    return 0.5 * std::erfc(-z / std::numbers::sqrt2);
}

/// A square image, `size` pixels of `deg_per_px`, filled with `background`.
DisplayedImage blank(int size, double deg_per_px, double background = 0.0) {
    DisplayedImage img;
    img.width = size;
    img.height = size;
    img.deg_per_px = deg_per_px;
    img.luminance_cd_m2.assign(static_cast<std::size_t>(size * size), static_cast<float>(background));
    return img;
}

/// Adds `luminance` to the pixels whose centre lies within radius_deg of centre.
void add_disc(DisplayedImage& img, glm::dvec2 centre, double radius_deg, double luminance) {
    const double r = radius_deg / img.deg_per_px;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const double dx = x + 0.5 - centre.x, dy = y + 0.5 - centre.y;
            if (dx * dx + dy * dy <= r * r)
                img.luminance_cd_m2[static_cast<std::size_t>(y * img.width + x)] += static_cast<float>(luminance);
        }
}

/// The solid angle (sr) of the pixels add_disc() fills: the discrete disc.
double disc_sr(const DisplayedImage& img, glm::dvec2 centre, double radius_deg) {
    const double r = radius_deg / img.deg_per_px;
    int n = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const double dx = x + 0.5 - centre.x, dy = y + 0.5 - centre.y;
            n += dx * dx + dy * dy <= r * r ? 1 : 0;
        }
    return n * img.pixel_sr(0, 0);
}

/// A Gaussian blob of peak `amplitude` cd/m² and sd `sigma_deg`.
DisplayedImage gaussian(int size, double deg_per_px, glm::dvec2 centre, double sigma_deg, double amplitude) {
    DisplayedImage img = blank(size, deg_per_px);
    const double s = sigma_deg / deg_per_px;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const double dx = x + 0.5 - centre.x, dy = y + 0.5 - centre.y;
            img.luminance_cd_m2[static_cast<std::size_t>(y * size + x)] =
                static_cast<float>(amplitude * std::exp(-(dx * dx + dy * dy) / (2 * s * s)));
        }
    return img;
}

// ---- Brightness -------------------------------------------------------------------

// A uniform disc of luminance L and radius R puts E = L Ω into the eye: exactly
// L × (its pixel count) × (pixel solid angle), and within the Gauss circle
// problem's boundary term (< 0.2% at a 100-pixel radius) of the small-angle
// L π R².
TEST(Brightness, OfAUniformDiscIsAnalytic) {
    const double dpp = 0.01;
    const glm::dvec2 c(200.0, 200.0);
    DisplayedImage img = blank(401, dpp);
    const double l = 1000.0, radius = 1.0;
    add_disc(img, c, radius, l);
    const double e_disc = l * std::numbers::pi * std::pow(radius * kDegToRad, 2);
    // Window larger than the disc: the disc's whole illuminance.
    EXPECT_NEAR(window_illuminance_lux(img, c, 1.5), l * disc_sr(img, c, radius), 1e-6 * e_disc);
    EXPECT_NEAR(window_illuminance_lux(img, c, 1.5), e_disc, 2e-3 * e_disc);
    // Window inside the disc: L π r².
    const double e_half = l * std::numbers::pi * std::pow(0.5 * kDegToRad, 2);
    EXPECT_NEAR(window_illuminance_lux(img, c, 0.5), l * disc_sr(img, c, 0.5), 1e-6 * e_half);
    EXPECT_NEAR(window_illuminance_lux(img, c, 0.5), e_half, 2e-3 * e_half);
    // Brightness is the power law of that, exactly.
    EXPECT_DOUBLE_EQ(brightness(img, c, 1.5, 0.33), std::pow(window_illuminance_lux(img, c, 1.5), 0.33));
    EXPECT_DOUBLE_EQ(brightness(img, c, 1.5, 1.0), window_illuminance_lux(img, c, 1.5));
    // Energy ratio 2^(1/0.33) -> brightness ratio 2.
    DisplayedImage brighter = blank(401, dpp);
    add_disc(brighter, c, radius, l * std::pow(2.0, 1.0 / 0.33));
    EXPECT_NEAR(brightness(brighter, c, 1.5, 0.33) / brightness(img, c, 1.5, 0.33), 2.0, 1e-5);
}

TEST(Brightness, IncrementSubtractsTheSurround) {
    const glm::dvec2 c(100.0, 100.0);
    DisplayedImage img = blank(201, 0.01, 0.5);
    add_disc(img, c, 0.2, 40.0);
    // The window (0.4°) holds the disc on the background; the annulus 0.4-0.8° is pure background.
    const double e_disc = 40.0 * disc_sr(img, c, 0.2);
    EXPECT_NEAR(increment_illuminance_lux(img, c, 0.4), e_disc, 1e-5 * e_disc);
    const double e_window = e_disc + 0.5 * disc_sr(img, c, 0.4);
    EXPECT_NEAR(window_illuminance_lux(img, c, 0.4), e_window, 1e-5 * e_window);
    // No light: no increment.
    EXPECT_NEAR(increment_illuminance_lux(blank(201, 0.01, 0.5), c, 0.4), 0.0, 1e-15);
}

// A light on a flat screen θ off the line of sight: a 2 × 2-pixel patch of
// luminance L (as the renderer draws a light without glare) has the intensity
// I = L · A · cos θ towards the eye (A its area, a Lambertian screen) and lies
// D / cos θ away (D the viewing distance), so the illuminance at the eye is
// I / (D / cos θ)² (the inverse-square and cosine laws). With each pixel's own
// solid angle the window's sum reproduces that; a centre pixel's Ω would be
// 1/cos³θ high (1.15 % at 5°, 21 % at 20°).
TEST(Brightness, ExactPixelSolidAnglesReproduceInverseSquare) {
    const double width_m = 0.598, distance_m = 0.9;
    const int width_px = 1920;
    const double pitch_m = width_m / width_px;
    const double focal_px = distance_m / pitch_m;
    const double l = 37.0;  // cd/m²
    for (const double theta_deg : {0.0, 5.0, 20.0}) {
        for (const double azimuth_deg : {0.0, 45.0, 180.0}) {
            SCOPED_TRACE(testing::Message() << theta_deg << " deg off-axis, azimuth " << azimuth_deg << " deg");
            const double theta = theta_deg * kDegToRad, phi = azimuth_deg * kDegToRad;
            DisplayedImage img = blank(101, 180.0 / std::numbers::pi / focal_px);
            img.focal_px = focal_px;
            const glm::dvec2 c(50.0, 50.0);  // the patch's centre: pixels 49 and 50 in x and y
            const double off_px = focal_px * std::tan(theta);
            img.principal_px = c - off_px * glm::dvec2(std::cos(phi), std::sin(phi));
            for (int y = 49; y <= 50; ++y)
                for (int x = 49; x <= 50; ++x) img.luminance_cd_m2[static_cast<std::size_t>(y * 101 + x)] = l;
            const double intensity_cd = l * 4.0 * pitch_m * pitch_m * std::cos(theta);
            const double slant_m = distance_m / std::cos(theta);
            const double expected_lux = intensity_cd / (slant_m * slant_m);
            // The patch spans 2 pixels: cos³ varies across it by ~(1/focal)², far below 1e-6.
            EXPECT_NEAR(window_illuminance_lux(img, c, 0.5), expected_lux, 1e-6 * expected_lux);
            EXPECT_NEAR(window_light_lux(img, c, 0.5), expected_lux, 1e-6 * expected_lux);
            EXPECT_NEAR(increment_illuminance_lux(img, c, 0.5), expected_lux, 1e-6 * expected_lux);
        }
    }
}

// The window of an image with its geometry is a circle of visual angle: at
// 20° off-axis along x a pixel 0.5° away radially lies 0.5° / cos²20° · (px
// per degree at the centre) pixels away, tangentially 0.5° / cos 20° ·.
TEST(Brightness, ExactWindowIsACircleOfVisualAngle) {
    const double focal_px = 2000.0;
    const double dpp = 180.0 / std::numbers::pi / focal_px;
    DisplayedImage img = blank(201, dpp);
    img.focal_px = focal_px;
    const double theta = 20.0 * kDegToRad;
    const glm::dvec2 c(100.5, 100.5);  // pixel (100, 100)'s centre
    img.principal_px = c - glm::dvec2(focal_px * std::tan(theta), 0.0);
    // Radially (x): the pixel centre at angle 20° + δ lies at f tan(20° + δ).
    auto radial_px = [&](double delta_deg) {
        return focal_px * (std::tan(theta + delta_deg * kDegToRad) - std::tan(theta));
    };
    const int inside = static_cast<int>(std::floor(radial_px(0.49)));
    const int outside = static_cast<int>(std::ceil(radial_px(0.51)));
    ASSERT_GT(outside, static_cast<int>(std::ceil(0.51 / dpp)));  // beyond a pixel circle of 0.5°
    img.luminance_cd_m2[static_cast<std::size_t>(100 * 201 + 100 + inside)] = 1.0f;
    EXPECT_GT(window_illuminance_lux(img, c, 0.5), 0.0);
    img.luminance_cd_m2[static_cast<std::size_t>(100 * 201 + 100 + inside)] = 0.0f;
    img.luminance_cd_m2[static_cast<std::size_t>(100 * 201 + 100 + outside)] = 1.0f;
    EXPECT_EQ(window_illuminance_lux(img, c, 0.5), 0.0);
}

TEST(Brightness, RefusesMalformedImages) {
    DisplayedImage img = blank(10, 0.1);
    img.luminance_cd_m2.pop_back();
    EXPECT_THROW((void)brightness(img, {5, 5}, 0.2, 0.33), std::invalid_argument);
    EXPECT_THROW((void)brightness(blank(10, 0.1), {5, 5}, 0.0, 0.33), std::invalid_argument);
}

// ---- The model observer -------------------------------------------------------------

/// Two discs whose log10 brightnesses (exponent p) differ by `delta`: a pair of views.
struct Pair {
    DisplayedImage first;
    DisplayedImage second;
    Shown shown(Task task = Task::TwoAfc) const {
        Shown s;
        s.task = task;
        s.views = {{&first, {30.0, 30.0}}, {&second, {30.0, 30.0}}};
        return s;
    }
};

Pair pair_with_difference(double delta_log10_brightness, double exponent) {
    Pair p{blank(61, 0.02), blank(61, 0.02)};
    add_disc(p.first, {30.0, 30.0}, 0.1, 100.0 * std::pow(10.0, delta_log10_brightness / exponent));
    add_disc(p.second, {30.0, 30.0}, 0.1, 100.0);
    return p;
}

double proportion_first(ModelObserver& o, const Shown& s, int n) {
    int first = 0;
    for (int i = 0; i < n; ++i) first += o.answer(s).response == Response::Left ? 1 : 0;
    return static_cast<double>(first) / n;
}

TEST(ModelObserver, WithoutNoiseAnswersExactlyByBrightness) {
    ModelObserverParams params;
    params.noise_sd_log10 = 0.0;
    ModelObserver o(params, 1);
    Rng rng(9);
    for (int i = 0; i < 200; ++i) {
        Pair p{blank(41, 0.03), blank(41, 0.03)};
        const double a = rng.uniform(1.0, 100.0), b = rng.uniform(1.0, 100.0);
        // Different shapes: the decision is on the window sums, not the peaks.
        add_disc(p.first, {20.5, 20.5}, rng.uniform(0.05, 0.3), a);
        add_disc(p.second, {20.5, 20.5}, rng.uniform(0.05, 0.3), b);
        const double b0 = brightness(p.first, {20.5, 20.5}, params.window_radius_deg, params.exponent);
        const double b1 = brightness(p.second, {20.5, 20.5}, params.window_radius_deg, params.exponent);
        ASSERT_NE(b0, b1);
        Shown s;
        s.task = Task::TwoAfc;
        s.views = {{&p.first, {20.5, 20.5}}, {&p.second, {20.5, 20.5}}};
        EXPECT_EQ(o.answer(s).response, b0 > b1 ? Response::Left : Response::Right);
        EXPECT_EQ(model_p_first(params, {&p.first, {20.5, 20.5}}, {&p.second, {20.5, 20.5}}), b0 > b1 ? 1.0 : 0.0);
    }
    // Exactly equal: a fair coin, both answers appear.
    const Pair same = pair_with_difference(0.0, params.exponent);
    const double p = proportion_first(o, same.shown(), 400);
    EXPECT_GT(p, 0.3);
    EXPECT_LT(p, 0.7);
    // Yes-no: Yes exactly when the increment exceeds the threshold.
    const DisplayedImage img = blank(61, 0.02);
    const double e_threshold = params.detection_threshold_lux;
    for (double f : {0.5, 0.9, 1.1, 2.0}) {
        DisplayedImage d = img;
        add_disc(d, {30.0, 30.0}, 0.1, f * e_threshold / disc_sr(img, {30.0, 30.0}, 0.1));
        Shown s;
        s.task = Task::YesNo;
        s.views = {{&d, {30.0, 30.0}}};
        EXPECT_EQ(o.answer(s).response, f > 1.0 ? Response::Yes : Response::No) << f;
    }
}

TEST(ModelObserver, ChoosesEachSideHalfTheTimeAtThePse) {
    ModelObserverParams params;
    params.noise_sd_log10 = 0.05;
    params.window_radius_deg = 0.15;  // holds the 0.1° discs; small windows keep the many trials fast
    ModelObserver o(params, 2);
    // Equal brightness from different images: a disc against a Gaussian of the
    // same window sum is still the PSE.
    const Pair p = pair_with_difference(0.0, params.exponent);
    const int n = 20000;
    const double se = std::sqrt(0.25 / n);
    EXPECT_NEAR(proportion_first(o, p.shown(), n), 0.5, 3 * se);
    EXPECT_DOUBLE_EQ(model_p_first(params, p.shown().views[0], p.shown().views[1]), 0.5);
}

TEST(ModelObserver, PsychometricSlopeIsItsGaussianNoise) {
    ModelObserverParams params;
    params.noise_sd_log10 = 0.04;
    params.window_radius_deg = 0.15;  // holds the 0.1° discs; small windows keep the many trials fast
    ModelObserver o(params, 3);
    const int n = 20000;
    // At Δ = k σ (log10 brightness) the model picks the first with Φ(k).
    std::map<double, double> observed;
    for (double k : {-2.0, -1.0, 1.0, 2.0}) {
        const Pair p = pair_with_difference(k * params.noise_sd_log10, params.exponent);
        const double expected = normal_cdf(k);
        const double se = std::sqrt(expected * (1 - expected) / n);
        observed[k] = proportion_first(o, p.shown(), n);
        EXPECT_NEAR(observed[k], expected, 3 * se) << k;
        EXPECT_NEAR(model_p_first(params, p.shown().views[0], p.shown().views[1]), expected, 1e-4) << k;
    }
    // A probit line through the points at ±σ gives the noise back:
    // σ_fit = 2σ / (Φ⁻¹(p+) − Φ⁻¹(p−)). Its standard error here is about 0.8%.
    const boost::math::normal_distribution<double> unit;
    const double sigma_fit = 2 * params.noise_sd_log10 /
                             (boost::math::quantile(unit, observed[1.0]) - boost::math::quantile(unit, observed[-1.0]));
    EXPECT_NEAR(sigma_fit, params.noise_sd_log10, 0.03 * params.noise_sd_log10);
}

TEST(ModelObserver, LapsesAnswerAtRandom) {
    ModelObserverParams params;
    params.noise_sd_log10 = 0.01;
    params.lapse_rate = 0.2;
    params.window_radius_deg = 0.15;  // holds the 0.1° discs; small windows keep the many trials fast
    ModelObserver o(params, 4);
    const Pair p = pair_with_difference(1.0, params.exponent);  // 100 σ: never wrong but for lapses
    const int n = 20000;
    const double expected = 1.0 - params.lapse_rate / 2.0;
    EXPECT_NEAR(proportion_first(o, p.shown(), n), expected, 3 * std::sqrt(expected * (1 - expected) / n));
    EXPECT_DOUBLE_EQ(model_p_first(params, p.shown().views[0], p.shown().views[1]), expected);
}

TEST(ModelObserver, YesNoFollowsTheNoiseAroundTheThreshold) {
    ModelObserverParams params;
    params.noise_sd_log10 = 0.05;
    params.detection_threshold_lux = 1e-6;
    params.window_radius_deg = 0.15;  // holds the 0.1° discs; small windows keep the many trials fast
    ModelObserver o(params, 5);
    const int n = 20000;
    for (double k : {-1.0, 0.0, 1.5}) {
        // p log10(E/E_θ) = k σ.
        const double e = params.detection_threshold_lux * std::pow(10.0, k * params.noise_sd_log10 / params.exponent);
        DisplayedImage img = blank(61, 0.02, 0.01);
        add_disc(img, {30.0, 30.0}, 0.1, e / disc_sr(img, {30.0, 30.0}, 0.1));
        Shown s;
        s.task = Task::YesNo;
        s.views = {{&img, {30.0, 30.0}}};
        int yes = 0;
        for (int i = 0; i < n; ++i) yes += o.answer(s).response == Response::Yes ? 1 : 0;
        const double expected = normal_cdf(k);
        EXPECT_NEAR(static_cast<double>(yes) / n, expected, 3 * std::sqrt(expected * (1 - expected) / n)) << k;
        EXPECT_NEAR(model_p_yes(params, s.views[0]), expected, 1e-5) << k;  // float pixels
    }
}

TEST(ModelObserver, IsDeterministicForASeed) {
    ModelObserverParams params;
    params.lapse_rate = 0.1;
    const Pair p = pair_with_difference(0.01, params.exponent);
    ModelObserver a(params, 77), b(params, 77), c(params, 78);
    std::vector<Response> ra, rb, rc;
    for (int i = 0; i < 200; ++i) {
        ra.push_back(a.answer(p.shown()).response);
        rb.push_back(b.answer(p.shown()).response);
        rc.push_back(c.answer(p.shown()).response);
    }
    EXPECT_EQ(ra, rb);
    EXPECT_NE(ra, rc);
}

TEST(ModelObserver, RespondsSlowerNearThePse) {
    ModelObserverParams params;
    const Pair hard = pair_with_difference(0.0, params.exponent);
    const Pair easy = pair_with_difference(0.5, params.exponent);
    ModelObserver o(params, 6);
    const double rt_hard = o.answer(hard.shown()).response_time_s;
    const double rt_easy = o.answer(easy.shown()).response_time_s;
    EXPECT_DOUBLE_EQ(rt_hard, params.rt_base_s + params.rt_hard_s);
    EXPECT_NEAR(rt_easy, params.rt_base_s, 1e-6);
}

TEST(ModelObserver, RefusesBadParametersAndViews) {
    ModelObserverParams params;
    params.lapse_rate = 1.0;
    EXPECT_THROW(ModelObserver(params, 1), std::invalid_argument);
    params = {};
    params.noise_sd_log10 = -0.1;
    EXPECT_THROW(ModelObserver(params, 1), std::invalid_argument);
    ModelObserver o({}, 1);
    Shown s;
    s.task = Task::TwoAfc;
    EXPECT_THROW((void)o.answer(s), std::invalid_argument);
    s.task = Task::Adjust;
    EXPECT_THROW((void)o.answer(s), std::invalid_argument);
}

// ---- True PSE and threshold ---------------------------------------------------------

// The reference is a 0.05° Gaussian of peak 10^level, the test a 0.3° one of
// peak A: in a window of radius r a Gaussian of sd s and peak a holds
// a · 2π s² (1 − exp(−r²/2s²)) (small angles), so the PSE is
//   level = log10(A s_t² (1 − exp(−r²/2s_t²)) / (s_r² (1 − exp(−r²/2s_r²)))).
TEST(TruePse, MatchesTheClosedFormForGaussianBlobs) {
    ModelObserverParams params;
    params.window_radius_deg = 0.4;
    const double dpp = 0.005;
    const int size = 241;
    const glm::dvec2 c(120.5, 120.5);
    const double s_ref = 0.05, s_test = 0.3, a_test = 50.0;
    const DisplayedImage test = gaussian(size, dpp, c, s_test, a_test);
    const auto reference_at = [&](double level) { return gaussian(size, dpp, c, s_ref, std::pow(10.0, level)); };
    const double r = params.window_radius_deg;
    const auto held = [&](double s) { return s * s * (1 - std::exp(-r * r / (2 * s * s))); };
    const double expected = std::log10(a_test * held(s_test) / held(s_ref));
    const double pse = true_pse(reference_at, c, test, c, -2.0, 6.0, params);
    EXPECT_NEAR(pse, expected, 2e-3);  // pixel sums against the integral
    // At the PSE the model chooses each half the time, to the root finder's precision.
    const DisplayedImage ref = reference_at(pse);
    EXPECT_NEAR(model_p_first(params, {&ref, c}, {&test, c}), 0.5, 1e-6);  // float pixels
    // The exponent does not move the PSE (equal energy is equal brightness).
    ModelObserverParams p2 = params;
    p2.exponent = 0.5;
    EXPECT_NEAR(true_pse(reference_at, c, test, c, -2.0, 6.0, p2), pse, 1e-6);
    // The 75% point lies σ Φ⁻¹(0.75) / p above it, in log10 units.
    const double l75 = true_matching_level(reference_at, c, test, c, 0.75, -2.0, 6.0, params);
    EXPECT_NEAR(l75 - pse, params.noise_sd_log10 * 0.6744897501960817 / params.exponent, 1e-6);
    // No crossing in the interval: an error, not a made-up number.
    EXPECT_THROW((void)true_pse(reference_at, c, test, c, 4.0, 6.0, params), std::invalid_argument);
}

TEST(TrueThreshold, IsWhereTheModelSaysYesAsOftenAsAsked) {
    ModelObserverParams params;
    params.lapse_rate = 0.04;
    const glm::dvec2 c(30.0, 30.0);
    const auto image_at = [&](double level) {
        DisplayedImage img = blank(61, 0.02, 0.001);
        add_disc(img, c, 0.1, std::pow(10.0, level));
        return img;
    };
    for (double p : {0.5, 0.75, 0.9}) {
        const double level = true_threshold(image_at, c, p, -6.0, 6.0, params);
        const DisplayedImage img = image_at(level);
        EXPECT_NEAR(model_p_yes(params, {&img, c}), p, 1e-6) << p;  // float pixels
    }
    // Beyond the lapses' reach.
    EXPECT_THROW((void)true_threshold(image_at, c, 0.99, -6.0, 6.0, params), std::invalid_argument);
}

// With no noise the model's adjustment ends within a fine step of its PSE.
TEST(ModelObserver, AdjustsToItsPse) {
    ModelObserverParams params;
    params.noise_sd_log10 = 0.0;
    const glm::dvec2 c(40.0, 40.0);
    DisplayedImage test = blank(81, 0.02);
    add_disc(test, c, 0.3, 3.0);
    const auto reference_at = [&](double level) {
        DisplayedImage img = blank(81, 0.02);
        add_disc(img, c, 0.1, std::pow(10.0, level));
        return img;
    };
    const double pse = true_pse(reference_at, c, test, c, -2.0, 4.0, params);
    AdjustmentParams ap;
    ap.start_min = -1.0;
    ap.start_max = 3.0;
    ap.coarse_step = 0.1;
    ap.fine_step = 0.01;
    ap.n_trials = 5;
    Adjustment adj(ap, 4);
    ModelObserver o(params, 8);
    while (auto prop = adj.next()) {
        const DisplayedImage ref = reference_at(prop->level);
        Shown s;
        s.task = Task::Adjust;
        s.views = {{&test, c}, {&ref, c}};
        s.adjusted_view = 1;
        adj.record(o.answer(s).response);
    }
    for (double m : adj.matches()) EXPECT_NEAR(m, pse, ap.fine_step + 1e-9);
}

// ---- The scripted observer ---------------------------------------------------------

Shown task_only(Task t) {
    Shown s;
    s.task = t;
    return s;
}

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const atonlab::InputError& e) {
        return e.what();
    }
    return "(no InputError)";
}

TEST(ScriptedObserver, ReadsAnswersInOrder) {
    ScriptedObserver o = ScriptedObserver::parse(
        "# session 3, observer P07\n"
        "left 0.62\n"
        "\n"
        "RIGHT   1.5   # changed their mind\n"
        "second\n"
        "yes 0.4\n"
        "coarse-up 0.2\n"
        "fine_down 0.1\n"
        "confirm 2",
        "p07.txt");
    EXPECT_EQ(o.size(), 7u);
    Answer a = o.answer(task_only(Task::TwoAfc));
    EXPECT_EQ(a.response, Response::Left);
    EXPECT_DOUBLE_EQ(a.response_time_s, 0.62);
    a = o.answer(task_only(Task::TwoAfc));
    EXPECT_EQ(a.response, Response::Right);
    EXPECT_DOUBLE_EQ(a.response_time_s, 1.5);
    a = o.answer(task_only(Task::TwoAfc));
    EXPECT_EQ(a.response, Response::Right);
    EXPECT_DOUBLE_EQ(a.response_time_s, 0.0);  // not given
    EXPECT_EQ(o.answer(task_only(Task::YesNo)).response, Response::Yes);
    EXPECT_EQ(o.answer(task_only(Task::Adjust)).response, Response::CoarseUp);
    EXPECT_EQ(o.answer(task_only(Task::Adjust)).response, Response::FineDown);
    EXPECT_EQ(o.remaining(), 1u);
    EXPECT_EQ(o.answer(task_only(Task::Adjust)).response, Response::Confirm);
    EXPECT_EQ(error_of([&] { (void)o.answer(task_only(Task::TwoAfc)); }),
              "p07.txt: the script's 7 answers are used up: answer 8 needs one more line.");
}

TEST(ScriptedObserver, RefusesBadLinesNamingThem) {
    EXPECT_EQ(error_of([] { (void)ScriptedObserver::parse("left 0.5\n# ok\nlfet 0.3\n", "a.txt"); }),
              "a.txt:3: unknown answer \"lfet\"; expected one of left, right, first, second, yes, no, coarse_up, "
              "coarse_down, fine_up, fine_down, confirm.");
    EXPECT_EQ(error_of([] { (void)ScriptedObserver::parse("yes -1\n", "a.txt"); }),
              "a.txt:1: the response time \"-1\" is not a number of seconds >= 0.");
    EXPECT_EQ(error_of([] { (void)ScriptedObserver::parse("\n\nyes 0.5s\n", "a.txt"); }),
              "a.txt:3: the response time \"0.5s\" is not a number of seconds >= 0.");
    EXPECT_EQ(error_of([] { (void)ScriptedObserver::parse("no 0.5 0.7\n", "a.txt"); }),
              "a.txt:1: expected an answer and at most a response time in seconds (\"left 0.62\"), got \"no 0.5 "
              "0.7\".");
    ScriptedObserver o = ScriptedObserver::parse("left\nyes\n", "b.txt");
    (void)o.answer(task_only(Task::TwoAfc));
    EXPECT_EQ(error_of([&] { (void)o.answer(task_only(Task::TwoAfc)); }),
              "b.txt:2: the answer \"yes\" does not fit a 2afc trial, which takes left or right.");
    EXPECT_EQ(o.remaining(), 1u);  // the refused answer is still there
    EXPECT_EQ(ScriptedObserver::parse("", "empty.txt").size(), 0u);
}

TEST(ScriptedObserver, LoadsFiles) {
    const std::filesystem::path file =
        std::filesystem::temp_directory_path() /
        ("atonlab_scripted_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + ".txt");
    {
        std::ofstream out(file);
        out << "no 0.8\nyes 0.9\n";
    }
    ScriptedObserver o = ScriptedObserver::load(file);
    EXPECT_EQ(o.answer(task_only(Task::YesNo)).response, Response::No);
    std::filesystem::remove(file);
    EXPECT_EQ(error_of([] { (void)ScriptedObserver::load("/nonexistent/answers.txt"); }),
              "/nonexistent/answers.txt: cannot read the answer file: No such file or directory.");
}

}  // namespace
