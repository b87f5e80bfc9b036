// `atonlab run PROTOCOL.toml --db STUDY.db (--observer ID | --headless (--model-observer | --script FILE))
//      [--resume SESSION_ID | --resume-last] [--seed N] [--observer-seed N] [--quiet] [on-screen options]`
// A protocol's session, full screen with a person (or an observer) or headless,
// each trial committed to the study file before the next is shown
// (docs/running.md). The engine is run_session.cpp; this file is the command
// line and the exit statuses of a study-file failure (4) and of a display whose
// timing is refused (5: the refresh measurement, or --strict-timing's margin).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <string>

#include "atonlab/present/screen_presenter.h"
#include "atonlab/protocols/protocol.h"
#include "atonlab/runner/run_command.h"
#include "atonlab/runner/session/run_session.h"
#include "atonlab/store/error.h"

namespace atonlab::runner {

namespace {

/// A finite number: CLI::Range compares with < and >, so "nan" passes it.
const CLI::Validator kFinite(
    [](std::string& text) {
        double v = 0.0;
        if (CLI::detail::lexical_cast(text, v) && !std::isfinite(v)) return std::string("must be a finite number");
        return std::string();
    },
    "FINITE");

}  // namespace

void add_run_command(CLI::App& app, RunOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "run",
        "Run a protocol's session, full screen for a person (--observer ID) or headless with a model or scripted "
        "observer, logging every trial to a study file");
    cmd->footer(
        "Exit status (docs/running.md): 0 completed; 2 bad input; 3 no OpenGL 4.5 context or no window; 4 the study "
        "file failed; 5 the display's timing was refused (the refresh measurement, or --strict-timing's presentation "
        "margin); 6 the observer ended the session; 7 the runner stopped it: presentations kept missing their refresh "
        "([timing] max_missed_in_a_row, max_missed_fraction; continue with --resume-last); 128 + N stopped by signal N.");
    cmd->add_option("protocol", o.protocol, "Protocol file (TOML; see docs/protocol-file.md)")->required();
    cmd->add_option("--db", o.db, "Study file (SQLite; created if absent; see docs/store.md)")->required();
    auto* profiles = cmd->add_option("--profiles", o.profiles,
                                     "The lab's display-profile file to take the display's calibration from (default: "
                                     "$ATONLAB_PROFILES, else $XDG_DATA_HOME/atonlab/profiles.sqlite if it exists)");
    auto* no_profiles =
        cmd->add_flag("--no-profiles", o.no_profiles, "Use only the calibrations the study file holds itself");
    profiles->excludes(no_profiles);
    auto* model =
        cmd->add_flag("--model-observer", o.model_observer, "Answer with the model observer (observer code \"model\")");
    auto* script = cmd->add_option("--script", o.script,
                                   "Answer from a file, one answer per line (docs/protocol-file.md, Observers)");
    auto* observer = cmd->add_option("--observer", o.observer,
                                     "Observer code (1-32 of A-Z a-z 0-9 _ -): the person at the screen, or with "
                                     "--script the code stored (default \"script\")");
    model->excludes(script);
    model->excludes(observer);
    cmd->add_flag("--headless", o.headless,
                  "Render off-screen (EGL) on a virtual display; needs --model-observer or --script");
    auto* resume = cmd->add_option("--resume", o.resume, "Continue this session (its id in the study file)");
    auto* last = cmd->add_flag("--resume-last", o.resume_last,
                               "Continue the latest unfinished session of this protocol and observer");
    resume->excludes(last);
    cmd->add_option("--seed", o.seed, "The session's random seed (default: the protocol's)");
    cmd->add_option("--observer-seed", o.observer_seed,
                    "The model observer's seed (default: derived from the session's seed)");
    cmd->add_flag("--quiet", o.quiet, "Print nothing but errors");
    cmd->add_option("--progress-every", o.progress_every,
                    "Without a terminal: a progress line every N trials (default 25)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--db-max-bytes", o.db_max_bytes,
                    "Let the study file grow to at most this many bytes; beyond, the run stops as on a full disk "
                    "(default 0: no limit)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_flag("--allow-undisplayable", o.allow_undisplayable,
                  "Run even when a condition cannot produce a match on this display (docs/running.md, "
                  "\"Displayability\"); recorded with the session");
    cmd->add_flag_callback(
        "--no-true-pse", [&o] { o.true_pse = false; },
        "Model observer: skip computing its true PSE / threshold for the summary");

