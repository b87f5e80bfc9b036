// Parameter recovery and bootstrap coverage on simulated datasets
// (analysis/psychometric.h; docs/analysis-fits.md "Recovery").
//
// Design (a brightness match analysed as "chose the test", gamma = 0):
//   family      cumulative normal, lambda free in [0, 0.06]
//   truth       PSE alpha = 0.1 log10 units, sigma = 0.2 (beta = 5), lambda = 0.02
//   levels      7 levels, -0.35 .. 0.55 log10 units in steps of 0.15 (PSE +- 2.25 sigma)
//   trials      40 per level (280 per dataset)
//   datasets    300, each with a 999-resample parametric bootstrap (95% percentile intervals)
// Pass: mean estimates within 3 standard errors of the truth (threshold,
// width), and the 95% intervals of threshold and width covering the truth in
// 92%..98% of the datasets (95% +- 3%). Slope and lambda are reported, not held:
// their ML estimates are known to be biased at this size (Wichmann & Hill 2001a).
#include <atonlab/analysis/psychometric.h>
#include <atonlab/protocols/rng.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

namespace an = atonlab::analysis;

namespace {

struct Stats {
    double sum = 0, sum2 = 0;
    int n = 0, covered = 0, with_interval = 0;
    void add(double v) {
        sum += v;
        sum2 += v * v;
        ++n;
    }
    double mean() const { return sum / n; }
    double sd() const { return std::sqrt((sum2 - sum * sum / n) / (n - 1)); }
    double se() const { return sd() / std::sqrt(static_cast<double>(n)); }
    void cover(const std::optional<an::Interval>& iv, double truth) {
        if (!iv) return;
        ++with_interval;
        if (iv->contains(truth)) ++covered;
    }
    double coverage() const { return static_cast<double>(covered) / with_interval; }
};

}  // namespace

TEST(AnalysisRecovery, UnbiasedAndIntervalsCover95Percent) {
    const an::Family family = an::Family::CumulativeNormal;
    const an::PsiParams truth{0.1, 5.0, 0.0, 0.02};
    const double true_threshold = truth.alpha;                                      // F = 0.5
    const double true_width = *an::sigmoid_width(family, truth.alpha, truth.beta);  // 0.658 log10 units
    const double true_slope = an::psi_derivative(family, true_threshold, truth);
    const int n_per_level = 40;
    const int n_datasets = 300;
    std::vector<double> levels;
    for (int i = 0; i < 7; ++i) levels.push_back(-0.35 + 0.15 * i);

    const an::FitOptions options = an::FitOptions::yes_no(family);
    an::ResampleOptions boot;
    boot.n_resamples = 999;
    boot.level = 0.95;
    boot.n_threads = 2;

    Stats threshold, width, slope, lambda;
    int n_fitted = 0, n_gof_below_05 = 0, n_gof = 0;
    for (int d = 0; d < n_datasets; ++d) {
        // The test's own binomial draws (Bernoulli sums), independent of the library's.
        atonlab::protocols::Rng rng(atonlab::protocols::derive_seed(0xA11A1, static_cast<std::uint64_t>(d)));
        std::vector<an::LevelCounts> data;
        for (double x : levels) {
            const double p = an::psi(family, x, truth);
            int k = 0;
            for (int t = 0; t < n_per_level; ++t) k += rng.uniform() < p ? 1 : 0;
            data.push_back({x, n_per_level, k});
        }
        const auto fit = an::fit_psychometric(data, options);
        ASSERT_TRUE(fit.estimate) << "dataset " << d << ": " << fit.reason;
        ++n_fitted;
        const auto& e = *fit.estimate;
        threshold.add(e.threshold);
        width.add(e.width);
        slope.add(e.slope);
        lambda.add(e.params.lambda);

        boot.seed = atonlab::protocols::derive_seed(0xB007, static_cast<std::uint64_t>(d));
        const auto b = an::bootstrap_psychometric(data, fit, boot);
        threshold.cover(b.threshold, true_threshold);
        width.cover(b.width, true_width);
        slope.cover(b.slope, true_slope);
        lambda.cover(b.lambda, truth.lambda);
        if (b.goodness_of_fit.p_value) {
            ++n_gof;
            if (*b.goodness_of_fit.p_value < 0.05) ++n_gof_below_05;
        }
    }

    std::printf("recovery (%d datasets, %d trials each, 999 resamples):\n", n_fitted, 7 * n_per_level);
    std::printf("  threshold: truth %.4f mean %.4f (SE %.4f) coverage %.3f of %d\n", true_threshold, threshold.mean(),
                threshold.se(), threshold.coverage(), threshold.with_interval);
    std::printf("  width:     truth %.4f mean %.4f (SE %.4f) coverage %.3f\n", true_width, width.mean(), width.se(),
                width.coverage());
    std::printf("  slope:     truth %.4f mean %.4f (SE %.4f) coverage %.3f\n", true_slope, slope.mean(), slope.se(),
                slope.coverage());
    std::printf("  lambda:    truth %.4f mean %.4f (SE %.4f) coverage %.3f\n", truth.lambda, lambda.mean(), lambda.se(),
                lambda.coverage());
    std::printf("  deviance GoF: %d of %d Monte-Carlo p < 0.05 (%.3f)\n", n_gof_below_05, n_gof,
                static_cast<double>(n_gof_below_05) / n_gof);

    EXPECT_NEAR(threshold.mean(), true_threshold, 3.0 * threshold.se());
    EXPECT_NEAR(width.mean(), true_width, 3.0 * width.se());
    EXPECT_EQ(threshold.with_interval, n_datasets);
    EXPECT_NEAR(threshold.coverage(), 0.95, 0.03);
    EXPECT_NEAR(width.coverage(), 0.95, 0.03);
    // The model is true, so the Monte-Carlo p is ~uniform: ~5% below 0.05
    // (binomial SD with 300 datasets: 1.3%).
    EXPECT_NEAR(static_cast<double>(n_gof_below_05) / n_gof, 0.05, 0.04);
}
