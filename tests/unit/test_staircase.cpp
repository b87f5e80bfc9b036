// Up/down and weighted staircases against sequences worked out by hand from
// PsychoPy's StairHandler rules (psychopy/data/staircase.py), cross-checked
// where possible with the expected values in PsychoPy's own test suite
// (psychopy/tests/test_data/test_StairHandlers.py), and against the
// theoretical convergence points of simulated observers (Levitt 1971:
// 1-up/n-down converges on P(Yes) = 0.5^(1/n); Kaernbach 1991: weighted
// up/down on P(Yes) = p).
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "atonlab/protocols/rng.h"
#include "atonlab/protocols/staircase.h"
#include "atonlab/protocols/weighted_staircase.h"
#include "normal_distribution.h"
#include "procedure_error.h"

namespace {

using atonlab::protocols::binary;
using atonlab::protocols::ProcedureError;
using atonlab::protocols::Response;
using atonlab::protocols::Rng;
using atonlab::protocols::Staircase;
using atonlab::protocols::StaircaseParams;
using atonlab::protocols::StepType;
using atonlab::protocols::WeightedStaircase;
using atonlab::protocols::WeightedStaircaseParams;

constexpr Response Y = Response::Yes;
constexpr Response N = Response::No;

/// Runs the staircase over `responses` (stopping early if it finishes) and
/// returns the level of every trial shown.
std::vector<double> run(Staircase& s, const std::vector<Response>& responses) {
    std::vector<double> shown;
    for (Response r : responses) {
        const auto p = s.next();
        if (!p) break;
        EXPECT_EQ(p->trial, shown.size());
        shown.push_back(p->level);
        s.record(r);
    }
    return shown;
}

/// PsychoPy's makeBasicResponseCycles: nCorrect Yes then nIncorrect No, repeated, cut to length.
std::vector<Response> cycles(int n_yes, int n_no, std::size_t length) {
    std::vector<Response> r;
    while (r.size() < length) {
        for (int i = 0; i < n_yes && r.size() < length; ++i) r.push_back(Y);
        for (int i = 0; i < n_no && r.size() < length; ++i) r.push_back(N);
    }
    return r;
}

void expect_levels(const std::vector<double>& got, const std::vector<double>& want, double tol) {
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) EXPECT_NEAR(got[i], want[i], tol) << "trial " << i;
}

// 1-up/3-down, linear, steps [0.1, 0.01, 0.001], start 0.8 in [0, 1],
// nReversals 4, nTrials 20; answers YYYY NNNN YYYY NNNN YYYY.
//  T0  0.8   Y  initial 1-up/1-down rule: down (start -> down, no reversal) -> 0.7
//  T1  0.7   Y  down -> 0.6;  T2 0.6 Y -> 0.5;  T3 0.5 Y -> 0.4
//  T4  0.4   N  down -> up: REVERSAL 1 (level 0.4); step -> 0.01; the initial rule
//               still makes this step: up -> 0.41; run counter reset to 0
//  T5  0.41  N  counter -1 <= -nUp: up (no reversal) -> 0.42; T6 -> 0.43; T7 -> 0.44
//  T8  0.44  Y  counter +1;  T9 0.44 Y  counter +2
//  T10 0.44  Y  counter +3 >= nDown: up -> down: REVERSAL 2 (0.44); step -> 0.001 -> 0.439
//  T11 0.439 Y  counter +1 (the run restarted at the step)
//  T12 0.439 N  counter -1: down -> up: REVERSAL 3 (0.439); step stays 0.001 -> 0.440
//  T13 0.440 N  -> 0.441; T14 -> 0.442; T15 -> 0.443
//  T16 0.443 Y  +1; T17 0.443 Y +2
//  T18 0.443 Y  +3: REVERSAL 4 (0.443) -> 0.442. 4 reversals but only 19 trials < nTrials:
//               NOT finished (both minimums must be met)
//  T19 0.442 Y  20 trials, 4 reversals: finished.
// PsychoPy's test_StairHandlerLinear expects exactly these values.
TEST(Staircase, LinearOneUpThreeDownByHand) {
    StaircaseParams p;
    p.start = 0.8;
    p.min_level = 0.0;
    p.max_level = 1.0;
    p.step_sizes = {0.1, 0.01, 0.001};
    p.n_up = 1;
    p.n_down = 3;
    p.n_reversals = 4;
    p.n_trials = 20;
    p.step_type = StepType::Lin;
    Staircase s(p);
    const auto shown = run(s, cycles(4, 4, 40));
    expect_levels(shown, {0.8,  0.7,   0.6,   0.5,  0.4,   0.41,  0.42,  0.43,  0.44,  0.44,
                          0.44, 0.439, 0.439, 0.44, 0.441, 0.442, 0.443, 0.443, 0.443, 0.442},
                  1e-12);
    EXPECT_TRUE(s.finished());
    EXPECT_FALSE(s.next().has_value());
    EXPECT_EQ(s.reversal_trials(), (std::vector<std::size_t>{4, 10, 12, 18}));
    expect_levels(s.reversal_levels(), {0.4, 0.44, 0.439, 0.443}, 1e-12);
    // estimate(): mean of all reversal levels.
    EXPECT_NEAR(s.estimate().value, (0.4 + 0.44 + 0.439 + 0.443) / 4, 1e-12);
    EXPECT_EQ(s.estimate().n, 4u);
}

