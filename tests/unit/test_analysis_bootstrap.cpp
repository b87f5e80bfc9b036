// Parametric bootstrap: determinism, threads, progress and cancel, the
// percentile rule, goodness of fit (analysis/psychometric.h, resample.h).
#include <atonlab/analysis/psychometric.h>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace an = atonlab::analysis;

namespace {

const std::vector<an::LevelCounts> kData{{-0.35, 40, 2}, {-0.2, 40, 6}, {-0.05, 40, 13}, {0.1, 40, 21},
                                         {0.25, 40, 30}, {0.4, 40, 36}, {0.55, 40, 39}};

bool same(const std::optional<an::Interval>& a, const std::optional<an::Interval>& b) {
    return a.has_value() == b.has_value() && (!a || *a == *b);
}

bool same(const an::PsychometricBootstrap& a, const an::PsychometricBootstrap& b) {
    return same(a.threshold, b.threshold) && same(a.slope, b.slope) && same(a.width, b.width) &&
           same(a.lambda, b.lambda) && a.threshold_samples == b.threshold_samples &&
           a.deviance_samples == b.deviance_samples && a.goodness_of_fit.p_value == b.goodness_of_fit.p_value &&
           a.n_failed == b.n_failed;
}

}  // namespace

TEST(AnalysisBootstrap, SameSeedSameIntervalsWhateverTheThreads) {
    const auto fit = an::fit_psychometric(kData, an::FitOptions::yes_no());
    ASSERT_TRUE(fit.estimate && fit.reliable) << fit.reason;
    an::ResampleOptions o;
    o.n_resamples = 199;
    o.seed = 42;
    const auto a = an::bootstrap_psychometric(kData, fit, o);
    const auto b = an::bootstrap_psychometric(kData, fit, o);
    o.n_threads = 3;
    const auto c = an::bootstrap_psychometric(kData, fit, o);
    ASSERT_TRUE(a.reliable) << a.reason;
    EXPECT_TRUE(same(a, b));
    EXPECT_TRUE(same(a, c));
    EXPECT_EQ(a.n_done, 199);
    EXPECT_EQ(a.threshold_samples.size(), 199u);
    o.seed = 43;
    const auto d = an::bootstrap_psychometric(kData, fit, o);
    EXPECT_NE(a.threshold_samples, d.threshold_samples);
    // The intervals bracket the estimate and are finite.
    for (const auto* iv : {&a.threshold, &a.slope, &a.width, &a.lambda}) {
        ASSERT_TRUE(iv->has_value());
        EXPECT_TRUE(std::isfinite((*iv)->lower) && std::isfinite((*iv)->upper));
        EXPECT_LE((*iv)->lower, (*iv)->upper);
        EXPECT_EQ((*iv)->level, 0.95);
    }
    EXPECT_TRUE(a.threshold->contains(fit.estimate->threshold));
    EXPECT_TRUE(a.width->contains(fit.estimate->width));
}

TEST(AnalysisBootstrap, ProgressAndCancel) {
    const auto fit = an::fit_psychometric(kData, an::FitOptions::yes_no());
    for (int threads : {1, 2}) {
        an::ResampleOptions o;
        o.n_resamples = 600;
        o.n_threads = threads;
        std::vector<int> seen;
        // With threads, the calling thread reports what finished meanwhile, so
        // the counts may jump; the run stops soon after the callback says so.
        o.progress = [&](int done, int total) {
            EXPECT_EQ(total, 600);
            seen.push_back(done);
            return done < 20;  // stop after 20
        };
        const auto b = an::bootstrap_psychometric(kData, fit, o);
        ASSERT_FALSE(seen.empty());
        for (std::size_t i = 1; i < seen.size(); ++i) EXPECT_GT(seen[i], seen[i - 1]);
        EXPECT_TRUE(b.cancelled);
        EXPECT_FALSE(b.reliable);
        EXPECT_GE(b.n_done, 20);
        EXPECT_LT(b.n_done, 600);
        // What was done is the first n_done resamples, identical to an uncancelled run's.
        an::ResampleOptions full;
        full.n_resamples = b.n_done;
        const auto ref = an::bootstrap_psychometric(kData, fit, full);
        EXPECT_EQ(b.threshold_samples, ref.threshold_samples) << threads;
    }
}

