// Method of adjustment, brightness enhancement, paired comparisons
// (analysis/matching.h).
#include <atonlab/analysis/matching.h>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace an = atonlab::analysis;

TEST(AnalysisAdjustment, MeanMedianOfLogRatios) {
    // log10(match/test): 0.1, 0.2, 0.3, 0.5 (and a setting with match 0, excluded).
    const std::vector<double> test{10.0, 10.0, 10.0, 10.0, 10.0};
    std::vector<double> match;
    for (double r : {0.1, 0.2, 0.3, 0.5}) match.push_back(10.0 * std::pow(10.0, r));
    match.push_back(0.0);
    an::ResampleOptions o;
    o.n_resamples = 999;
    o.seed = 7;
    const auto s = an::summarize_adjustment(match, test, o);
    EXPECT_EQ(s.n, 4);
    EXPECT_EQ(s.n_excluded, 1);
    EXPECT_FALSE(s.reliable);  // an exclusion is reported
    EXPECT_NEAR(*s.mean_log10_ratio, 0.275, 1e-12);
    EXPECT_NEAR(*s.median_log10_ratio, 0.25, 1e-12);
    // SD: deviations -0.175 -0.075 0.025 0.225 -> SS 0.0875, / 3.
    EXPECT_NEAR(*s.sd_log10_ratio, std::sqrt(0.0875 / 3.0), 1e-12);
    ASSERT_TRUE(s.mean_ci && s.median_ci);
    // Bootstrap means of 4 values lie within [min, max]; the CI brackets the mean.
    EXPECT_GE(s.mean_ci->lower, 0.1 - 1e-12);
    EXPECT_LE(s.mean_ci->upper, 0.5 + 1e-12);
    EXPECT_TRUE(s.mean_ci->contains(0.275));
    // Same seed, same CI; threads do not matter.
    o.n_threads = 2;
    const auto s2 = an::summarize_adjustment(match, test, o);
    EXPECT_EQ(*s.mean_ci, *s2.mean_ci);
    EXPECT_EQ(*s.median_ci, *s2.median_ci);

    const double ratios[] = {0.2, 0.2, 0.2};
    const auto clean = an::summarize_log_ratios(ratios, o);
    EXPECT_TRUE(clean.reliable) << clean.reason;
    EXPECT_DOUBLE_EQ(clean.mean_ci->lower, 0.2);
    EXPECT_DOUBLE_EQ(clean.mean_ci->upper, 0.2);

    const auto none = an::summarize_log_ratios({}, o);
    EXPECT_FALSE(none.mean_log10_ratio);
    EXPECT_FALSE(none.reliable);
    const double single[] = {0.3};
    const auto one = an::summarize_log_ratios(single, o);
    EXPECT_EQ(*one.mean_log10_ratio, 0.3);
    EXPECT_FALSE(one.mean_ci);
    EXPECT_FALSE(one.reliable);
}

TEST(AnalysisAdjustment, BootstrapCoverageOfTheMean) {
    // Nonparametric bootstrap of a mean of 30 normal values: the percentile CI
    // should cover the true mean ~95% of the time (checked loosely: 200 sets).
    int covered = 0;
    const int sets = 200;
    for (int s = 0; s < sets; ++s) {
        atonlab::protocols::Rng rng(atonlab::protocols::derive_seed(11, static_cast<std::uint64_t>(s)));
        std::vector<double> v;
        for (int i = 0; i < 30; ++i) {
            // Sum of 12 uniforms - 6: mean 0, SD 1 (close to normal).
            double z = -6.0;
            for (int k = 0; k < 12; ++k) z += rng.uniform();
            v.push_back(0.2 + 0.1 * z);
        }
        an::ResampleOptions o;
        o.n_resamples = 499;
        o.seed = static_cast<std::uint64_t>(s);
        const auto r = an::summarize_log_ratios(v, o);
        if (r.mean_ci && r.mean_ci->contains(0.2)) ++covered;
    }
    EXPECT_NEAR(static_cast<double>(covered) / sets, 0.95, 0.05);
}