// Same run with nReversals unset: PsychoPy defaults it to len(stepSizes) = 3, so
// the stop rule is met at T19 (3 reversals long before, 20 trials): same 20 trials.
TEST(Staircase, NReversalsDefaultsToStepCount) {
    StaircaseParams p;
    p.start = 0.8;
    p.step_sizes = {0.1, 0.01, 0.001};
    p.n_trials = 20;
    p.step_type = StepType::Lin;
    EXPECT_EQ(*Staircase(p).params().n_reversals, 3);
    Staircase s(p);
    EXPECT_EQ(run(s, cycles(4, 4, 40)).size(), 20u);

    p.n_reversals = 2;  // smaller than the step list: raised to 3 (PsychoPy)
    EXPECT_EQ(*Staircase(p).params().n_reversals, 3);
    p.n_reversals = 5;  // larger: kept
    EXPECT_EQ(*Staircase(p).params().n_reversals, 5);
}

// dB steps [0.4, 0.2, 0.2, 0.1], same rule and answers as the linear case. Writing
// level = 0.8 * 10^(e/20), the exponent e (dB) walks exactly like the linear case:
//  T0..T3 Y: e = 0, -0.4, -0.8, -1.2;  T4 e=-1.6 N: REVERSAL 1, step -> 0.2, up
//  T5..T8: e = -1.4, -1.2, -1.0, -0.8 (T5-T7 N up; T8 Y)
//  T9 -0.8 Y; T10 -0.8 Y: REVERSAL 2, step -> stepSizes[2] = 0.2, down -> -1.0
//  T11 -1.0 Y (+1); T12 -1.0 N: REVERSAL 3, step -> stepSizes[3] = 0.1, up -> -0.9
//  T13..T16: -0.9, -0.8, -0.7, -0.6 (T16 Y); T17 -0.6 Y; T18 -0.6 Y: REVERSAL 4 -> -0.7
//  T19 -0.7: 20 trials, finished.
// PsychoPy's test_StairHandlerDb lists 0.8, 0.763994069, ... 0.746603441, 0.738057142.
TEST(Staircase, DecibelStepListByHand) {
    StaircaseParams p;
    p.start = 0.8;
    p.min_level = 0.0;
    p.max_level = 1.0;
    p.step_sizes = {0.4, 0.2, 0.2, 0.1};
    p.n_reversals = 4;
    p.n_trials = 20;
    p.step_type = StepType::Db;
    Staircase s(p);
    const auto shown = run(s, cycles(4, 4, 40));
    const std::vector<double> e_db = {0,    -0.4, -0.8, -1.2, -1.6, -1.4, -1.2, -1.0, -0.8, -0.8,
                                      -0.8, -1.0, -1.0, -0.9, -0.8, -0.7, -0.6, -0.6, -0.6, -0.7};
    std::vector<double> want;
    for (double e : e_db) want.push_back(0.8 * std::pow(10.0, e / 20.0));
    expect_levels(shown, want, 1e-12);
    // PsychoPy's own expected values (9 significant digits).
    expect_levels(shown, {0.8,         0.763994069, 0.729608671, 0.696770872, 0.665411017, 0.680910431, 0.696770872,
                          0.713000751, 0.729608671, 0.729608671, 0.729608671, 0.713000751, 0.713000751, 0.72125691,
                          0.729608671, 0.738057142, 0.746603441, 0.746603441, 0.746603441, 0.738057142},
                  1e-9);
    EXPECT_EQ(s.reversal_trials(), (std::vector<std::size_t>{4, 10, 12, 18}));
    EXPECT_TRUE(s.finished());
}

