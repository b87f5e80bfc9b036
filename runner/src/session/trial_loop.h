#pragma once
// The trial loop: each trial shown (on screen or on the virtual display),
// answered, given to the procedure and committed to the study file before the
// next is shown.
#include <cstddef>
#include <optional>

#include "atonlab/present/presenter.h"
#include "atonlab/present/screen_presenter.h"
#include "atonlab/protocols/protocol.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/runner/session/run_options.h"
#include "atonlab/runner/session/session_observer.h"
#include "atonlab/runner/session/stimulus_renderer.h"
#include "atonlab/store/store.h"
#include "session/missed_bound.h"
#include "session/progress.h"
#include "session/session_display.h"

namespace atonlab::runner {

/// What the trial loop works with (all owned by run_session()).
struct SessionParts {
    const RunOptions& options;
    const protocols::Protocol& protocol;
    store::Store& store;
    store::SessionId session;
    StimulusRenderer& renderer;
    SessionObserver& observer;
    SessionDisplay& display;
    present::Presenter& presenter;
    present::ScreenPresenter* screen;  ///< null headless
    Progress& progress;
};

struct TrialLoopResult {
    bool observer_quit = false;  ///< the observer ended the session (the quit key, a script's end)
    std::size_t rows = 0;        ///< the session's stored trials, counted or not
    double snapshot_s = 0.0;     ///< wall-clock s spent on condition snapshots
    double store_s = 0.0;        ///< wall-clock s spent committing trials
    /// The missed presentations of this run; reached(): the run stopped at its bound.
    std::optional<MissedBound> missed;
};

/// Shows the instructions, then runs trials until the schedule finishes, a
/// signal arrives (stop_signals.h), the observer quits or the missed
/// presentations reach their bound (missed_bound.h). first_row: the
/// session's stored trials so far; previous_ended_trial: the next trial gets
/// the inter-trial fixation (resume.h Replayed).
TrialLoopResult run_trials(const SessionParts& parts, protocols::Schedule& schedule, std::size_t first_row,
                           bool previous_ended_trial, bool resumed);

}  // namespace atonlab::runner
