#pragma once
// Thresholds from adaptive procedures, summarised after the fact: the mean of
// a staircase's last reversals, and QUEST's posterior (Watson & Pelli 1983).
// Levels are in the procedure's own units (atonlab's staircases and QUEST run
// on log10 intensities, so the means below are geometric means of intensity).
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "atonlab/analysis/resample.h"

namespace atonlab::analysis {

/// Mean and SD of the levels at a staircase's last k reversals.
struct ReversalSummary {
    int n_trials = 0;            ///< levels given
    int n_reversals = 0;         ///< reversal flags set
    int n_used = 0;              ///< reversals averaged: min(k, n_reversals)
    std::optional<double> mean;  ///< level units; absent without reversals
    std::optional<double> sd;    ///< sample SD (n - 1), level units; absent with fewer than 2
    std::optional<double> sem;   ///< sd / sqrt(n_used)
    bool reliable = false;
    std::string reason;  ///< e.g. fewer reversals than asked; empty when reliable
};

/// levels[i]: the level of trial i; reversal[i]: trial i caused a reversal (its
/// level is the reversal level, PsychoPy's convention, see protocols/staircase.h).
/// Averages the levels of the last `last_k` reversals (all reversals when
/// last_k <= 0; Levitt 1971 recommends an even number so that up- and
/// down-turns balance). Sizes must match (the shorter length is used otherwise).
/// Non-finite levels at reversals are skipped and make the summary unreliable.
ReversalSummary summarize_reversals(std::span<const double> levels, std::span<const bool> reversal, int last_k);

/// What is known about a finished QUEST, as stored by the procedure.
struct StoredPosterior {
    std::optional<double> mean;  ///< posterior mean (QuestMean), log10 units
    std::optional<double> sd;    ///< posterior SD (QuestSd), log10 units
    /// Stored quantiles: (order, value), e.g. {0.05, t05}, {0.95, t95}.
    std::vector<std::pair<double, double>> quantiles;
    /// The posterior on its grid (same size, grid ascending); when given,
    /// mean, SD, mode and quantiles are recomputed from it and the fields
    /// above are ignored. Need not be normalised; entries must be >= 0.
    std::vector<double> grid;
    std::vector<double> posterior;
};

struct PosteriorSummary {
    std::optional<double> mean;                     ///< log10 units
    std::optional<double> sd;                       ///< log10 units
    std::optional<double> mode;                     ///< from the posterior grid only
    std::optional<Interval> interval;               ///< at the requested level (see summarize_posterior)
    bool from_posterior = false;                    ///< recomputed from the grid
    bool interval_is_normal_approximation = false;  ///< mean +- z sd, no quantiles available
    bool reliable = false;
    std::string reason;
};

/// QUEST's estimate: from the posterior grid when given (mean, SD, mode, and
/// the credible interval by linear interpolation of the cumulative posterior,
/// as Psychtoolbox's QuestQuantile), else from the stored values. The interval
/// at `level` comes from the grid, else from stored quantiles of orders
/// (1 -+ level)/2 (within 1e-9), else as mean -+ z sd (normal approximation,
/// flagged). Never throws; absent values where nothing can be said.
PosteriorSummary summarize_posterior(const StoredPosterior& q, double level = 0.95);

}  // namespace atonlab::analysis