// Log10 steps: stepSizes / 20 in log units equals the dB run above (PsychoPy's
// test_StairHandlerLog makes the same point).
TEST(Staircase, LogStepsMatchDecibelStepsOverTwenty) {
    StaircaseParams p;
    p.start = 0.8;
    p.step_sizes = {0.4 / 20, 0.2 / 20, 0.2 / 20, 0.1 / 20};
    p.n_reversals = 4;
    p.n_trials = 20;
    p.step_type = StepType::Log;
    Staircase s(p);
    const auto shown = run(s, cycles(4, 4, 40));
    ASSERT_EQ(shown.size(), 20u);
    EXPECT_NEAR(shown[4], 0.8 * std::pow(10.0, -1.6 / 20), 1e-12);
    EXPECT_NEAR(shown[19], 0.8 * std::pow(10.0, -0.7 / 20), 1e-12);
}

// Log10 steps [0.2, 0.1], 2-up/1-down, start 1 = 10^0, nReversals 3; answers N N Y N N N Y.
//  T0 e=0   N  initial rule: up (no reversal) -> 0.2
//  T1 e=0.2 N  up -> 0.4
//  T2 e=0.4 Y  up -> down: REVERSAL 1 (10^0.4); step -> 0.1; initial rule steps down -> 0.3
//  T3 e=0.3 N  counter -1 (> -nUp = -2): stay
//  T4 e=0.3 N  counter -2: up; was down: REVERSAL 2 (10^0.3) -> 0.4
//  T5 e=0.4 N  counter restarts from 0 at the step: -1: stay
//  T6 e=0.4 Y  counter +1 >= nDown = 1: down; was up: REVERSAL 3 (10^0.4) -> 0.3; finished
TEST(Staircase, LogTwoUpOneDownByHand) {
    StaircaseParams p;
    p.start = 1.0;
    p.step_sizes = {0.2, 0.1};
    p.step_type = StepType::Log;
    p.n_up = 2;
    p.n_down = 1;
    p.n_reversals = 3;
    Staircase s(p);
    const auto shown = run(s, {N, N, Y, N, N, N, Y, Y, Y});
    std::vector<double> want;
    for (double e : {0.0, 0.2, 0.4, 0.3, 0.3, 0.4, 0.4}) want.push_back(std::pow(10.0, e));
    expect_levels(shown, want, 1e-12);
    EXPECT_TRUE(s.finished());
    EXPECT_EQ(s.reversal_trials(), (std::vector<std::size_t>{2, 4, 6}));
    expect_levels(s.reversal_levels(), {std::pow(10.0, 0.4), std::pow(10.0, 0.3), std::pow(10.0, 0.4)}, 1e-12);
}

