#pragma once
// The bound on missed presentations (docs/running.md, "Missed frames and
// timeouts"): with `[timing] repeat_missed = true` a trial whose stimulus
// missed a refresh is stored and shown again, which on a machine that cannot
// keep up would go on for ever. A run of `atonlab run` stops (exit status 7)
// at `max_missed_in_a_row` missed presentations in a row, or when its missed
// presentations exceed `max_missed_fraction` of the schedule's bound on
// trials. Both count from the start of this run (a resumed session counts
// afresh: the experimenter was told why it stopped and has acted on it).
#include <cstddef>
#include <optional>
#include <string>

#include "atonlab/protocols/protocol.h"

namespace atonlab::runner {

class MissedBound {
public:
    /// max_trials: the schedule's bound on counted trials (none: only the
    /// consecutive bound applies). period_s: the refresh period the trials are
    /// counted in (measured on screen, nominal headless), s.
    MissedBound(const protocols::Timing& timing, std::optional<std::size_t> max_trials, double period_s);

    /// Counts one stored presentation; `missed`: its stimulus missed its
    /// deadline and it is shown again; `dropped`: the refreshes it lost.
    void add(bool missed, int dropped);
    /// The bound was reached: the run stops before the next trial.
    bool reached() const noexcept { return reason() != nullptr; }
    /// "missed_in_a_row" or "missed_per_session"; null while neither bound is reached.
    const char* reason() const noexcept;
    /// The most missed presentations this run may have (more stops it); none without a schedule bound.
    std::optional<int> per_session_limit() const noexcept { return per_session_; }

    /// What the stop record stores (sessions.stop_json; docs/store.md), JSON
    /// object text; `trials_stored`: the session's stored trials.
    std::string record(std::size_t trials_stored, const std::string& margin_json) const;
    /// One paragraph for the experimenter: what was measured and what to do.
    std::string message(long long session) const;

private:
    bool enabled_;
    int in_a_row_max_;
    std::optional<int> per_session_;
    double period_s_;
    int in_a_row_ = 0;
    int missed_ = 0;
    int presented_ = 0;
    int dropped_ = 0;        ///< refreshes lost at the missed presentations, in all
    int worst_dropped_ = 0;  ///< the most refreshes one missed presentation lost
};

}  // namespace atonlab::runner
