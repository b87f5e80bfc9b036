// The engine of `atonlab run` (run_session.h; docs/running.md): the driver
// over the parts in session/.
#include "atonlab/runner/session/run_session.h"

#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/present/presenter.h"
#include "atonlab/present/screen_presenter.h"
#include "atonlab/present/text.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/protocols/simulated_observer.h"
#include "atonlab/runner/displayability.h"
#include "atonlab/runner/session/session_inputs.h"
#include "atonlab/runner/session/stop_signals.h"
#include "atonlab/runner/session/summary.h"
#include "atonlab/stimuli/gl/context.h"
#include "atonlab/store/store.h"
#include "calibrate/calibration_policy.h"
#include "calibrate/profile_location.h"
#include "session/display_record.h"
#include "session/presentation_margin.h"
#include "session/progress.h"
#include "session/resume.h"
#include "session/session_display.h"
#include "session/trial_loop.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace s = atonlab::stimuli;
namespace st = atonlab::store;

namespace {

/// What this display will show of every condition (displayability.h), printed;
/// false when a level range cannot produce a match and the run is refused
/// (nothing written; --allow-undisplayable runs anyway).
bool displayability_allows(const Displayability& displayability, const RunOptions& o) {
    if (!o.quiet) {
        std::printf("%s", displayability_table(displayability).c_str());
        std::fflush(stdout);
    }
    if (displayability.displayable()) return true;
    std::fprintf(stderr, "atonlab: %s\n", displayability_refusal(displayability, o.protocol).c_str());
    if (!o.allow_undisplayable) {
        std::fprintf(stderr,
                     "atonlab: nothing was written; change the protocol as said, try it with `atonlab check %s`, "
                     "or run anyway with --allow-undisplayable (recorded with the session).\n",
                     o.protocol.c_str());
        return false;
    }
    std::fprintf(stderr, "atonlab: warning: running anyway (--allow-undisplayable; recorded with the session)\n");
    return true;
}

/// The model observer's parameters: the protocol's [observer] table. Its
/// departures from the stationary model (bias, overdispersion, learning,
/// fluctuation) are `atonlab simulate`'s; a run with the model observer
/// refuses them rather than answering as another observer.
p::ModelObserverParams model_observer_params(const RunOptions& o, const p::Protocol& protocol) {
    const p::SimulatedObserverParams params = p::observer_params(protocol);
    if (o.model_observer)
        for (const p::ObserverSetting& s : protocol.observer)
            if (p::find_observer_key(s.key)->departure)
                throw InputError(s.where, fmt::format("the observer's {} is a simulated observer's (atonlab "
                                                      "simulate); atonlab run's model observer is the stationary "
                                                      "model: leave it out to run this protocol.",
                                                      s.key));
    return o.model_params.value_or(params.model);
}

/// A model observer inside an adjustment match when the log stopped: show it
/// that match's steps again (they are in the frame cache after the first), so
/// that it continues from the same state.
void reshow_open_match(SessionObserver& observer, StimulusRenderer& renderer, const Replayed& replayed,
                       const std::vector<st::TrialRecord>& logged) {
    if (!observer.model()) return;
    for (const auto& [step, row] : replayed.open_match) {
        const p::Answer a = observer.answer(step, &renderer);
        const std::string_view logged_word = logged[row].response;
        if (p::response_word(a.response) != logged_word)
            std::fprintf(stderr,
                         "atonlab: warning: replaying step %zu of the open adjustment, the model observer "
                         "answered \"%s\" where the log has \"%s\" (has the scene file changed?)\n",
                         step.step, std::string(p::response_word(a.response)).c_str(),
                         std::string(logged_word).c_str());
    }
}

/// The measured screen, on stdout.
void print_screen(const RunOptions& o, const present::ScreenPresenter& screen, const SessionDisplay& display) {
    const present::RefreshEstimate& r = screen.refresh();
    std::printf(
        "screen: monitor %d \"%s\", %d×%d, %d bits per channel, mode %s; measured %.4f ms ± %.4f ms "
        "(SD) over %d flips (%d rejected) = %.3f Hz\n  flips timed by %s\n  %s\n",
        o.monitor, screen.monitor_name().c_str(), screen.width_px(), screen.height_px(), screen.framebuffer_bits(),
        screen.mode_hz() > 0 ? fmt::format("{} Hz", screen.mode_hz()).c_str() : "without a rate", r.period_s * 1e3,
        r.sd_s * 1e3, r.valid, r.rejected, r.hz(), screen.timing_method().c_str(), display.luminance_note().c_str());
    std::fflush(stdout);
}

/// How the session ended, its timings and the per-condition summary, on stdout.
void print_session_end(const RunOptions& o, const SessionParts& s, const p::Schedule& schedule,
                       const TrialLoopResult& loop, bool completed, int stop,
                       const std::vector<ConditionSummary>& summary, bool with_true, std::size_t true_frames,
                       double true_s) {
    const std::size_t total = schedule.history().size();
    const bool missed_stop = loop.missed && loop.missed->reached();
    std::printf("%s after %zu trials (%zu in this run, %s)\n",
                completed            ? "completed"
                : loop.observer_quit ? "ended by the observer"
                : missed_stop        ? "stopped: presentations kept missing their refresh"
                                     : fmt::format("stopped by signal {}", stop).c_str(),
                total, s.progress.done_here(), clock_text(s.progress.seconds()).c_str());
    if (loop.rows != total)
        std::printf("  %zu trials stored in all: %zu shown again (missed refreshes or timeouts)\n", loop.rows,
                    loop.rows - total);
    std::printf(
        "  %zu frames rendered for %zu shown (%.1f s, snapshots included); snapshots %.1f s; "
        "study file %.1f s\n",
        s.renderer.frames_rendered(), s.renderer.frames_requested(), s.renderer.render_seconds(), loop.snapshot_s,
        loop.store_s);
    print_summary(summary);
    if (with_true)
        std::printf("  (the true values took %zu more frames, %.1f s; --no-true-pse skips them)\n", true_frames,
                    true_s);
    std::printf("\nstudy file: %s, session %lld (%s)%s\n", o.db.c_str(), static_cast<long long>(s.session.value),
                completed ? "completed" : "quit",
                completed ? "" : fmt::format("; continue with --resume {}", s.session.value).c_str());
}

/// The presentation margin (session/presentation_margin.h), printed (with a
/// warning under 50 %) and returned as stored; under --strict-timing a frame
/// that cannot be shown within the refresh refuses the session (exit 5).
std::string measured_margin(const RunOptions& o, present::ScreenPresenter& screen, StimulusRenderer& renderer,
                            const p::Protocol& protocol, const Displayability& displayability, int bits) {
    const PresentationMargin m =
        measure_margin(screen, renderer, protocol, displayability, bits, 30, o.inject_frame_cost_ms * 1e-3);
    if (!o.quiet) {
        std::printf("%s\n", margin_text(m).c_str());
        std::fflush(stdout);
    }
    if (m.margin() < 0.0 && o.strict_timing)
        throw present::DisplayTimingRefused(fmt::format(
            "a prepared frame of condition \"{}\" takes {:.2f} ms to show (median of {}), longer than the {:.2f} ms "
            "refresh: under --strict-timing the session is not started (nothing was written); close other programs, "
            "check that the GPU driver is in use, or run without --strict-timing (late trials are then marked).",
            m.condition, m.show_s * 1e3, m.times, m.period_s * 1e3));
    if (m.margin() < kMarginWarning)
        std::fprintf(stderr,
                     "atonlab: warning: presentation margin %.0f %% (under %.0f %%): showing a frame takes %.2f ms of "
                     "the %.2f ms refresh, so a busy machine will miss refreshes; close other programs%s.\n",
                     m.margin() * 100.0, kMarginWarning * 100.0, m.show_s * 1e3, m.period_s * 1e3,
                     o.strict_timing ? "" : " (--strict-timing refuses a screen where a frame cannot be shown in time)");
    return margin_json(m);
}

/// Opens the study file for writing (every check has passed) and begins the
/// session, or reopens the resumed one.
st::SessionId begin_or_reopen(st::Store& store, const RunOptions& o, const SessionToRun& run,
                              const SessionInputs& in, const std::string& code, const Displayability& displayability,
                              const SessionCalibration& calibration, const std::string& margin) {
    if (run.resumed) {
        const st::ResumePoint rp = store.resume_session(run.session);
        if (static_cast<std::size_t>(rp.next_trial_index) != run.logged.size())
            throw st::StoreError(st::StoreErrc::busy, o.db,
                                 fmt::format("{}: session {} gained trials while it was being resumed; another "
                                             "process is running it.",
                                             o.db, run.session.value));
        return run.session;
    }
    st::SessionStart start;
    start.observer_code = code;
    start.protocol_text = in.protocol_text;
    start.protocol_name = std::filesystem::path(o.protocol).filename().string();
    start.scene_text = in.scene_text;
    start.scene_name = in.protocol.scene.filename().string();
    start.seed = run.seed;
    start.displayability_json = displayability_json(displayability, o.allow_undisplayable, margin);
    start.simulation_json = o.simulation_json;
    start.calibration = calibration.calibration     ? *calibration.calibration
                        : calibration.from_profiles ? copy_into_study(store, *calibration.from_profiles)
                                                    : record_display(store, in.display_scene, in.protocol.scene);
    return store.begin_session(start);
}

}  // namespace