// 1-up/1-down, scalar step 0.1 lin, nReversals 6, nTrials 10; answers YYN repeated.
//  T0 0.8 Y -> 0.7; T1 0.7 Y -> 0.6; T2 0.6 N: REV -> 0.7; T3 0.7 Y: REV -> 0.6
//  T4 0.6 Y -> 0.5; T5 0.5 N: REV -> 0.6; T6 0.6 Y: REV -> 0.5; T7 0.5 Y -> 0.4
//  T8 0.4 N: REV -> 0.5; T9 0.5 Y: REV (6th), 10 trials: finished.
// PsychoPy's test_StairHandlerScalarStepSize expects the same.
TEST(Staircase, ScalarStepOneUpOneDownByHand) {
    StaircaseParams p;
    p.start = 0.8;
    p.min_level = 0.0;
    p.max_level = 1.0;
    p.step_sizes = {0.1};
    p.n_up = 1;
    p.n_down = 1;
    p.n_reversals = 6;
    p.n_trials = 10;
    p.step_type = StepType::Lin;
    Staircase s(p);
    expect_levels(run(s, cycles(2, 1, 20)), {0.8, 0.7, 0.6, 0.7, 0.6, 0.5, 0.6, 0.5, 0.4, 0.5}, 1e-12);
    EXPECT_EQ(s.reversal_trials(), (std::vector<std::size_t>{2, 3, 5, 6, 8, 9}));
    EXPECT_TRUE(s.finished());
}

// applyInitialRule = false, 1-up/2-down, step 2 lin, start 10, nReversals 2; answers N Y Y N.
//  T0 10 N: counter -1 <= -1: up; direction was 'start': no reversal -> 12
//  T1 12 Y: counter +1 < 2: stay;  T2 12 Y: +2: down, was up: REVERSAL 1 -> 10
//  T3 10 N: -1: up, was down: REVERSAL 2 -> 12; finished.
// PsychoPy's test_applyInitialRule_False: intensities [10, 12, 12, 10].
TEST(Staircase, WithoutInitialRuleByHand) {
    StaircaseParams p;
    p.start = 10;
    p.step_sizes = {2};
    p.n_reversals = 2;
    p.n_up = 1;
    p.n_down = 2;
    p.apply_initial_rule = false;
    p.step_type = StepType::Lin;
    Staircase s(p);
    expect_levels(run(s, {N, Y, Y, N, N}), {10, 12, 12, 10}, 0.0);
    EXPECT_EQ(s.reversal_trials(), (std::vector<std::size_t>{2, 3}));
    EXPECT_TRUE(s.finished());
}

// Clamps. 1-up/2-down lin, step 0.2, start 0.9 in [0.5, 1.0], nReversals 2; answers N N Y Y Y Y Y N.
//  T0 0.9 N: initial rule up: 1.1 clamped to max 1.0
//  T1 1.0 N: up: 1.2 -> 1.0 (no reversal: still up)
//  T2 1.0 Y: REVERSAL 1 (1.0), initial rule down -> 0.8
//  T3 0.8 Y: counter +1 (< 2)
//  T4 0.8 Y: +2: down (already down, no reversal) -> 0.6
//  T5 0.6 Y: +1;  T6 0.6 Y: +2: down 0.4 clamped to min 0.5
//  T7 0.5 N: -1: up: REVERSAL 2 (0.5) -> 0.7; finished (nTrials 0).
TEST(Staircase, ClampsByHand) {
    StaircaseParams p;
    p.start = 0.9;
    p.min_level = 0.5;
    p.max_level = 1.0;
    p.step_sizes = {0.2};
    p.n_up = 1;
    p.n_down = 2;
    p.n_reversals = 2;
    p.step_type = StepType::Lin;
    Staircase s(p);
    expect_levels(run(s, {N, N, Y, Y, Y, Y, Y, N, Y}), {0.9, 1.0, 1.0, 0.8, 0.8, 0.6, 0.6, 0.5}, 1e-12);
    EXPECT_EQ(s.reversal_trials(), (std::vector<std::size_t>{2, 7}));
    expect_levels(s.reversal_levels(), {1.0, 0.5}, 1e-12);
    EXPECT_TRUE(s.finished());
}

