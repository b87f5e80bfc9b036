#pragma once
// What a session found when it ends: the per-condition estimates, and the
// model observer's true values beside them; printed, or handed to the caller
// (the Python module's run(), RunOptions::on_summary).
#include <optional>
#include <string>
#include <vector>

#include "atonlab/protocols/protocol.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/runner/session/session_observer.h"
#include "atonlab/runner/session/stimulus_renderer.h"

namespace atonlab::runner {

/// One condition's outcome, levels in its procedure's units.
struct ConditionSummary {
    std::string condition;
    std::string method;              ///< how the procedure estimates ("mean of last 4 reversals", ...)
    std::vector<double> tracks;      ///< each track's finite estimate
    std::optional<double> estimate;  ///< their mean; nullopt when no track has one
    std::size_t n_tracks = 0, finished = 0, responses = 0;
    /// With the true values asked for (a model observer): the model's true
    /// PSE (2AFC and adjust at P = 0.5) or its level at the procedure's target
    /// probability, and what it is ("PSE", "level at P = 0.750"); or why none
    /// (true_value_why).
    std::optional<double> true_value;
    std::string true_kind;
    std::string true_value_why;
};

/// Per condition of the protocol, in its order (those with tracks): the mean
/// estimate over its tracks, the method, how many tracks finished; with
/// compute_true, the model observer's true value (true_value.h).
std::vector<ConditionSummary> summarise(const protocols::Protocol& protocol, const protocols::Schedule& schedule,
                                        StimulusRenderer* renderer, const SessionObserver& observer, bool compute_true);

/// The summary on stdout, one line per condition, with the estimate's error
/// against the true value where there is one.
void print_summary(const std::vector<ConditionSummary>& rows);

}  // namespace atonlab::runner