    // On screen (docs/running.md, "On screen" and "Timing").
    const char* screen = "On screen";
    cmd->add_option("--monitor", o.monitor,
                    "Full screen on this monitor (GLFW's order; 0, the default, is the primary)")
        ->check(CLI::NonNegativeNumber)
        ->group(screen);
    cmd->add_option("--software-vsync", o.software_vsync_hz,
                    "A display with no vertical blank (Xvfb, some virtual machines): pace flips with a timer at this "
                    "rate, Hz. For testing only")
        ->check(kFinite & CLI::Range(1.0, 1000.0))
        ->group(screen);
    cmd->add_flag("--skip-sync-test", o.skip_sync_test,
                  "Start even when the refresh measurement fails (reported, not enforced). For testing only")
        ->group(screen);
    cmd->add_option("--sync-sd-max-ms", o.sync_sd_max_ms,
                    "The start-up measurement's flip intervals must have an SD below this, ms (default 1)")
        ->check(kFinite & CLI::Range(0.001, 100.0))
        ->group(screen);
    cmd->add_option("--refresh-tolerance", o.refresh_tolerance,
                    "The measured refresh rate may differ from the nominal by this fraction (default 0.02)")
        ->check(kFinite & CLI::Range(0.0001, 1.0))
        ->group(screen);
    cmd->add_option("--font", o.font, "TrueType font for the screens (default DejaVu Sans, fonts-dejavu-core)")
        ->group(screen);
    cmd->add_flag("--strict-timing", o.strict_timing,
                  "Refuse to start (exit status 5) when a prepared frame of the protocol's heaviest condition cannot "
                  "be shown within one refresh (docs/running.md, \"Presentation margin\"); without it, warned about")
        ->group(screen);
    cmd->add_flag("--trace", o.trace, "Print what each screen waits for (\"trace: ...\" lines on stdout)")
        ->group(screen);

    // Test-only hooks (docs/running.md, "Testing").
    const char* testing = "Testing (not for studies)";
    cmd->add_option("--inject-stall-frames", o.inject_stall_frames,
                    "Stall this many refreshes after the stimulus onset of the trial --inject-stall-at-trial names")
        ->check(CLI::Range(1, 600))
        ->group(testing);
    auto* stall_at = cmd->add_option("--inject-stall-at-trial", o.inject_stall_at_trial,
                                     "The trial (the study file's trial_index, from 0) whose stimulus stalls")
                         ->check(CLI::NonNegativeNumber)
                         ->group(testing);
    cmd->add_flag("--inject-stall-every-trial", o.inject_stall_every_trial,
                  "Stall the stimulus of every trial by --inject-stall-frames (headless too)")
        ->excludes(stall_at)
        ->group(testing);
    cmd->add_option("--inject-frame-cost-ms", o.inject_frame_cost_ms,
                    "On screen: the presentation margin's timed frames each take this much longer (a sleep), ms")
        ->check(kFinite & CLI::Range(0.0, 1000.0))
        ->group(testing);
    cmd->add_option("--capture-trial", o.capture_trial,
                    "Capture every frame of this trial (trial_index) as it is shown, into --capture-dir (PNG: the drawn back buffer)")
        ->check(CLI::NonNegativeNumber)
        ->group(testing);
    cmd->add_option("--capture-dir", o.capture_dir, "Folder for --capture-trial's images")->group(testing);
    cmd->add_option("--capture-screen-file", o.capture_screen_file,
                    "Capture by copying this file (the screen Xvfb -fbdir maps) after a round trip to the X server, "
                    "instead of reading the GL back buffer")
        ->group(testing);
}

int run_run(const RunOptions& o) {
    try {
        return run_session(o);
    } catch (const store::StoreError& e) {
        // The study file failed (newer schema, write-protected, disk full, I/O
        // error, ...): what is stored stays as it was; one sentence, status 4.
        std::fprintf(stderr, "atonlab: %s\n", e.what());
        return 4;
    } catch (const present::DisplayTimingRefused& e) {
        // The refresh measurement failed before any session began: nothing stored.
        std::fprintf(stderr, "atonlab: %s\n", e.what());
        return 5;
    }
}

}  // namespace atonlab::runner
