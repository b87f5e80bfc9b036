// The trial loop (trial_loop.h).
#include "session/trial_loop.h"

#include <fmt/format.h>

#include <chrono>
#include <optional>
#include <set>
#include <string>

#include "atonlab/runner/session/stop_signals.h"
#include "atonlab/stimuli/error.h"
#include "session/snapshot.h"
#include "session/trial_record.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace st = atonlab::store;

namespace {

/// "block R of N, trial T of at most M": where the session stands, for the break and pause screens.
std::string progress_text(const p::Schedule& schedule, const p::ScheduledTrial& t, std::size_t row) {
    const std::size_t runs = schedule.block_runs().size();
    const std::optional<std::size_t> bound = schedule.max_trials();
    return fmt::format("block {} of {}, trial {} of {}{}", t.run + 1, runs, row + 1, bound ? "at most " : "",
                       bound ? fmt::format("{}", *bound) : std::string("?"));
}

/// Before a block run: the break, the block's instructions, the adaptation.
/// False when the observer (or a signal) ended the session on one of them.
bool show_run_start(const SessionParts& s, const p::Schedule& schedule, const p::ScheduledTrial& t, std::size_t row) {
    const p::Block& block = s.protocol.blocks[t.block];
    const p::Condition& c = block.conditions[t.condition];
    bool go_on = true;
    if (t.starts_run && t.run > 0)
        go_on = s.display.text_screen(s.protocol.screens.between, progress_text(schedule, t, row), "break");
    go_on = go_on && s.display.text_screen(block.instructions, "", "block instructions");
    return go_on && s.display.adapt(c, block.adaptation_s);
}

/// The observer's answer to trial t (none when a person answers at the screen).
std::optional<p::Answer> observer_answer(const SessionParts& s, const p::ScheduledTrial& t) {
    if (s.observer.person()) return std::nullopt;
    try {
        return s.observer.answer(t, &s.renderer);
    } catch (const InputError& e) {
        // The script ran out or does not fit: what is stored stays, and the session can go on.
        throw InputError(e.where().value_or(SourceLocation{}),
                         fmt::format("{} Session {} stays open: continue it with --resume {}.", e.message(),
                                     s.session.value, s.session.value));
    }
}

/// The test hooks (--inject-stall-*, --capture-*) for trial t stored as `row`.
TrialHooks hooks_for(const SessionParts& s, const p::ScheduledTrial& t, std::size_t row) {
    const RunOptions& o = s.options;
    TrialHooks hooks;
    if (o.inject_stall_every_trial ||
        (o.inject_stall_at_trial && static_cast<std::size_t>(*o.inject_stall_at_trial) == row))
        hooks.stall_frames = o.inject_stall_frames;
    if (o.capture_trial && static_cast<std::size_t>(*o.capture_trial) == row) {
        hooks.before_frame_onset = [&s, &t, row](std::size_t f) {
            capture_frame(s.options, s.screen, s.renderer, t, row, f, false);
        };
        hooks.after_frame_onset = [&s, &t, row](std::size_t f) {
            capture_frame(s.options, s.screen, s.renderer, t, row, f, true);
        };
    }
    return hooks;
}

}  // namespace

