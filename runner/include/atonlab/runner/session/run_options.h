#pragma once
// The options of `atonlab run`, the session engine's input (run_session.h;
// run_command.h is the command line around it).
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "atonlab/protocols/observer.h"
#include "atonlab/protocols/protocol_schedule.h"

namespace atonlab::runner {

struct ConditionSummary;  // session/summary.h

/// `atonlab run` (docs/running.md). Exit status: 0 completed, 2 bad input, 3 no
/// GL, 4 the study file failed (StoreError), 5 the display's timing was refused,
/// 6 the observer ended the session (quit key, confirmed), 7 the runner stopped it:
/// presentations kept missing their refresh (session/missed_bound.h), 128 + N
/// stopped by signal N.
struct RunOptions {
    std::string protocol;
    /// Non-empty: the protocol's text, read instead of the file's (`atonlab
    /// simulate`'s designs, protocol_variant.h); `protocol` still names the
    /// file, for messages and the folder its scene and conditions files are in.
    std::string protocol_text;
    /// Non-empty: the session is a simulated one; stored as its
    /// sessions.simulation_json (docs/simulate.md).
    std::string simulation_json;
    /// The model observer's parameters instead of the protocol's [observer]
    /// table's (`atonlab simulate --observer` with --render-every-trial).
    std::optional<protocols::ModelObserverParams> model_params;
    std::string db;
    std::string profiles;      ///< --profiles: the display-profile file (default: profile_location.h)
    bool no_profiles = false;  ///< --no-profiles: the study file's calibrations only
    bool model_observer = false;
    std::string observer;  ///< the observer code (--observer); with model_observer, "model" when empty
    std::string script;    ///< scripted answers (--script)
    bool headless = false;
    std::optional<std::int64_t> resume;
    bool resume_last = false;
    std::optional<std::uint64_t> seed;
    std::optional<std::uint64_t> observer_seed;
    bool quiet = false;
    int progress_every = 0;         ///< 0: 25 when stdout is not a terminal (a terminal gets one updating line)
    bool true_pse = true;           ///< model observer: compute the true PSE / threshold for the summary
    std::int64_t db_max_bytes = 0;  ///< > 0: the study file may not grow past this (StoreOptions::max_size_bytes)
    bool allow_undisplayable = false;  ///< run a protocol the displayability check refuses (recorded with the session)
    /// Headless: a GL 4.5 context is already current (the Python module's one
    /// context) and is used instead of a new one.
    bool gl_context_current = false;
    /// Called after each trial is committed with the session's stored trials
    /// and the schedule's bound (the Python module's progress callback and its
    /// Ctrl-C check); it may call request_stop() (session/stop_signals.h).
    std::function<void(std::size_t stored, std::optional<std::size_t> bound)> after_trial;
    /// A custom observer (the Python module's run(observer=callable), docs/python.md
    /// "Your own observer"): when set it answers every trial, shown what the model
    /// observer is shown (each judged light's window of displayed luminance,
    /// session_observer.h shown_for) with the trial's facts. Its trials are stored
    /// with observer kind "custom" and custom_observer_name; `observer` is the code.
    /// An exception it throws ends the session there: that trial is neither
    /// answered nor stored, the committed ones are kept and the session stays
    /// open for --resume. Its answers should depend on what it is shown alone,
    /// so that a resumed session answers as an uninterrupted one would.
    std::function<protocols::Answer(const protocols::ScheduledTrial&, const protocols::Shown&)> custom_observer;
    std::string custom_observer_name;  ///< stored in each trial's state as "observer_name"
    /// Called once the session has ended (completed or stopped by a signal or
    /// the observer) with what it found per condition (session/summary.h), the
    /// model's true values included where `true_pse` and the session completed.
    std::function<void(const std::vector<ConditionSummary>&)> on_summary;

    // On screen (without --headless; docs/running.md "On screen").
    int monitor = 0;                          ///< GLFW's monitor index; 0 is the primary
    std::optional<double> software_vsync_hz;  ///< pace flips by a timer (a display without vblank, e.g. Xvfb)
    bool skip_sync_test = false;              ///< start even when the refresh measurement fails
    double sync_sd_max_ms = 1.0;              ///< the flip intervals' SD must be below this, ms
    double refresh_tolerance = 0.02;          ///< measured vs nominal refresh rate, relative
    std::string font;                         ///< TrueType font (default DejaVu Sans)
    /// Refuse (exit status 5) a screen on which a prepared frame of the
    /// protocol's heaviest condition cannot be shown within one refresh
    /// (session/presentation_margin.h); without it such a screen is warned about.
    bool strict_timing = false;
    bool trace = false;                       ///< print what each screen waits for (tests drive keys from it)

    // Test-only (docs/running.md "Testing").
    int inject_stall_frames = 0;                        ///< stall this many refreshes after a stimulus onset ...
    std::optional<std::int64_t> inject_stall_at_trial;  ///< ... of this trial (the store's trial_index)
    bool inject_stall_every_trial = false;              ///< ... of every trial
    double inject_frame_cost_ms = 0.0;  ///< the margin measurement's frames take this much longer (a sleep), ms
    std::optional<std::int64_t> capture_trial;          ///< capture each frame of this trial as shown ...
    std::string capture_dir;                            ///< ... into this folder
    std::string capture_screen_file;                    ///< ... copying this file (Xvfb -fbdir's screen) instead of
                                                        ///< reading the GL back buffer
};

}  // namespace atonlab::runner
