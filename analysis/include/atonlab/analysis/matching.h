#pragma once
// Matching statistics: the method of adjustment, brightness enhancement from
// PSEs, and paired comparisons of two conditions across observers.
// All ratios are log10 of intensities (or luminances) in the same unit.
#include <optional>
#include <span>
#include <string>

#include "atonlab/analysis/resample.h"

namespace atonlab::analysis {

/// Adjustment settings summarised as log10(match / test).
struct AdjustmentSummary {
    int n = 0;                                 ///< settings used
    int n_excluded = 0;                        ///< pairs dropped (non-positive or non-finite intensity)
    std::optional<double> mean_log10_ratio;    ///< mean of log10(match/test)
    std::optional<double> median_log10_ratio;  ///< median (midpoint of the middle two for even n)
    std::optional<double> sd_log10_ratio;      ///< sample SD (n - 1)
    std::optional<Interval> mean_ci;           ///< percentile bootstrap over settings
    std::optional<Interval> median_ci;         ///< percentile bootstrap over settings
    bool reliable = false;
    std::string reason;
};

/// match_cd[i], test_cd[i]: the observer's final setting and the test it was
/// matched to, both in the same unit (e.g. cd), > 0. Nonparametric bootstrap
/// (settings resampled with replacement, resample_rng(seed, i)) for the CIs.
/// Fewer than 2 usable settings: no CIs, unreliable. Never throws.
AdjustmentSummary summarize_adjustment(std::span<const double> match_cd, std::span<const double> test_cd,
                                       const ResampleOptions& options = {});
/// The same from log10(match/test) values directly.
AdjustmentSummary summarize_log_ratios(std::span<const double> log10_ratios, const ResampleOptions& options = {});

/// Brightness enhancement of the glare rendering: log10(matched no-glare
/// intensity / glare test intensity). The PSE is the log10 intensity of the
/// no-glare reference that looks as bright as the glare test shown at
/// test_log10; > 0 means the glare version looks brighter than its
/// energy-matched no-glare twin (docs/architecture.md "Physical invariants").
struct Enhancement {
    std::optional<double> log10_enhancement;  ///< pse_log10 - test_log10
    std::optional<double> ratio;              ///< 10^log10_enhancement
    std::optional<Interval> ci;               ///< log10 units, percentile of (PSE* - test_log10)
    bool reliable = false;
    std::string reason;
};

/// pse_log10 and its bootstrap replicates (e.g. PsychometricBootstrap::threshold_samples),
/// log10 of the reference intensity; test_log10: log10 of the glare test
/// intensity, same unit. No samples: no CI (unreliable). Never throws.
Enhancement brightness_enhancement(double pse_log10, std::span<const double> pse_bootstrap_log10, double test_log10,
                                   double level = 0.95);

/// Condition A against condition B within observers.
/// It answers: "is the mean within-observer difference A - B different from
/// zero?", i.e. does the manipulation shift each observer's value, with the
/// between-observer spread of absolute levels removed. It does not say the
/// difference holds for every observer, nor anything about one observer's
/// precision (use that observer's bootstrap for that).
struct PairedComparison {
    int n = 0;                              ///< observers with both values finite
    int n_excluded = 0;                     ///< pairs dropped (a non-finite value)
    std::optional<double> mean_difference;  ///< mean of a_i - b_i
    std::optional<double> sd_difference;    ///< sample SD of a_i - b_i
    std::optional<Interval> ci;             ///< percentile bootstrap over observers, of the mean difference
    std::optional<double> t;                ///< mean / (sd / sqrt(n))
    int dof = 0;                            ///< n - 1
    std::optional<double> p_value;          ///< two-sided, Student's t(n-1) (Boost.Math)
    std::optional<Interval> t_ci;           ///< mean +- t_{(1+level)/2, n-1} sd/sqrt(n)
    bool reliable = false;
    std::string reason;
};

/// a[i], b[i]: observer i's value in conditions A and B (e.g. PSEs, log10 cd).
/// Sizes must match (the shorter length is used otherwise). Fewer than 2
/// observers: no test (unreliable). All differences equal (zero spread): t,
/// p and t_ci absent, unreliable. Never throws.
PairedComparison compare_paired(std::span<const double> a, std::span<const double> b,
                                const ResampleOptions& options = {});

}  // namespace atonlab::analysis