TEST(AnalysisBootstrap, PercentileRule) {
    // Hyndman-Fan type 6: with n = 999, p = 0.025 is the 25th value, 0.975 the 975th.
    std::vector<double> v(999);
    for (int i = 0; i < 999; ++i) v[static_cast<std::size_t>(i)] = i + 1.0;  // 1 .. 999
    EXPECT_DOUBLE_EQ(*an::sorted_quantile(v, 0.025), 25.0);
    EXPECT_DOUBLE_EQ(*an::sorted_quantile(v, 0.975), 975.0);
    EXPECT_DOUBLE_EQ(*an::sorted_quantile(v, 0.5), 500.0);
    EXPECT_DOUBLE_EQ(*an::sorted_quantile(v, 0.0), 1.0);
    EXPECT_DOUBLE_EQ(*an::sorted_quantile(v, 1.0), 999.0);
    // Interpolation between order statistics: n = 4, p = 0.5 -> h = 2.5.
    const std::vector<double> w{10, 20, 30, 40};
    EXPECT_DOUBLE_EQ(*an::sorted_quantile(w, 0.5), 25.0);
    EXPECT_FALSE(an::sorted_quantile(std::vector<double>{}, 0.5));
    // Unsorted input, NaN dropped.
    const auto iv = an::percentile_interval({5, 1, std::nan(""), 3, 2, 4}, 0.5);
    ASSERT_TRUE(iv);
    EXPECT_DOUBLE_EQ(iv->lower, *an::sorted_quantile(std::vector<double>{1, 2, 3, 4, 5}, 0.25));
    EXPECT_FALSE(an::percentile_interval({1.0}, 0.95));
}

TEST(AnalysisBootstrap, GoodnessOfFit) {
    const auto fit = an::fit_psychometric(kData, an::FitOptions::yes_no());
    an::ResampleOptions o;
    o.n_resamples = 199;
    const auto b = an::bootstrap_psychometric(kData, fit, o);
    const auto& g = b.goodness_of_fit;
    EXPECT_DOUBLE_EQ(g.deviance, fit.estimate->deviance);
    EXPECT_EQ(g.dof, 7 - 3);
    ASSERT_TRUE(g.p_value && g.p_value_chi2);
    // p = (1 + #{D* >= D}) / (1 + B), recomputed from the returned samples.
    int ge = 0;
    for (double d : b.deviance_samples) ge += d >= g.deviance ? 1 : 0;
    EXPECT_DOUBLE_EQ(*g.p_value, (1.0 + ge) / (1.0 + static_cast<double>(b.deviance_samples.size())));
    EXPECT_GT(*g.p_value, 0.0);
    EXPECT_LE(*g.p_value, 1.0);
    // Data the model cannot fit (non-monotonic) give a small p.
    const std::vector<an::LevelCounts> bad{{-0.35, 40, 2}, {-0.2, 40, 38}, {-0.05, 40, 1}, {0.1, 40, 39},
                                           {0.25, 40, 3},  {0.4, 40, 37},  {0.55, 40, 39}};
    const auto bad_fit = an::fit_psychometric(bad, an::FitOptions::yes_no());
    ASSERT_TRUE(bad_fit.estimate);
    const auto bb = an::bootstrap_psychometric(bad, bad_fit, o);
    ASSERT_TRUE(bb.goodness_of_fit.p_value);
    EXPECT_DOUBLE_EQ(*bb.goodness_of_fit.p_value, 1.0 / 200.0);
    EXPECT_LT(*bb.goodness_of_fit.p_value_chi2, 1e-6);
}