// max_trials caps an observer who never reverses (always Yes at min_level).
TEST(Staircase, MaxTrialsCapsARunaway) {
    StaircaseParams p;
    p.start = 1.0;
    p.min_level = 0.0;
    p.step_sizes = {0.5};
    p.step_type = StepType::Lin;
    p.n_reversals = 3;
    p.max_trials = 25;
    Staircase s(p);
    const auto shown = run(s, std::vector<Response>(100, Y));
    EXPECT_EQ(shown.size(), 25u);
    EXPECT_EQ(shown.back(), 0.0);
    EXPECT_TRUE(s.reversal_levels().empty());
    EXPECT_TRUE(std::isnan(s.estimate().value));
}

TEST(Staircase, EstimateUsesTheLastReversals) {
    StaircaseParams p;
    p.start = 0.8;
    p.step_sizes = {0.1};
    p.n_up = 1;
    p.n_down = 1;
    p.n_reversals = 6;
    p.n_trials = 10;
    p.step_type = StepType::Lin;
    p.estimate_reversals = 4;
    Staircase s(p);
    run(s, cycles(2, 1, 20));  // reversal levels 0.6 0.7 0.5 0.6 0.4 0.5 (see ScalarStepOneUpOneDownByHand)
    const auto e = s.estimate();
    EXPECT_EQ(e.n, 4u);
    EXPECT_NEAR(e.value, (0.5 + 0.6 + 0.4 + 0.5) / 4, 1e-12);
    // sample sd of {0.5, 0.6, 0.4, 0.5}: deviations 0, .1, -.1, 0 -> sqrt(0.02 / 3)
    EXPECT_NEAR(e.sd, std::sqrt(0.02 / 3), 1e-12);
}

// Weighted up/down, p = 0.75: S_up = S_down * 0.75/0.25 = 3 S_down. S_down = 1 lin, start 10,
// nReversals 4; answers Y Y N Y N N Y.
//  T0 10 Y -> 9;  T1 9 Y -> 8;  T2 8 N: REVERSAL 1 (8) -> 11;  T3 11 Y: REVERSAL 2 (11) -> 10
//  T4 10 N: REVERSAL 3 (10) -> 13;  T5 13 N -> 16;  T6 16 Y: REVERSAL 4 (16) -> 15, finished.
TEST(WeightedStaircase, LinearByHand) {
    WeightedStaircaseParams p;
    p.start = 10;
    p.target = 0.75;
    p.step_sizes = {1.0};
    p.step_type = StepType::Lin;
    p.n_reversals = 4;
    WeightedStaircase s(p);
    EXPECT_EQ(s.kind(), "weighted-staircase");
    expect_levels(run(s, {Y, Y, N, Y, N, N, Y, Y}), {10, 9, 8, 11, 10, 13, 16}, 1e-12);
    EXPECT_EQ(s.reversal_trials(), (std::vector<std::size_t>{2, 3, 4, 6}));
    expect_levels(s.reversal_levels(), {8, 11, 10, 16}, 1e-12);
    EXPECT_TRUE(s.finished());
}

// Weighted, p = 0.8 (S_up = 4 S_down), dB steps S_down = [2, 1], start 1 = 10^(0/20),
// nReversals defaults to 2, nTrials 5; answers Y N N Y Y. Exponent e in dB:
//  T0 e=0 Y -> -2;  T1 -2 N: REVERSAL 1, S_down -> 1, up 4 -> 2;  T2 2 N -> 6
//  T3 6 Y: REVERSAL 2 -> 5;  T4 5 Y -> 4; 5 trials and 2 reversals: finished.
TEST(WeightedStaircase, DecibelStepListByHand) {
    WeightedStaircaseParams p;
    p.start = 1.0;
    p.target = 0.8;
    p.step_sizes = {2.0, 1.0};
    p.step_type = StepType::Db;
    p.n_trials = 5;
    WeightedStaircase s(p);
    std::vector<double> want;
    for (double e : {0.0, -2.0, 2.0, 6.0, 5.0}) want.push_back(std::pow(10.0, e / 20.0));
    expect_levels(run(s, {Y, N, N, Y, Y, Y}), want, 1e-12);
    EXPECT_EQ(s.reversal_trials(), (std::vector<std::size_t>{1, 3}));
    EXPECT_TRUE(s.finished());
}