TrialLoopResult run_trials(const SessionParts& s, p::Schedule& schedule, std::size_t first_row,
                           bool previous_ended_trial, bool resumed) {
    const RunOptions& o = s.options;
    std::set<std::string> snapshotted;
    if (resumed) {
        for (const p::Block& b : s.protocol.blocks)
            for (const p::Condition& c : b.conditions)
                if (s.store.get_snapshot(s.session, c.name)) snapshotted.insert(c.name);
    }
    TrialLoopResult out;
    out.missed.emplace(s.protocol.timing, schedule.max_trials(), s.presenter.period_s());
    out.rows = first_row;  // the next trial_index: every stored trial, counted or not
    const std::size_t runs = schedule.block_runs().size();
    bool first_trial_here = true;
    std::size_t run_started = runs;  // the block run whose break, instructions and adaptation were shown
    if (!s.display.text_screen(s.protocol.screens.instructions, resumed ? "Continuing the session." : "",
                               "instructions"))
        out.observer_quit = stop_signal() == 0;
    while (!out.observer_quit && !schedule.finished() && stop_signal() == 0) {
        const p::ScheduledTrial t = *schedule.next();
        const p::Condition& c = s.protocol.blocks[t.block].conditions[t.condition];
        if (t.starts_run || first_trial_here) s.progress.block(s.protocol, t, runs, s.presenter.on_screen());
        // Headless the simulated clock adapts only where a run starts (as an
        // uninterrupted session would); on screen a resumed session adapts
        // again, the observer having been away.
        if ((t.starts_run || (first_trial_here && s.presenter.on_screen())) && run_started != t.run) {
            run_started = t.run;  // once per run: a trial shown again after a pause does not start it again
            if (!show_run_start(s, schedule, t, out.rows)) {
                out.observer_quit = stop_signal() == 0;
                break;
            }
            previous_ended_trial = true;
        }
        first_trial_here = false;
        if (!snapshotted.count(c.name)) {
            const auto started = std::chrono::steady_clock::now();
            s.store.put_snapshot(s.session, c.name, snapshot_exr(s.renderer, s.protocol, c, t, s.session.value));
            snapshotted.insert(c.name);
            out.snapshot_s += seconds_since(started);
        }
        const std::optional<p::Answer> answer = observer_answer(s, t);
        const TrialShown shown = s.display.present(t, c, previous_ended_trial, answer, hooks_for(s, t, out.rows));
        if (shown.end == TrialEnd::interrupted) break;
        if (shown.end == TrialEnd::paused) {
            // Nothing of the interrupted trial is stored: it is shown again
            // (after a fixation) unless the observer ends the session here.
            if (s.display.confirm_quit(progress_text(schedule, t, out.rows))) {
                out.observer_quit = stop_signal() == 0;
                break;
            }
            previous_ended_trial = true;
            continue;
        }
        // A trial the procedure does not see: a timeout, or (repeat_missed)
        // a stimulus that missed a refresh. Stored, then shown again.
        const bool repeat_missed = shown.end == TrialEnd::answered && shown.missed_deadline &&
                                   s.protocol.timing.repeat_missed && t.task != p::Task::Adjust;
        const bool counted = shown.end == TrialEnd::answered && !repeat_missed;
        if (counted) {
            try {
                schedule.record(*shown.response);
            } catch (const p::ProcedureError& e) {
                throw InputError(SourceLocation{o.script.empty() ? o.protocol : o.script, 0, 0, ""},
                                 fmt::format("trial {} ({}) cannot take the answer \"{}\": {}", t.step + 1,
                                             t.condition_id, p::response_word(*shown.response), e.message()));
            }
        }
        const st::TrialRecord tr = trial_record(s.protocol, t, out.rows, shown, counted, schedule, s.observer, s.renderer);
        const auto storing = std::chrono::steady_clock::now();
        s.store.record_trial(s.session, tr);  // durable before the next stimulus
        out.store_s += seconds_since(storing);
        ++out.rows;
        previous_ended_trial = !counted || t.task != p::Task::Adjust || *shown.response == p::Response::Confirm;
        s.progress.trial(s.protocol, t, out.rows);
        if (o.after_trial) o.after_trial(out.rows, schedule.max_trials());
        // A presentation shown again because it missed (repeat_missed; a
        // timeout that missed too): counted towards the bound, which ends the run.
        out.missed->add((repeat_missed || (shown.end == TrialEnd::timeout && shown.missed_deadline &&
                                           t.task != p::Task::Adjust)),
                        shown.dropped_frames);
        if (out.missed->reached()) break;
    }
    s.progress.end_line();
    return out;
}

}  // namespace atonlab::runner
