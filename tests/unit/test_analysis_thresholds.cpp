// Staircase reversal means and QUEST posterior summaries (analysis/thresholds.h).
#include <atonlab/analysis/thresholds.h>
#include <atonlab/protocols/quest.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

namespace an = atonlab::analysis;
namespace pr = atonlab::protocols;

TEST(AnalysisReversals, MeanAndSdOfTheLastK) {
    //                      0    1    2    3    4    5    6    7    8    9
    const double levels[] = {1.0, 0.8, 0.6, 0.8, 0.6, 0.4, 0.6, 0.4, 0.6, 0.5};
    const bool reversal[] = {false, false, false, true, true, false, true, true, true, false};
    // Reversal levels: 0.8, 0.6, 0.6, 0.4, 0.6.
    const auto all = an::summarize_reversals(levels, reversal, 0);
    EXPECT_EQ(all.n_trials, 10);
    EXPECT_EQ(all.n_reversals, 5);
    EXPECT_EQ(all.n_used, 5);
    EXPECT_NEAR(*all.mean, 3.0 / 5.0, 1e-15);
    EXPECT_TRUE(all.reliable) << all.reason;

    const auto last4 = an::summarize_reversals(levels, reversal, 4);  // 0.6, 0.6, 0.4, 0.6
    EXPECT_EQ(last4.n_used, 4);
    EXPECT_NEAR(*last4.mean, 0.55, 1e-15);
    // Sample SD: deviations 0.05, 0.05, -0.15, 0.05 -> sum of squares 0.03, / 3.
    EXPECT_NEAR(*last4.sd, std::sqrt(0.03 / 3.0), 1e-15);
    EXPECT_NEAR(*last4.sem, std::sqrt(0.03 / 3.0) / 2.0, 1e-15);

    const auto ask8 = an::summarize_reversals(levels, reversal, 8);
    EXPECT_EQ(ask8.n_used, 5);
    EXPECT_FALSE(ask8.reliable);
    EXPECT_NE(ask8.reason.find("only 5 reversals"), std::string::npos) << ask8.reason;

    const bool none[] = {false, false, false};
    const auto no = an::summarize_reversals(std::span(levels, 3), none, 6);
    EXPECT_FALSE(no.mean);
    EXPECT_FALSE(no.sd);
    EXPECT_FALSE(no.reliable);

    const double one_level[] = {0.5};
    const bool one_rev[] = {true};
    const auto one = an::summarize_reversals(one_level, one_rev, 1);
    EXPECT_DOUBLE_EQ(*one.mean, 0.5);
    EXPECT_FALSE(one.sd);
    EXPECT_FALSE(one.reliable);

    const double with_nan[] = {0.5, std::nan(""), 0.7};
    const bool all_rev[] = {true, true, true};
    const auto nan = an::summarize_reversals(with_nan, all_rev, 0);
    EXPECT_EQ(nan.n_used, 2);
    EXPECT_NEAR(*nan.mean, 0.6, 1e-15);
    EXPECT_FALSE(nan.reliable);
}

TEST(AnalysisQuest, GaussianPosteriorOnAGrid) {
    // N(0.3, 0.1^2) on a fine grid: mean 0.3, SD 0.1, mode 0.3, 95% interval
    // 0.3 -+ 1.959964 * 0.1 (to the grid's resolution).
    an::StoredPosterior q;
    for (int i = -2000; i <= 2000; ++i) {
        const double t = 0.3 + i * 0.00025;
        q.grid.push_back(t);
        q.posterior.push_back(std::exp(-0.5 * std::pow((t - 0.3) / 0.1, 2)));
    }
    const auto s = an::summarize_posterior(q, 0.95);
    ASSERT_TRUE(s.from_posterior);
    EXPECT_TRUE(s.reliable) << s.reason;
    EXPECT_NEAR(*s.mean, 0.3, 1e-9);
    EXPECT_NEAR(*s.sd, 0.1, 1e-6);
    EXPECT_NEAR(*s.mode, 0.3, 1e-12);
    ASSERT_TRUE(s.interval);
    EXPECT_NEAR(s.interval->lower, 0.3 - 0.1959964, 5e-4);
    EXPECT_NEAR(s.interval->upper, 0.3 + 0.1959964, 5e-4);
}

TEST(AnalysisQuest, AgreesWithTheProcedureItself) {
    // protocols::Quest computes QuestMean, QuestSd and QuestQuantile on its own
    // (log) posterior; recomputing from its grid and posterior must agree.
    pr::QuestParams p;
    p.t_guess = -1.0;
    p.t_guess_sd = 2.0;
    p.n_trials = 40;
    pr::Quest quest(p);
    for (int i = 0; i < 30; ++i) quest.record(pr::binary(i % 3 != 0));
    an::StoredPosterior q;
    q.grid = quest.grid();
    q.posterior = quest.posterior();
    const auto s = an::summarize_posterior(q, 0.9);
    ASSERT_TRUE(s.mean && s.sd && s.interval);
    EXPECT_NEAR(*s.mean, quest.mean(), 1e-9);
    EXPECT_NEAR(*s.sd, quest.sd(), 1e-9);
    EXPECT_NEAR(*s.mode, quest.mode(), 1e-12);
    EXPECT_NEAR(s.interval->lower, quest.quantile(0.05), 1e-9);
    EXPECT_NEAR(s.interval->upper, quest.quantile(0.95), 1e-9);
}

TEST(AnalysisQuest, FromStoredValues) {
    an::StoredPosterior q;
    q.mean = -0.8;
    q.sd = 0.15;
    q.quantiles = {{0.025, -1.1}, {0.975, -0.5}};
    const auto s = an::summarize_posterior(q, 0.95);
    EXPECT_FALSE(s.from_posterior);
    EXPECT_TRUE(s.reliable) << s.reason;
    EXPECT_EQ(*s.mean, -0.8);
    EXPECT_EQ(s.interval->lower, -1.1);
    EXPECT_EQ(s.interval->upper, -0.5);
    EXPECT_FALSE(s.interval_is_normal_approximation);
    // No matching quantiles: mean -+ z sd, flagged.
    const auto s90 = an::summarize_posterior(q, 0.90);
    ASSERT_TRUE(s90.interval);
    EXPECT_TRUE(s90.interval_is_normal_approximation);
    EXPECT_NEAR(s90.interval->upper, -0.8 + 1.6448536269514722 * 0.15, 1e-12);
    // Nothing stored: absent values, unreliable, no throw.
    const auto empty = an::summarize_posterior({}, 0.95);
    EXPECT_FALSE(empty.mean);
    EXPECT_FALSE(empty.interval);
    EXPECT_FALSE(empty.reliable);
    // A broken grid falls back to the stored values and says so.
    an::StoredPosterior broken = q;
    broken.grid = {0.0, 1.0};
    broken.posterior = {1.0};
    const auto b = an::summarize_posterior(broken, 0.95);
    EXPECT_FALSE(b.from_posterior);
    EXPECT_EQ(*b.mean, -0.8);
    EXPECT_FALSE(b.reliable);
}