// ---- Convergence on simulated observers -------------------------------------

using atonlab::test::normal_cdf;
using atonlab::test::normal_quantile;

/// Mean over `runs` seeded runs of the mean of the last `last` reversal levels,
/// with a yes/no observer P(Yes | x) = Phi((x - mu) / sigma), mu = 0, sigma = 1.
double converged_level(Staircase prototype, int runs, int last) {
    double total = 0;
    for (int run_i = 0; run_i < runs; ++run_i) {
        Staircase s = prototype;
        Rng observer(1000 + static_cast<std::uint64_t>(run_i));
        while (auto p = s.next()) s.record(binary(observer.uniform() < normal_cdf(p->level)));
        const auto& rev = s.reversal_levels();
        EXPECT_GE(rev.size(), static_cast<std::size_t>(last));
        double sum = 0;
        for (std::size_t i = rev.size() - static_cast<std::size_t>(last); i < rev.size(); ++i) sum += rev[i];
        total += sum / last;
    }
    return total / runs;
}

StaircaseParams simulation_params(int n_up, int n_down) {
    StaircaseParams p;
    p.start = 2.5;
    p.step_sizes = {0.8, 0.4, 0.2, 0.1};
    p.step_type = StepType::Lin;
    p.n_up = n_up;
    p.n_down = n_down;
    p.n_reversals = 60;
    return p;
}

// 1-up/3-down tracks P(Yes) = 0.5^(1/3) = 79.4%, at x = Phi^-1(0.794) = 0.819 sigma.
// With a final step of 0.1 sigma the transformed rule's bias is a few hundredths of
// sigma; 40 runs x 50 reversals put the standard error near 0.01 sigma.
TEST(StaircaseConvergence, OneUpThreeDownOn794Percent) {
    const double target = normal_quantile(std::pow(0.5, 1.0 / 3.0));
    EXPECT_NEAR(target, 0.8193, 1e-4);
    EXPECT_NEAR(converged_level(Staircase(simulation_params(1, 3)), 40, 50), target, 0.05);
}

// 1-up/2-down tracks 70.7%, at 0.545 sigma.
TEST(StaircaseConvergence, OneUpTwoDownOn707Percent) {
    const double target = normal_quantile(std::sqrt(0.5));
    EXPECT_NEAR(converged_level(Staircase(simulation_params(1, 2)), 40, 50), target, 0.05);
}

// 1-up/1-down tracks 50%: x = mu = 0.
TEST(StaircaseConvergence, OneUpOneDownOnFiftyPercent) {
    EXPECT_NEAR(converged_level(Staircase(simulation_params(1, 1)), 40, 50), 0.0, 0.05);
}

// Weighted up/down with p = 0.75 tracks P(Yes) = 75%: x = 0.674 sigma. The discrete
// walk with unequal steps sits slightly above it (about 0.6 S_down, measured: +0.018 at
// S_down = 0.05, +0.006 at 0.02, +0.002 at 0.01), inside the tolerance at S_down = 0.02.
TEST(StaircaseConvergence, WeightedOnTargetProbability) {
    WeightedStaircaseParams p;
    p.start = 2.5;
    p.target = 0.75;
    p.step_sizes = {0.4, 0.2, 0.1, 0.05, 0.02};
    p.step_type = StepType::Lin;
    p.n_reversals = 60;
    EXPECT_NEAR(converged_level(WeightedStaircase(p), 40, 50), normal_quantile(0.75), 0.05);
}

// ---- Bad parameters -----------------------------------------------------------

/// Expects `make` to throw ProcedureError naming `parameter`.
using atonlab::test::expect_bad;