TEST(AnalysisEnhancement, PseMinusTestWithShiftedInterval) {
    const std::vector<double> boot{1.9, 2.0, 2.1, 2.2, 2.3};
    const auto e = an::brightness_enhancement(2.1, boot, 2.0, 0.5);
    EXPECT_NEAR(*e.log10_enhancement, 0.1, 1e-12);
    EXPECT_NEAR(*e.ratio, std::pow(10.0, 0.1), 1e-12);
    ASSERT_TRUE(e.ci);
    const auto iv = an::percentile_interval(boot, 0.5);
    EXPECT_NEAR(e.ci->lower, iv->lower - 2.0, 1e-12);
    EXPECT_NEAR(e.ci->upper, iv->upper - 2.0, 1e-12);
    EXPECT_TRUE(e.reliable);
    const auto no_boot = an::brightness_enhancement(2.1, {}, 2.0);
    EXPECT_TRUE(no_boot.log10_enhancement);
    EXPECT_FALSE(no_boot.ci);
    EXPECT_FALSE(no_boot.reliable);
    const auto bad = an::brightness_enhancement(std::nan(""), boot, 2.0);
    EXPECT_FALSE(bad.log10_enhancement);
}

TEST(AnalysisPaired, StudentsSleepDataAsPublished) {
    // Student (1908) / Cushny & Peebles, R's `sleep` data: extra hours of sleep
    // under two drugs, 10 patients. R 4.x, t.test(x1, x2, paired = TRUE):
    // t = -4.0621, df = 9, p-value = 0.002833, 95% CI -2.4598858 -0.7001142,
    // mean difference -1.58.
    const double drug1[] = {0.7, -1.6, -0.2, -1.2, -0.1, 3.4, 3.7, 0.8, 0.0, 2.0};
    const double drug2[] = {1.9, 0.8, 1.1, 0.1, -0.1, 4.4, 5.5, 1.6, 4.6, 3.4};
    an::ResampleOptions o;
    o.n_resamples = 1999;
    const auto c = an::compare_paired(drug1, drug2, o);
    EXPECT_TRUE(c.reliable) << c.reason;
    EXPECT_EQ(c.n, 10);
    EXPECT_EQ(c.dof, 9);
    EXPECT_NEAR(*c.mean_difference, -1.58, 1e-12);
    EXPECT_NEAR(*c.t, -4.0621, 5e-5);
    EXPECT_NEAR(*c.p_value, 0.002833, 5e-7);
    EXPECT_NEAR(c.t_ci->lower, -2.4598858, 5e-7);
    EXPECT_NEAR(c.t_ci->upper, -0.7001142, 5e-7);
    ASSERT_TRUE(c.ci);
    EXPECT_LT(c.ci->upper, 0.0);  // the bootstrap interval excludes 0 too
    EXPECT_TRUE(c.ci->contains(-1.58));
}

TEST(AnalysisPaired, DegenerateInputs) {
    const double a[] = {1.0, 2.0, 3.0};
    const double b[] = {0.5, 1.5, 2.5};  // all differences 0.5
    const auto same = an::compare_paired(a, b);
    EXPECT_NEAR(*same.mean_difference, 0.5, 1e-15);
    EXPECT_FALSE(same.t);
    EXPECT_FALSE(same.p_value);
    EXPECT_FALSE(same.reliable);
    const double one_a[] = {1.0};
    const double one_b[] = {0.0};
    const auto one = an::compare_paired(one_a, one_b);
    EXPECT_FALSE(one.sd_difference);
    EXPECT_FALSE(one.reliable);
    const double nan_a[] = {1.0, std::nan(""), 2.0, 4.0};
    const double nan_b[] = {0.0, 1.0, 1.5, 2.0};
    const auto n = an::compare_paired(nan_a, nan_b);
    EXPECT_EQ(n.n, 3);
    EXPECT_EQ(n.n_excluded, 1);
    EXPECT_FALSE(n.reliable);
    EXPECT_TRUE(n.p_value);
    const auto empty = an::compare_paired({}, {});
    EXPECT_FALSE(empty.mean_difference);
}
