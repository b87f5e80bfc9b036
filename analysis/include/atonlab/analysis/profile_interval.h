#pragma once
// The profile-likelihood interval of a psychometric fit's threshold (Venzon &
// Moolgavkar 1988; Pawitan 2001, "In All Likelihood", sec. 3.4 and 9.5): the
// thresholds t whose profile log-likelihood
//
//   LL_p(t) = max over beta (and a free lambda) of LL(alpha(t, beta), beta, gamma, lambda)
//
// lies within chi2_1(level) / 2 of the maximum (Wilks 1938). It needs no
// resampling (one small optimisation per threshold tried), which is what the
// simulation report (simulation.h) uses per session by default. It assumes the
// likelihood's asymptotic chi-squared shape, so with few trials its coverage is
// measured, not promised: that is what the simulation report is for.
#include <optional>
#include <span>
#include <string>

#include "atonlab/analysis/psychometric.h"

namespace atonlab::analysis {

struct ProfileInterval {
    std::optional<Interval> ci;  ///< level units (linear for the Weibull)
    /// An end that the profile did not fall below the cut-off within the
    /// search range of alpha (FitOptions' default: the tested range extended
    /// by its own length on each side): that end is the range's limit.
    bool lower_open = false, upper_open = false;
    std::string reason;     ///< why there is no interval
    int n_evaluations = 0;  ///< likelihood evaluations
};

/// The profile-likelihood interval at `level` of the threshold of `fit` (which
/// must come from fit_psychometric(data, ...)); the same threshold definition
/// (F = threshold_proportion), guess rate and lapse range as the fit.
ProfileInterval profile_threshold_interval(std::span<const LevelCounts> data, const PsychometricFit& fit,
                                           double level = 0.95);

}  // namespace atonlab::analysis
