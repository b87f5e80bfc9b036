// The `spencer` glare model's PSF (stimuli/src/glare_models/spencer.cpp draws
// eye_model.h's spencer_psf): Spencer et al. 1995's sum of terms, against
// values worked by hand from its coefficients at 0° and 1°, the mesopic
// lenticular halo's peak, width and weight, and finite for every angle.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "atonlab/stimuli/eye_model.h"
#include "input_error.h"

namespace {

using namespace atonlab::stimuli;
using atonlab::InputError;

constexpr double pi = std::numbers::pi;

// ---- Spencer et al. 1995 -------------------------------------------------------------

TEST(Spencer, PhotopicAtZero) {
    // 0.384 × 2.61e6 + 0.478 × 20.91 / 0.02³ + 0.138 × 72.37 / 0.02²
    // = 1002240 + 0.478 × 2613750 + 0.138 × 180925
    // = 1002240 + 1249372.5 + 24967.65 = 2276580.15
    EXPECT_NEAR(spencer_psf(0.0, 550.0, SpencerVision::photopic), 2276580.15, 1e-6);
}

TEST(Spencer, ScotopicAtZero) {
    // 0.282 × 2.61e6 + 0.478 × 2613750 + 0.207 × 180925 + 0.033 × f3(0) with
    // f3(0, 568) = 436.9 e^{-19.75 × 9} ≈ 0: 736020 + 1249372.5 + 37451.475.
    EXPECT_NEAR(spencer_psf(0.0, 568.0, SpencerVision::scotopic), 2022843.975, 1e-6);
}

TEST(Spencer, PhotopicFarOut) {
    // θ = 1°: f0 = 0 (e^{-2500}), f1 = 20.91 / 1.061208 = 19.703960, f2 = 72.37 / 1.0404 = 69.559785;
    // 0.478 × 19.703960 + 0.138 × 69.559785 = 9.418493 + 9.599250 = 19.017743
    EXPECT_NEAR(spencer_psf(1.0, 550.0, SpencerVision::photopic), 19.017743, 1e-5);
}

TEST(Spencer, MesopicLenticularHaloPeaksAtThreeLambdaOver568) {
    // f0, f1, f2 do not depend on λ, so mesopic(θ, 450) - mesopic(θ, 650)
    // = 0.016 (f3(θ, 450) - f3(θ, 650)): near θ = 3·450/568 = 2.3768° it is
    // 0.016 f3(θ, 450), peaking at 0.016 × 436.9 × 568/450 = 8.823438.
    auto diff = [](double theta) {
        return spencer_psf(theta, 450.0, SpencerVision::mesopic) - spencer_psf(theta, 650.0, SpencerVision::mesopic);
    };
    double best = 0, best_theta = 0;
    for (double theta = 1.0; theta < 3.0; theta += 0.001) {
        if (diff(theta) > best) {
            best = diff(theta);
            best_theta = theta;
        }
    }
    EXPECT_NEAR(best_theta, 3 * 450.0 / 568, 0.001);
    EXPECT_NEAR(best, 8.823438, 1e-4);
    // The ring's width: 0.2° off the peak, e^{-19.75 × 0.04} = 0.453845.
    EXPECT_NEAR(diff(3 * 450.0 / 568 + 0.2), 8.823438 * 0.453845, 1e-3);
    // Each term integrates to 1 sr in deg², (180/π)² = 3282.806: the halo's
    // weight times that, from 0 to the midpoint between the two rings (2.9°).
    double integral = 0;
    const double dt = 1e-4;
    for (double theta = 0.5 * dt; theta < 2.9; theta += dt) integral += diff(theta) * 2 * pi * theta * dt;
    EXPECT_NEAR(integral, 0.016 * 3282.806, 0.005 * 0.016 * 3282.806);
}

TEST(Spencer, FiniteForEveryAngle) {
    for (auto v : {SpencerVision::photopic, SpencerVision::mesopic, SpencerVision::scotopic})
        for (double theta : {0.0, 1e-9, 0.02, 1.0, 10.0, 90.0, 180.0, 1e6}) {
            const double f = spencer_psf(theta, 575.0, v);
            EXPECT_TRUE(std::isfinite(f) && f >= 0) << theta;
        }
    EXPECT_THROW(spencer_psf(-1.0, 575.0, SpencerVision::photopic), InputError);
    EXPECT_THROW(spencer_psf(1.0, 0.0, SpencerVision::mesopic), InputError);
}

}  // namespace
