#pragma once
// Facts several procedure kinds share (procedures.h ProcedureType), so that
// each type file states only what is its own.
#include <algorithm>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "atonlab/protocols/procedures.h"

namespace atonlab::protocols::detail {

/// Its min_level and max_level, those given.
template <class Params>
std::vector<double> given_bounds(const Params& p) {
    std::vector<double> out;
    if (p.min_level) out.push_back(*p.min_level);
    if (p.max_level) out.push_back(*p.max_level);
    return out;
}

/// A track's first level `first` and the interleaved tracks' starts ± 3 where
/// min_level or max_level is not given (staircases, QUEST).
template <class Params>
std::pair<double, double> starts_search_range(const Params& p, double first, std::span<const double> track_starts) {
    double lo = first, hi = first;
    for (const double v : track_starts) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    }
    return {p.min_level.value_or(lo - 3.0), p.max_level.value_or(hi + 3.0)};
}

/// A staircase's cap on answers (max_trials), if it has one.
template <class Params>
std::optional<std::size_t> max_trials_cap(const Params& p) {
    if (p.max_trials) return static_cast<std::size_t>(*p.max_trials);
    return std::nullopt;
}

/// The task's guess rate, not one of its own.
inline std::optional<double> task_guess_rate(const ProcedureParams&) {
    return std::nullopt;
}

/// No state for analysis to follow.
inline TrackState no_track_state(const Procedure&) {
    return {};
}

/// A Staircase's (or WeightedStaircase's) reversals.
inline TrackState reversal_state(const Procedure& p) {
    TrackState s;
    if (const auto* stair = dynamic_cast<const Staircase*>(&p)) s.reversal_trials = stair->reversal_trials();
    return s;
}

}  // namespace atonlab::protocols::detail