int run_session(const RunOptions& o) {
    // Installed first: a signal during the setup ends the session before its first trial.
    StopSignals signals;
    const bool person = !o.model_observer && o.script.empty() && !o.custom_observer;
    const std::string code = checked_observer_code(o);
    // --- Load and validate everything before the first trial.
    SessionInputs in = load_session_inputs(o);
    const p::Protocol& protocol = in.protocol;

    // --- The study file, read-only: checked (a study, undamaged, not newer:
    // exit 4) and read for the session to continue and the display's
    // calibration. Nothing is created or written until every check that can
    // refuse the session has passed (docs/running.md, "Before the session").
    st::StoreOptions store_options;
    store_options.max_size_bytes = o.db_max_bytes;
    std::optional<st::Store> existing = read_existing_study(o.db, store_options);
    const SessionToRun run = session_to_run(o, existing, protocol, in.protocol_sha, in.scene_sha, code);
    SessionObserver observer(o, observer_seed_to_run(o, run), std::move(in.script), model_observer_params(o, protocol));
    Replayed replayed = replay_logged(protocol, run, o.db, observer);

    // --- The display's calibration (calibration_policy.h): warnings before the
    // session; a measured calibration's model encodes every frame.
    // The lab's display-profile file (profile_location.h); a resumed session keeps its own calibration.
    const std::optional<st::Profiles> profiles = open_profiles_for_run(o.profiles, o.no_profiles || run.resumed);
    const SessionCalibration calibration = session_calibration(
        existing ? &*existing : nullptr, protocol.display,
        run.resumed ? existing->session(run.session).calibration : std::nullopt, utc_today(), o.db,
        profiles ? RunProfiles{&profiles->displays(), profiles->path().string()} : RunProfiles{});
    print_calibration_warnings(calibration, o.quiet);
    if (calibration.display) apply_display_model(in.display_scene, *calibration.display);

    // --- GL (and the screen, measured) before the session: a machine without GL,
    // or a display whose timing is refused, leaves no empty session behind.
    std::optional<present::Font> font;
    if (!o.headless)
        font = present::Font::load(o.font.empty() ? std::filesystem::path(present::kDefaultFontFile)
                                                  : std::filesystem::path(o.font));
    std::unique_ptr<gl::Context> context;
    std::unique_ptr<present::Presenter> presenter;
    present::ScreenPresenter* screen = nullptr;
    if (o.headless) {
        if (!o.gl_context_current) context = gl::create_headless_context();
        presenter = std::make_unique<present::VirtualPresenter>(protocol.timing.refresh_hz.value_or(60.0),
                                                                protocol.display.width_px, protocol.display.height_px);
    } else {
        presenter = open_screen(o, protocol, in.display_scene, screen);
    }
    StimulusRenderer renderer(*in.scene, observer.params().window_radius_deg,
                              protocol.timing.stimulus_s);
    if (calibration.display) renderer.use_display_model(*calibration.display);
    // A level range that cannot produce a match is refused, before anything is written.
    const Displayability displayability = check_displayability(renderer, protocol);
    if (!displayability_allows(displayability, o)) return 2;
    // On screen: how much of a refresh showing a frame leaves (may refuse, exit 5).
    const std::string margin_record = screen ? measured_margin(o, *screen, renderer, protocol, displayability,
                                                             in.display_scene.output.encode.bits)
                                           : std::string();

    // --- Every check has passed: open the study file for writing (creating it
    // if it does not exist), then begin or reopen the session.
    existing.reset();
    st::Store store = st::Store::create_or_open(o.db, store_options);
    const st::SessionId session =
        begin_or_reopen(store, o, run, in, code, displayability, calibration, margin_record);
    // From here on a StoreError names the session to continue.
    try {
        reshow_open_match(observer, renderer, replayed, run.logged);
        p::Schedule& schedule = replayed.schedule;
        Progress progress(o.quiet, o.progress_every, schedule.max_trials());
        if (!o.quiet) {
            std::printf("atonlab run: %s, observer \"%s\", seed %llu: session %lld in %s (%s)\n", protocol.name.c_str(),
                        code.c_str(), static_cast<unsigned long long>(run.seed),
                        static_cast<long long>(session.value), o.db.c_str(),
                        run.resumed ? fmt::format("resumed after trial {}", run.logged.size()).c_str() : "new");
            std::fflush(stdout);
        }
        // --- What is shown: the screens and the trials, on screen or on the
        // virtual display (session/session_display.h). The session clock goes on from
        // the last stored answer.
        SessionDisplayOptions display_options;
        display_options.person = person;
        display_options.trace = o.trace;
        display_options.font = font ? &*font : nullptr;
        display_options.screen = screen;
        SessionDisplay display(*presenter, renderer, protocol, in.display_scene, display_options, replayed.clock_s);
        // On screen a signal ends the wait (or the stimulus) at once; headless a
        // trial takes no time to show, and is finished and stored first.
        if (presenter->on_screen()) presenter->set_interrupt([] { return stop_signal() != 0; });
        if (screen && !o.quiet) print_screen(o, *screen, display);

        const SessionParts parts{o,        protocol, store,   session, renderer, observer,
                                 display,  *presenter, screen, progress};
        const TrialLoopResult loop =
            run_trials(parts, schedule, run.logged.size(), replayed.previous_ended_trial, run.resumed);
        const int stop = stop_signal();
        const bool completed = schedule.finished();
        const bool missed_stop = !completed && loop.missed->reached();
        if (missed_stop) {
            // Kept with the session (sessions.stop_json), for analyze and the report.
            store.stop_session(session, loop.missed->record(loop.rows, margin_record));
        } else {
            store.finish_session(session, completed ? st::SessionStatus::completed : st::SessionStatus::quit);
        }
        if (completed && stop == 0) display.text_screen(protocol.screens.end, "", "end");
        signals.restore();
        // What the session found: printed, and handed to the caller (RunOptions::on_summary).
        const bool with_true = completed && observer.model() && o.true_pse;
        const std::size_t frames_before = renderer.frames_rendered();
        const auto summarising = std::chrono::steady_clock::now();
        std::vector<ConditionSummary> summary;
        if (!o.quiet || o.on_summary) summary = summarise(protocol, schedule, &renderer, observer, with_true);
        const std::size_t true_frames = renderer.frames_rendered() - frames_before;
        const double true_s = seconds_since(summarising);
        if (!o.quiet)
            print_session_end(o, parts, schedule, loop, completed, stop, summary, with_true, true_frames, true_s);
        if (o.on_summary) o.on_summary(summary);
        if (missed_stop) {
            std::fprintf(stderr, "atonlab: %s\n", loop.missed->message(session.value).c_str());
            return 7;
        }
        if (loop.observer_quit && !completed) return 6;
        return completed ? 0 : 128 + stop;
    } catch (const st::StoreError& e) {
        throw st::StoreError(
            e.kind(), e.file(),
            fmt::format("{}; session {} stays open: continue it with --resume {} (or --resume-last) once the "
                        "cause is fixed",
                        e.what(), session.value, session.value),
            e.sqlite_code());
    }
}

}  // namespace atonlab::runner