TEST(Staircase, BadParametersNameTheParameter) {
    const auto with = [](auto change) {
        return [change] {
            StaircaseParams p;
            p.start = 1.0;
            p.step_sizes = {1.0};
            change(p);
            Staircase s(p);
        };
    };
    expect_bad(with([](StaircaseParams& p) { p.step_sizes = {}; }), "step_sizes");
    expect_bad(with([](StaircaseParams& p) { p.step_sizes = {1.0, 0.0}; }), "step_sizes");
    expect_bad(with([](StaircaseParams& p) { p.step_sizes = {-0.5}; }), "step_sizes");
    expect_bad(with([](StaircaseParams& p) { p.step_sizes = {NAN}; }), "step_sizes");
    expect_bad(with([](StaircaseParams& p) { p.n_down = 0; }), "n_down");
    expect_bad(with([](StaircaseParams& p) { p.n_up = 0; }), "n_up");
    expect_bad(with([](StaircaseParams& p) { p.n_trials = -1; }), "n_trials");
    expect_bad(with([](StaircaseParams& p) { p.n_reversals = -1; }), "n_reversals");
    expect_bad(with([](StaircaseParams& p) {
                   p.n_reversals = 0;
                   p.n_trials = 0;
               }),
               "n_reversals");  // no stop rule
    expect_bad(with([](StaircaseParams& p) { p.max_trials = 0; }), "max_trials");
    expect_bad(with([](StaircaseParams& p) {
                   p.n_trials = 50;
                   p.max_trials = 10;
               }),
               "max_trials");
    expect_bad(with([](StaircaseParams& p) {
                   p.min_level = 2.0;
                   p.max_level = 1.0;
               }),
               "min_level");
    expect_bad(with([](StaircaseParams& p) { p.start = 0.0; }), "start");  // dB steps multiply
    expect_bad(with([](StaircaseParams& p) {
                   p.start = -1.0;
                   p.step_type = StepType::Log;
               }),
               "start");
    expect_bad(with([](StaircaseParams& p) {
                   p.start = INFINITY;
                   p.step_type = StepType::Lin;
               }),
               "start");
    expect_bad(with([](StaircaseParams& p) { p.max_level = 0.5; }), "start");
    expect_bad(with([](StaircaseParams& p) { p.min_level = 1.5; }), "start");
    expect_bad(with([](StaircaseParams& p) { p.up_step_ratio = 0.0; }), "up_step_ratio");
    expect_bad(with([](StaircaseParams& p) { p.estimate_reversals = -2; }), "estimate_reversals");
    expect_bad([] { atonlab::protocols::parse_step_type("dB"); }, "step_type");
    // A zero-start linear staircase and an explicit stop rule of 0 reversals + n trials are fine.
    StaircaseParams ok;
    ok.start = 0.0;
    ok.step_type = StepType::Lin;
    ok.n_reversals = 0;
    ok.n_trials = 5;
    EXPECT_NO_THROW(Staircase{ok});

    const auto weighted = [](double target) {
        return [target] {
            WeightedStaircaseParams p;
            p.start = 1.0;
            p.target = target;
            WeightedStaircase s(p);
        };
    };
    expect_bad(weighted(0.0), "target");
    expect_bad(weighted(1.0), "target");
    expect_bad(weighted(NAN), "target");
    expect_bad(
        [] {
            WeightedStaircaseParams p;
            p.start = 1.0;
            p.step_sizes = {0.0};
            WeightedStaircase s(p);
        },
        "step_sizes");
}

TEST(Staircase, RejectsAnswersItCannotTake) {
    StaircaseParams p;
    p.start = 1.0;
    Staircase s(p);
    s.record(Y);
    const std::string before = s.state();
    expect_bad([&] { s.record(Response::Left); }, "response");
    expect_bad([&] { s.record(Response::Confirm); }, "response");
    EXPECT_EQ(s.state(), before);  // nothing changed
    EXPECT_EQ(s.history().size(), 1u);
}

}  // namespace
