// QUEST against (1) the closed-form inverse of the Weibull and Pelli's quantile
// order, (2) a brute-force Bayesian posterior computed here, in the linear
// domain, from the prior and the product of the likelihoods on the same grid,
// (3) the values PsychoPy's test suite expects from its port of the same
// Psychtoolbox code (psychopy/tests/test_data/test_StairHandlers.py,
// TestQuestHandler.test_QuestHandler), (4) simulated observers with a known
// threshold, and (5) 10 000-trial runs that must stay finite.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "atonlab/protocols/quest.h"
#include "atonlab/protocols/rng.h"
#include "procedure_error.h"

namespace {

using atonlab::protocols::binary;
using atonlab::protocols::ProcedureError;
using atonlab::protocols::Quest;
using atonlab::protocols::QuestMethod;
using atonlab::protocols::QuestParams;
using atonlab::protocols::Response;
using atonlab::protocols::Rng;

// ---- Independent reference computations -------------------------------------

/// QuestCreate's Weibull at x (log10 units, threshold shift already added).
double weibull(const QuestParams& p, double x) {
    return p.delta * p.gamma + (1 - p.delta) * (1 - (1 - p.gamma) * std::exp(-std::pow(10.0, p.beta * x)));
}

/// The x at which the unshifted Weibull equals p_threshold, solved in closed form:
/// e^-u = (1 - (pT - delta gamma)/(1 - delta)) / (1 - gamma), x = log10(u) / beta.
double x_threshold_analytic(const QuestParams& p) {
    const double e = (1 - (p.p_threshold - p.delta * p.gamma) / (1 - p.delta)) / (1 - p.gamma);
    return std::log10(-std::log(e)) / p.beta;
}

/// QuestRecompute's xThreshold: linear interpolation of the tabulated function on
/// x2 = i2*grain, i2 = -dim..dim, over its strictly increasing points.
double x_threshold_tabulated(const QuestParams& p, long dim) {
    double prev_x = 0, prev_p = -1;
    bool have_prev = false;
    for (long i2 = -dim; i2 < dim; ++i2) {
        const double x = static_cast<double>(i2) * p.grain;
        const double v = weibull(p, x);
        const double v_next = weibull(p, static_cast<double>(i2 + 1) * p.grain);
        if (v_next == v) continue;  // not part of the strictly monotonic subset
        if (have_prev && prev_p <= p.p_threshold && p.p_threshold <= v)
            return prev_x + (p.p_threshold - prev_p) / (v - prev_p) * (x - prev_x);
        prev_x = x;
        prev_p = v;
        have_prev = true;
    }
    return std::numeric_limits<double>::quiet_NaN();
}

struct Trial {
    double level;
    bool yes;
};

/// Posterior on the QUEST grid by Bayes' rule, written out directly: Gaussian prior
/// times the product over trials of p or 1 - p, at x = (rounded, clamped) intensity
/// offset minus the candidate threshold; then normalised.
std::vector<double> brute_posterior(const QuestParams& p, long dim, double x_thr, const std::vector<Trial>& trials) {
    std::vector<double> post;
    for (long i = -dim / 2; i <= dim / 2; ++i) {
        const double xi = static_cast<double>(i) * p.grain;
        double v = std::exp(-0.5 * (xi / p.t_guess_sd) * (xi / p.t_guess_sd));
        for (const Trial& t : trials) {
            double k = std::round((t.level - p.t_guess) / p.grain);
            k = std::clamp(k, -static_cast<double>(dim / 2), static_cast<double>(dim / 2));
            const double x = (k - static_cast<double>(i)) * p.grain;
            const double py = weibull(p, x + x_thr);
            v *= t.yes ? py : 1 - py;
        }
        post.push_back(v);
    }
    double sum = 0;
    for (double v : post) sum += v;
    for (double& v : post) v /= sum;
    return post;
}

struct Summary {
    double mean, sd, mode;
};

Summary summarise(const std::vector<double>& post, const std::vector<double>& grid) {
    double m = 0, m2 = 0;
    std::size_t imax = 0;
    for (std::size_t j = 0; j < post.size(); ++j) {
        m += post[j] * grid[j];
        if (post[j] > post[imax]) imax = j;
    }
    for (std::size_t j = 0; j < post.size(); ++j) m2 += post[j] * (grid[j] - m) * (grid[j] - m);
    return {m, std::sqrt(m2), grid[imax]};
}

/// QuestQuantile's rule: interpolate the cumulative sum over the points where it
/// strictly increases; below the first point, the first grid point.
double brute_quantile(const std::vector<double>& post, const std::vector<double>& grid, double q) {
    std::vector<double> c, x;
    double cum = 0, prev = -1;
    for (std::size_t j = 0; j < post.size(); ++j) {
        cum += post[j];
        if (cum > prev) {
            c.push_back(cum);
            x.push_back(grid[j]);
        }
        prev = cum;
    }
    const double target = q * cum;
    if (target < c[0]) return grid[0];
    for (std::size_t k = 1; k < c.size(); ++k)
        if (target <= c[k]) return x[k - 1] + (target - c[k - 1]) / (c[k] - c[k - 1]) * (x[k] - x[k - 1]);
    return x.back();
}

// ---- Psychometric function and quantile order ---------------------------------

TEST(Quest, ThresholdShiftMatchesTheClosedForm) {
    QuestParams p;  // QuestDemo: pThreshold 0.82, beta 3.5, delta 0.01, gamma 0.5
    p.n_trials = 10;
    Quest q(p);
    // The table interpolation differs from the exact inverse by O(grain^2).
    EXPECT_NEAR(q.x_threshold(), x_threshold_analytic(p), 1e-4);
    EXPECT_NEAR(q.x_threshold(), x_threshold_tabulated(p, 500), 1e-12);
    EXPECT_NEAR(q.p_yes(0.0), 0.82, 1e-4);  // threshold sits at x = 0
    // Floor and ceiling: gamma, and delta*gamma + 1 - delta.
    EXPECT_NEAR(q.p_yes(-5.0), 0.5, 1e-12);
    EXPECT_NEAR(q.p_yes(5.0), 0.005 + 0.99, 1e-12);
}

// QuestRecompute's comment: "For 2-interval forced choice, if pL=0.5 and pH=1 then best
// quantileOrder=0.60". By hand: pE = -0.5 ln 0.5 - 0.5 ln 0.5 = ln 2; pE = 1/(1 + e^(ln2 / -0.5))
// = 1/(1 + 1/4) = 0.8; order = (0.8 - 0.5) / 0.5 = 0.6.
TEST(Quest, PelliQuantileOrderForTwoAfc) {
    QuestParams p;
    p.delta = 0.0;
    p.gamma = 0.5;
    p.n_trials = 10;
    EXPECT_NEAR(Quest(p).quantile_order(), 0.6, 1e-12);
    // Yes/no with gamma = delta = 0: pL = 0, pH = 1: pE = 0/(-1) -> 1/(1 + e^0) = 0.5: the median.
    p.gamma = 0.0;
    p.p_threshold = 0.5;
    EXPECT_NEAR(Quest(p).quantile_order(), 0.5, 1e-12);
}

TEST(Quest, GridFollowsQuestCreate) {
    QuestParams p;
    p.t_guess = -1;
    p.n_trials = 10;
    EXPECT_EQ(Quest(p).grid_size(), 501u);  // dim = 500 without a range
    p.range = 5;
    p.grain = 0.01;
    EXPECT_EQ(Quest(p).grid_size(), 501u);  // 5 / 0.01 = 500 steps
    p.range = 3.005;
    EXPECT_EQ(Quest(p).grid_size(), 303u);  // 300.5 rounded up to the even 302
    const auto g = Quest(p).grid();
    EXPECT_NEAR(g.front(), -1 - 1.51, 1e-12);
    EXPECT_NEAR(g.back(), -1 + 1.51, 1e-12);
}

// ---- Brute-force posterior ----------------------------------------------------

void check_against_brute_force(const QuestParams& p, long dim, std::uint64_t seed, bool observer_driven) {
    Quest q(p);
    Rng rng(seed);
    std::vector<Trial> trials;
    for (int t = 0; t < 50; ++t) {
        const auto prop = q.next();
        ASSERT_TRUE(prop.has_value());
        // Either coin flips, or an observer with threshold 0.3 above the guess.
        const bool yes = observer_driven
                             ? rng.uniform() < weibull(p, prop->level - (p.t_guess + 0.3) + x_threshold_analytic(p))
                             : rng.coin();
        trials.push_back({prop->level, yes});
        q.record(binary(yes));
    }
    const double x_thr = x_threshold_tabulated(p, dim);
    const auto want = brute_posterior(p, dim, x_thr, trials);
    const auto got = q.posterior();
    ASSERT_EQ(got.size(), want.size());
    double peak = 0;
    for (double v : want) peak = std::max(peak, v);
    for (std::size_t j = 0; j < want.size(); ++j)
        ASSERT_NEAR(got[j], want[j], 1e-10 * want[j] + 1e-14 * peak) << "grid point " << j;

    const auto grid = q.grid();
    const Summary s = summarise(want, grid);
    EXPECT_NEAR(q.mean(), s.mean, 1e-10);
    EXPECT_NEAR(q.sd(), s.sd, 1e-10);
    EXPECT_DOUBLE_EQ(q.mode(), s.mode);
    for (double order : {0.05, 0.25, 0.5, q.quantile_order(), 0.95})
        EXPECT_NEAR(q.quantile(order), brute_quantile(want, grid, order), 1e-9) << "order " << order;
    EXPECT_NEAR(q.estimate().value, s.mean, 1e-10);
    EXPECT_NEAR(q.estimate().sd, s.sd, 1e-10);
}

TEST(Quest, PosteriorMatchesBruteForceTwoAfc) {
    QuestParams p;  // QuestDemo's 2AFC function
    p.t_guess = -1;
    p.t_guess_sd = 2;
    p.range = 5;
    p.n_trials = 100;
    check_against_brute_force(p, 500, 11, false);
    check_against_brute_force(p, 500, 12, true);
}

TEST(Quest, PosteriorMatchesBruteForceYesNoWithoutLapses) {
    QuestParams p;  // gamma = delta = 0: likelihoods reach exactly 0 and 1
    p.t_guess = 0.5;
    p.t_guess_sd = 1;
    p.gamma = 0;
    p.delta = 0;
    p.p_threshold = 0.5;
    p.beta = 2;
    p.grain = 0.02;
    p.range = 4;
    p.method = QuestMethod::Mean;
    p.n_trials = 100;
    check_against_brute_force(p, 200, 21, true);
    p.method = QuestMethod::Mode;
    check_against_brute_force(p, 200, 22, false);
}

// ---- PsychoPy's expected values -------------------------------------------------

// PsychoPy's QuestHandler test: startVal 50, startValSd 50, pThreshold 0.82, beta 3.5,
// gamma 0.5, delta 0.01, grain 0.01, range 100, minVal 0, maxVal 100, method 'quantile',
// answers 1 1 0 0 1 1 0 0 1 1, first trial at startVal. Its expected intensities and the
// final mean, mode and quantile (np.allclose: rtol 1e-5).
TEST(Quest, ReproducesPsychoPyQuestHandlerTest) {
    QuestParams p;
    p.t_guess = 50;
    p.t_guess_sd = 50;
    p.p_threshold = 0.82;
    p.beta = 3.5;
    p.gamma = 0.5;
    p.delta = 0.01;
    p.grain = 0.01;
    p.range = 100;
    p.min_level = 0;
    p.max_level = 100;
    p.first_at_guess = true;
    p.n_trials = 10;
    Quest q(p);
    EXPECT_EQ(q.grid_size(), 10001u);
    const std::vector<double> want = {50,
                                      45.139710407074872,
                                      37.291086503930742,
                                      58.297413127139947,
                                      80.182967131096547,
                                      75.295251409003527,
                                      71.57627192423783,
                                      79.881680484036906,
                                      90.712313302815517,
                                      88.265808957695796};
    const bool answers[] = {true, true, false, false, true, true, false, false, true, true};
    for (std::size_t t = 0; t < want.size(); ++t) {
        const auto prop = q.next();
        ASSERT_TRUE(prop.has_value());
        EXPECT_NEAR(prop->level, want[t], 1e-8 * want[t]) << "trial " << t;
        q.record(binary(answers[t]));
    }
    EXPECT_TRUE(q.finished());
    EXPECT_NEAR(q.mean(), 86.0772169427, 1e-8);
    EXPECT_NEAR(q.mode(), 80.11, 1e-9);
    EXPECT_NEAR(q.quantile(), 86.3849031085, 1e-8);
}

// ---- Long runs and convergence ------------------------------------------------------

void expect_sane(const Quest& q, double lo, double hi) {
    for (double v : q.log_posterior()) ASSERT_FALSE(std::isnan(v));
    EXPECT_EQ(*std::max_element(q.log_posterior().begin(), q.log_posterior().end()), 0.0);
    for (double v : {q.mean(), q.mode(), q.quantile(), q.quantile(0.05), q.quantile(0.95)}) {
        EXPECT_TRUE(std::isfinite(v));
        EXPECT_GE(v, lo);
        EXPECT_LE(v, hi);
    }
    EXPECT_TRUE(std::isfinite(q.sd()));
    EXPECT_GE(q.sd(), 0.0);
}

/// Runs to the end with an observer whose P(Yes) at intensity I is the QUEST Weibull at
/// I - threshold (threshold = the true p_threshold point).
Quest run_observer(const QuestParams& p, double threshold, std::uint64_t seed) {
    Quest q(p);
    Rng rng(seed);
    const double xt = x_threshold_analytic(p);
    while (auto prop = q.next()) q.record(binary(rng.uniform() < weibull(p, prop->level - threshold + xt)));
    return q;
}

TEST(Quest, TenThousandTrialsStayFiniteAndOnThreshold) {
    QuestParams p;
    p.t_guess = -1;
    p.t_guess_sd = 2;
    p.range = 5;
    p.n_trials = 10000;
    const Quest q = run_observer(p, -1.3, 5);
    EXPECT_EQ(q.levels().size(), 10000u);
    expect_sane(q, -3.5, 1.5);
    EXPECT_NEAR(q.mean(), -1.3, 0.02);
    EXPECT_LT(q.sd(), 0.02);
}

TEST(Quest, TenThousandOneSidedAnswersStayFinite) {
    QuestParams p;
    p.t_guess = 0;
    p.t_guess_sd = 1;
    p.range = 4;
    p.n_trials = 10000;
    {  // always correct: the threshold is driven to the bottom of the grid
        Quest q(p);
        while (q.next()) q.record(Response::Yes);
        expect_sane(q, -2, 2);
        EXPECT_LT(q.mean(), -1.9);
    }
    p.gamma = 0;  // yes/no without lapses, always No: log(1 - p) = -10^(beta x) overflows to -inf
    p.delta = 0;
    p.p_threshold = 0.5;
    {
        Quest q(p);
        while (q.next()) q.record(Response::No);
        expect_sane(q, -2, 2);
        EXPECT_GT(q.mean(), 1.9);
    }
}

// 30 simulated observers with threshold -1.3, guess -1 +- 2, 200 trials each: every
// estimate within 3 posterior sd of the truth, the average error a small fraction of a
// log unit (the posterior sd after 200 2AFC trials with beta = 3.5 is ~0.04).
TEST(Quest, ConvergesOnASimulatedObserversThreshold) {
    QuestParams p;
    p.t_guess = -1;
    p.t_guess_sd = 2;
    p.range = 5;
    p.n_trials = 200;
    double mean_error = 0;
    int outside = 0;
    for (std::uint64_t seed = 0; seed < 30; ++seed) {
        const Quest q = run_observer(p, -1.3, 100 + seed);
        mean_error += (q.mean() - (-1.3)) / 30;
        if (std::abs(q.mean() - (-1.3)) > 3 * q.sd()) ++outside;
        EXPECT_LT(q.sd(), 0.1);
    }
    EXPECT_LE(outside, 1);
    EXPECT_NEAR(mean_error, 0.0, 0.02);
}

TEST(Quest, StopsOnTheConfidenceInterval) {
    QuestParams p;
    p.t_guess = -1;
    p.t_guess_sd = 2;
    p.range = 5;
    p.n_trials = 1000;
    p.stop_interval = 0.4;
    const Quest q = run_observer(p, -1.3, 9);
    EXPECT_LT(q.levels().size(), 1000u);
    EXPECT_LT(q.quantile(0.95) - q.quantile(0.05), 0.4);
    // One answer fewer: still too wide (it stopped at the first narrow posterior).
    Quest shorter(p);
    for (std::size_t t = 0; t + 1 < q.levels().size(); ++t) shorter.record(q.history()[t]);
    EXPECT_FALSE(shorter.finished());
    EXPECT_GE(shorter.quantile(0.95) - shorter.quantile(0.05), 0.4);
}

TEST(Quest, ProposalsAreClampedToTheLevelRange) {
    QuestParams p;
    p.t_guess = 0;
    p.t_guess_sd = 2;
    p.min_level = -0.5;
    p.max_level = 0.5;
    p.n_trials = 30;
    Quest q(p);
    while (auto prop = q.next()) {
        EXPECT_GE(prop->level, -0.5);
        EXPECT_LE(prop->level, 0.5);
        q.record(Response::Yes);  // always correct drives the suggestion below -0.5
    }
    EXPECT_EQ(q.levels().back(), -0.5);
}

// ---- Bad parameters -------------------------------------------------------------

using atonlab::test::expect_bad;

TEST(Quest, BadParametersNameTheParameter) {
    const auto with = [](auto change) {
        return [change] {
            QuestParams p;
            p.n_trials = 40;
            change(p);
            Quest q(p);
        };
    };
    expect_bad(with([](QuestParams& p) { p.t_guess = NAN; }), "t_guess");
    expect_bad(with([](QuestParams& p) { p.t_guess_sd = 0; }), "t_guess_sd");
    expect_bad(with([](QuestParams& p) { p.beta = -1; }), "beta");
    expect_bad(with([](QuestParams& p) { p.delta = 1; }), "delta");
    expect_bad(with([](QuestParams& p) { p.gamma = 1; }), "gamma");
    expect_bad(with([](QuestParams& p) { p.gamma = -0.1; }), "gamma");
    expect_bad(with([](QuestParams& p) { p.p_threshold = 0.5; }), "p_threshold");  // = gamma
    expect_bad(with([](QuestParams& p) { p.p_threshold = 0.3; }), "p_threshold");  // below gamma
    expect_bad(with([](QuestParams& p) { p.p_threshold = 1.0; }), "p_threshold");
    expect_bad(with([](QuestParams& p) {
                   p.delta = 0.1;
                   p.p_threshold = 0.97;
               }),
               "p_threshold");  // above 0.95 ceiling
    expect_bad(with([](QuestParams& p) { p.grain = 0; }), "grain");
    expect_bad(with([](QuestParams& p) { p.grain = -0.01; }), "grain");
    expect_bad(with([](QuestParams& p) { p.range = 0; }), "range");
    expect_bad(with([](QuestParams& p) {
                   p.range = 1e6;
                   p.grain = 1e-3;
               }),
               "grain");  // 1e9 grid points
    expect_bad(with([](QuestParams& p) { p.quantile_order = 1.5; }), "quantile_order");
    expect_bad(with([](QuestParams& p) { p.n_trials = 0; }), "n_trials");  // no stop rule
    expect_bad(with([](QuestParams& p) { p.stop_interval = 0; }), "stop_interval");
    expect_bad(with([](QuestParams& p) {
                   p.min_level = 1;
                   p.max_level = 0;
               }),
               "min_level");
    expect_bad([] { atonlab::protocols::parse_quest_method("median"); }, "method");
    QuestParams ok;
    ok.n_trials = 5;
    expect_bad([&] { Quest(ok).record(Response::Right); }, "response");
}

}  // namespace
