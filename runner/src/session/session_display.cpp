// What a session shows (session_display.h; docs/running.md "On screen").
#include "session/session_display.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "atonlab/common/input_error.h"
#include "atonlab/display/display_model.h"
#include "atonlab/present/screen_presenter.h"
#include "atonlab/runner/session/stimulus_renderer.h"
#include "atonlab/stimuli/image_io.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace s = atonlab::stimuli;
namespace d = atonlab::display;

namespace {

std::vector<std::string> lights_of_frame(const p::Stimulus& stimulus, std::size_t f) {
    std::vector<std::string> lights;
    for (const p::StimulusView& v : stimulus.views)
        if (v.frame == f) lights.push_back(v.light);
    return lights;
}

std::string clock_mm_ss(double seconds) {
    const auto total = static_cast<long long>(std::ceil(std::max(0.0, seconds) - 1e-9));
    return fmt::format("{}:{:02}", total / 60, total % 60);
}

std::string join_keys(const std::vector<std::string>& keys) {
    std::string out;
    for (std::size_t i = 0; i < keys.size(); ++i) {
        if (i) out += i + 1 == keys.size() ? " or " : ", ";
        out += keys[i] == "enter" ? "Enter" : keys[i] == "space" ? "Space" : keys[i] == "escape" ? "Escape" : keys[i];
    }
    return out;
}

/// A trial's steps: the fixation screen (when n_iti > 0), then each frame for n_stim refreshes with a
/// blank of n_isi between frames, and, when the stimulus loops, a blank after the last frame too.
struct TrialSteps {
    std::vector<present::Step> steps;
    std::vector<int> frame_of_step;   ///< the frame each step shows; -1 for a fixation or blank
    std::size_t last_frame_step = 0;  ///< the last interval's step, where 2AFC and yes-no answers are taken from
};

TrialSteps trial_steps(const std::vector<present::Screen>& frames, const present::Screen& bg,
                       const present::Screen& fix, int n_stim, int n_isi, int n_iti, bool loop) {
    TrialSteps plan;
    std::vector<present::Step>& steps = plan.steps;
    std::vector<int>& frame_of_step = plan.frame_of_step;
    if (n_iti > 0) {
        steps.push_back({fix, n_iti, false});
        frame_of_step.push_back(-1);
    }
    const std::size_t first_stimulus_step = steps.size();
    for (std::size_t f = 0; f < frames.size(); ++f) {
        if (f > 0 && n_isi > 0) {
            steps.push_back({bg, n_isi, true});
            frame_of_step.push_back(-1);
        }
        steps.push_back({frames[f], n_stim, true});
        frame_of_step.push_back(static_cast<int>(f));
    }
    // Looping alternation: the blank after the last interval too, before the first again.
    if (loop && frames.size() > 1 && n_isi > 0) {
        steps.push_back({bg, n_isi, true});
        frame_of_step.push_back(-1);
    }
    std::size_t& last_frame_step = plan.last_frame_step;
    last_frame_step = first_stimulus_step;
    for (std::size_t i = 0; i < steps.size(); ++i)
        if (frame_of_step[i] >= 0) last_frame_step = i;
    return plan;
}

// Headless the flips are k / rate exactly; times within the trial are then
// whole numbers of refreshes, written without the subtraction's rounding
// (so a resumed session stores the same text as an uninterrupted one).
double trial_time(double dt, bool on_screen, double hz) { return on_screen ? dt : std::round(dt * hz) / hz; }

/// A trial's timing: the first stimulus onset, the last interval's onset, the offset, and the shown steps.
struct ShownTimes {
    double onset = 0.0, window = 0.0, offset = 0.0;
    std::vector<ShownStep> shown;
};

/// The timing of what play() showed; adds the stimulus's dropped frames and missed deadlines to `out`.
ShownTimes shown_times(const present::Played& played, const TrialSteps& plan, bool on_screen, double hz,
                       TrialShown& out) {
    const std::vector<present::Step>& steps = plan.steps;
    const std::vector<int>& frame_of_step = plan.frame_of_step;
    const std::size_t last_frame_step = plan.last_frame_step;
    auto rel = [&](double dt) { return trial_time(dt, on_screen, hz); };
    double onset = 0.0, window = 0.0, offset = played.intervals.back().onset_s;
    bool onset_seen = false, window_seen = false;
    std::vector<ShownStep> shown;
    for (std::size_t i = 0; i < played.intervals.size(); ++i) {
        const present::IntervalTiming& iv = played.intervals[i];
        const std::size_t step = played.step_of[i];
        const bool stimulus = step < steps.size() ? steps[step].stimulus : true;  // the offset flip counts
        if (step < steps.size() && frame_of_step[step] >= 0 && !onset_seen) {
            onset = iv.onset_s;
            onset_seen = true;
        }
        if (step == last_frame_step && !window_seen) {
            window = iv.onset_s;
            window_seen = true;
        }
        if (stimulus && onset_seen) {
            if (step < steps.size() || iv.late_onset) out.dropped_frames += iv.dropped;
            out.missed_deadline = out.missed_deadline || (step < steps.size() ? iv.missed : iv.late_onset);
        }
        if (step < steps.size() && onset_seen && i < 16)
            shown.push_back({frame_of_step[step], rel(iv.onset_s - onset), rel(iv.duration_s()), iv.flips, iv.dropped});
    }
    return {onset, window, offset, shown};
}

}  // namespace

SessionDisplay::SessionDisplay(present::Presenter& presenter, StimulusRenderer& renderer, const p::Protocol& protocol,
                               const s::Scene& display_scene, SessionDisplayOptions options, double clock_origin_s)
    : presenter_(presenter),
      renderer_(renderer),
      protocol_(protocol),
      options_(options),
      clock_offset_s_(clock_origin_s - presenter.now_s()) {
    const d::DisplayModel& display = display_scene.output.display;
    bits_ = display_scene.output.encode.bits;
    // Text is drawn after display encoding, at the code that makes the display
    // model emit the luminance asked for (a neutral grey; no dither).
    const int max_code = (1 << bits_) - 1;
    const double white = d::displayed_luminance_cd_m2(display, glm::ivec3(max_code), bits_);
    auto ink_for = [&](double L_cd_m2, double& shown) {
        const double rel = std::clamp(L_cd_m2 / white, 0.0, 1.0);
        const glm::ivec3 c =
            d::encode_pixel(display, glm::dvec3(rel), glm::ivec2(0), 0, d::EncodeSettings{bits_, d::Dither::none, 0});
        shown = d::displayed_luminance_cd_m2(display, c, bits_);
        return present::Code3{static_cast<std::uint16_t>(c.r), static_cast<std::uint16_t>(c.g),
                              static_cast<std::uint16_t>(c.b)};
    };
    text_ink_ = ink_for(protocol.screens.text_cd_m2, text_luminance_cd_m2_);
    cue_ink_ = ink_for(protocol.screens.cue_cd_m2, cue_luminance_cd_m2_);
    pixels_per_degree_ = display_scene.display.pixels_per_degree_at_centre();
    // Sized in degrees of visual angle, so it reads the same at any resolution;
    // never below 12 px, where DejaVu Sans stops being legible.
    text_px_ = std::max(12.0, protocol.screens.text_size_deg * pixels_per_degree_);
    all_off_ = renderer.all_off(protocol.display_overrides());
    // Headless the virtual clock itself moves there, so that its flips stay on
    // the k / rate grid of the session clock.
    set_clock(clock_origin_s);
}

double SessionDisplay::now_s() {
    return presenter_.now_s() + clock_offset_s_;
}

void SessionDisplay::set_clock(double t_s) {
    if (auto* v = dynamic_cast<present::VirtualPresenter*>(&presenter_)) {
        v->advance_to(t_s);
        clock_offset_s_ = 0.0;
    } else {
        clock_offset_s_ = t_s - presenter_.now_s();
    }
}

std::string SessionDisplay::luminance_note() const {
    return fmt::format(
        "text {:.3g} cd/m² (code {}) on screens, {:.3g} cd/m² (code {}) for the countdown, prompt and fixation mark; "
        "lines {:.0f} px ({:g}° at {:.1f} px/°)",
        text_luminance_cd_m2_, text_ink_[0], cue_luminance_cd_m2_, cue_ink_[0], text_px_,
        protocol_.screens.text_size_deg, pixels_per_degree_);
}

void SessionDisplay::trace(const std::string& line) const {
    if (!options_.trace) return;
    std::printf("trace: %s\n", line.c_str());
    std::fflush(stdout);
}

std::string SessionDisplay::keys_text(p::Action a) const {
    return join_keys(protocol_.responses.keys_of(a));
}

present::Overlay SessionDisplay::text_overlay(const std::string& text, present::Code3 ink, double y_fraction,
                                              double scale) const {
    present::Overlay o;
    o.ink = ink;
    if (!options_.font || text.empty()) return o;
    const int max_width = static_cast<int>(0.8 * presenter_.width_px());
    auto bmp = std::make_shared<present::TextBitmap>(options_.font->render(text, text_px_ * scale, max_width));
    o.x = (presenter_.width_px() - bmp->width) / 2;
    o.y = static_cast<int>(std::lround(y_fraction * presenter_.height_px() - 0.5 * bmp->height));
    o.y = std::clamp(o.y, 0, std::max(0, presenter_.height_px() - bmp->height));
    o.coverage = std::move(bmp);
    return o;
}

present::Overlay SessionDisplay::fixation_overlay() const {
    // A cross 0.3° across with arms 0.04° thick (at least 1 px), centred.
    const int arm = std::max(3, static_cast<int>(std::lround(0.15 * pixels_per_degree_)));
    const int thick = std::max(1, static_cast<int>(std::lround(0.04 * pixels_per_degree_)));
    present::Overlay o;
    o.ink = cue_ink_;
    o.coverage = std::make_shared<present::TextBitmap>(present::fixation_cross(arm, thick));
    o.x = presenter_.width_px() / 2 - arm;
    o.y = presenter_.height_px() / 2 - arm;
    return o;
}

present::Screen SessionDisplay::background_screen(const p::Condition& c) {
    present::Screen sc;
    sc.bits = bits_;
    if (!presenter_.on_screen()) return sc;  // nothing is drawn headless: nothing to render
    // The condition's scene with every light off: what surrounds the stimuli,
    // and what the observer adapts to (docs/protocol-file.md, [[block]]).
    p::Frame bg;
    bg.overrides = protocol_.display_overrides();
    bg.overrides.insert(bg.overrides.end(), c.set.begin(), c.set.end());
    bg.overrides.insert(bg.overrides.end(), all_off_.begin(), all_off_.end());
    sc.picture = renderer_.codes(bg, {});
    return sc;
}


bool SessionDisplay::confirm_quit(const std::string& progress) {
    trace("pause");
    present::Screen sc;
    sc.bits = bits_;
    sc.overlays.push_back(text_overlay(
        fmt::format("Paused.\n\nPress {} to go on, or {} to end the session.\nEverything answered so far is kept; "
                    "the session can be continued later.",
                    keys_text(p::Action::Continue), keys_text(p::Action::Quit)),
        text_ink_, 0.4));
    if (!progress.empty()) sc.overlays.push_back(text_overlay(progress, text_ink_, 0.85, 0.7));
    const auto e = presenter_.wait(&sc, presenter_.now_s(), std::nullopt, [&](const present::InputEvent& ev) {
        return present::action_of(protocol_.responses, present::InputContext::pause, p::Task::TwoAfc, ev).has_value();
    });
    if (!e) return true;  // interrupted (a signal): the session ends
    const bool quit =
        present::action_of(protocol_.responses, present::InputContext::pause, p::Task::TwoAfc, *e) == p::Action::Quit;
    trace(quit ? "quit confirmed" : "going on");
    return quit;
}

bool SessionDisplay::text_screen(const std::string& text, const std::string& footer, std::string_view what) {
    if (!options_.person || text.empty()) return true;
    present::Screen sc;
    sc.bits = bits_;
    sc.overlays.push_back(text_overlay(text, text_ink_, 0.4));
    std::string foot = fmt::format("Press {} to continue.", keys_text(p::Action::Continue));
    if (!footer.empty()) foot = footer + "\n" + foot;
    sc.overlays.push_back(text_overlay(foot, text_ink_, 0.88, 0.7));
    for (;;) {
        trace(fmt::format("waiting for continue ({})", what));
        const auto e = presenter_.wait(&sc, presenter_.now_s(), std::nullopt, [&](const present::InputEvent& ev) {
            return present::action_of(protocol_.responses, present::InputContext::screen, p::Task::TwoAfc, ev)
                .has_value();
        });
        if (!e) return false;  // a signal
        if (present::action_of(protocol_.responses, present::InputContext::screen, p::Task::TwoAfc, *e) ==
            p::Action::Continue)
            return true;
        if (confirm_quit(footer)) return false;
    }
}

bool SessionDisplay::adapt(const p::Condition& c, double seconds) {
    if (!(seconds > 0.0)) return true;
    present::Screen bg = background_screen(c);
    const double start = presenter_.now_s();
    const double end = start + seconds;
    if (!presenter_.on_screen()) {
        presenter_.wait(&bg, start, end, [](const present::InputEvent&) { return false; });
        return true;
    }
    const bool skippable = protocol_.timing.adaptation_skippable;
    trace(fmt::format("adapting for {:g} s", seconds));
    for (;;) {
        const double now = presenter_.now_s();
        if (now >= end) return true;
        present::Screen sc = bg;
        std::string line = fmt::format("Adapting: {}", clock_mm_ss(end - now));
        if (skippable) line += fmt::format(" (press {} to skip)", keys_text(p::Action::Continue));
        sc.overlays.push_back(text_overlay(line, cue_ink_, 0.92, 0.7));
        // Wake at the next whole second of the countdown to redraw it.
        const double left = end - now;
        const double next = end - (std::ceil(left - 1e-9) - 1.0);
        const auto e = presenter_.wait(&sc, start, std::min(end, next), [&](const present::InputEvent& ev) {
            const auto a = present::action_of(protocol_.responses, present::InputContext::screen, p::Task::TwoAfc, ev);
            return a == p::Action::Quit || (skippable && a == p::Action::Continue);
        });
        if (!e) {
            if (presenter_.now_s() < std::min(end, next) - 1e-3) return false;  // a signal
            continue;
        }
        if (present::action_of(protocol_.responses, present::InputContext::screen, p::Task::TwoAfc, *e) ==
            p::Action::Continue) {
            trace("adaptation skipped");
            return true;
        }
        if (confirm_quit("")) return false;
    }
}

TrialShown SessionDisplay::present(const p::ScheduledTrial& t, const p::Condition& c, bool fixation,
                                   const std::optional<p::Answer>& observer_answer, const TrialHooks& hooks) {
    const p::Timing& tm = protocol_.timing;
    const double period = presenter_.period_s();
    const int n_stim = present::frames_for(tm.stimulus_s, period, 1);
    const int n_isi = present::frames_for(tm.inter_stimulus_s, period, 0);
    const int n_iti = fixation ? present::frames_for(tm.inter_trial_s, period, 0) : 0;
    const bool on_screen = presenter_.on_screen();
    const bool person = options_.person;
    const bool adjust = t.task == p::Task::Adjust;
    const bool loop = person && adjust;  // a person adjusts while the stimulus repeats

    const present::Screen bg = background_screen(c);
    std::vector<present::Screen> frames;
    for (std::size_t f = 0; f < t.stimulus.frames.size(); ++f)
        frames.push_back(stimulus_screen(renderer_, t.stimulus, f, bits_, on_screen));

    present::Screen fix = bg;  // shown before the stimulus when n_iti > 0
    if (n_iti > 0 && on_screen && protocol_.screens.fixation) fix.overlays.push_back(fixation_overlay());
    const TrialSteps plan = trial_steps(frames, bg, fix, n_stim, n_isi, n_iti, loop);
    const std::vector<int>& frame_of_step = plan.frame_of_step;

    present::Screen then = bg;
    if (on_screen && !c.prompt.empty() && !adjust) then.overlays.push_back(text_overlay(c.prompt, cue_ink_, 0.75));

    auto answer_action = [&](const present::InputEvent& e) {
        return present::action_of(protocol_.responses, present::InputContext::trial, t.task, e);
    };
    const double sequence_start = presenter_.now_s();
    present::PlayOptions po;
    po.loop = loop;
    po.stall_frames = hooks.stall_frames;
    if (hooks.before_frame_onset)
        po.before_onset = [&](std::size_t step) {
            if (frame_of_step[step] >= 0) hooks.before_frame_onset(static_cast<std::size_t>(frame_of_step[step]));
        };
    if (hooks.after_frame_onset)
        po.after_onset = [&](std::size_t step) {
            if (frame_of_step[step] >= 0) hooks.after_frame_onset(static_cast<std::size_t>(frame_of_step[step]));
        };
    if (loop)
        po.stop = [&](const present::InputQueue& q) {
            return q.find(sequence_start, [&](const present::InputEvent& e) { return answer_action(e).has_value(); }) !=
                   nullptr;
        };
    trace(fmt::format("trial {}: presenting", t.step + 1));
    const present::Played played = presenter_.play(plan.steps, then, po);

    // Timing: onsets, offset and what was missed (shown_times).
    TrialShown out;
    const double hz = on_screen ? 1.0 / period : protocol_.timing.refresh_hz.value_or(60.0);
    const ShownTimes times = shown_times(played, plan, on_screen, hz, out);
    const double onset = times.onset, window = times.window, offset = times.offset;
    const double presented = trial_time(offset - onset, on_screen, hz);
    out.onset_s = onset + clock_offset_s_;
    out.frames = FramesShown{hz, n_stim, n_isi, n_iti, presented, times.shown};

    auto is_quit = [&](const present::InputEvent& e) { return answer_action(e) == p::Action::Quit; };
    if (played.stopped && !(loop && presenter_.input().find(sequence_start, [&](const present::InputEvent& e) {
            return answer_action(e).has_value();
        }))) {
        out.end = TrialEnd::interrupted;
        return out;
    }
    // The quit key at any time during the presentation: pause.
    if (presenter_.input().find(sequence_start, is_quit)) {
        presenter_.input().clear();
        out.end = TrialEnd::paused;
        return out;
    }

    if (person) {
        std::optional<present::InputEvent> e;
        if (adjust) {
            e = presenter_.input().take_first(
                sequence_start, [&](const present::InputEvent& ev) { return answer_action(ev).has_value(); });
        } else {
            std::optional<double> deadline;
            if (tm.response_timeout_s) deadline = offset + *tm.response_timeout_s;
            trace(fmt::format("trial {}: waiting for an answer", t.step + 1));
            e = presenter_.wait(nullptr, window, deadline,
                                [&](const present::InputEvent& ev) { return answer_action(ev).has_value(); });
            if (!e) {
                if (deadline && presenter_.now_s() >= *deadline) {
                    out.end = TrialEnd::timeout;
                    out.response_time_s = *deadline - onset;
                    out.answer_after_offset_s = *tm.response_timeout_s;
                    trace(fmt::format("trial {}: timeout", t.step + 1));
                } else {
                    out.end = TrialEnd::interrupted;
                }
                return out;
            }
        }
        if (!e) {
            out.end = TrialEnd::interrupted;
            return out;
        }
        const auto a = answer_action(*e);
        if (a == p::Action::Quit) {
            presenter_.input().clear();
            out.end = TrialEnd::paused;
            return out;
        }
        out.response = p::response_of(*a);
        out.input = (e->source == present::InputEvent::Source::gamepad ? "gamepad:" : "") + e->name;
        out.response_time_s = e->time_s - onset;
        out.answer_after_offset_s = e->time_s - offset;
        trace(fmt::format("trial {}: answered {} ({})", t.step + 1, e->name, to_string(*a)));
        return out;
    }

    // An observer: its answer after its response time (the screen keeps
    // showing the response screen meanwhile; the quit key still pauses).
    const double rt = std::max(0.0, observer_answer ? observer_answer->response_time_s : 0.0);
    const bool timed_out = !adjust && tm.response_timeout_s && rt > *tm.response_timeout_s;
    const double after = timed_out ? *tm.response_timeout_s : rt;
    const auto e = presenter_.wait(nullptr, sequence_start, offset + after, is_quit);
    if (e) {
        presenter_.input().clear();
        out.end = TrialEnd::paused;
        return out;
    }
    if (on_screen && presenter_.now_s() < offset + after - 1e-3) {
        out.end = TrialEnd::interrupted;
        return out;
    }
    out.response_time_s = presented + after;
    out.answer_after_offset_s = after;
    if (timed_out) {
        out.end = TrialEnd::timeout;
        return out;
    }
    out.response = observer_answer ? std::optional<p::Response>(observer_answer->response) : std::nullopt;
    return out;
}

present::Screen stimulus_screen(StimulusRenderer& renderer, const p::Stimulus& stimulus, std::size_t f, int bits,
                                bool on_screen) {
    present::Screen sc;
    sc.bits = bits;
    if (!on_screen) return sc;  // nothing is drawn headless: nothing to render
    const p::Frame& frame = stimulus.frames[f];
    if (renderer.animated(frame)) {
        sc.animate = [&renderer, frame](double at_s) { renderer.encode(frame, at_s); };
        sc.present = [&renderer](int x, int y) { renderer.present(x, y); };
    } else {
        sc.picture = renderer.codes(frame, lights_of_frame(stimulus, f));
    }
    return sc;
}

std::unique_ptr<present::Presenter> open_screen(const RunOptions& o, const p::Protocol& protocol,
                                                const s::Scene& display_scene, present::ScreenPresenter*& screen) {
    present::ScreenOptions so;
    so.monitor = o.monitor;
    so.software_vsync_hz = o.software_vsync_hz;
    so.skip_sync_test = o.skip_sync_test;
    so.sync.max_sd_s = o.sync_sd_max_ms * 1e-3;
    so.sync.max_deviation = o.refresh_tolerance;
    so.expected_hz = protocol.timing.refresh_hz;
    so.title = "atonlab: " + protocol.name;
    std::unique_ptr<present::ScreenPresenter> sp = present::ScreenPresenter::open(so);
    if (sp->width_px() != protocol.display.width_px || sp->height_px() != protocol.display.height_px)
        throw InputError(SourceLocation{protocol.file, 0, 0, "display.width_px"},
                         fmt::format("the protocol's display is {}×{} px but monitor {} shows {}×{}: the stimuli's "
                                     "angles would be wrong; give [display] the monitor's native size (or choose "
                                     "another with --monitor).",
                                     protocol.display.width_px, protocol.display.height_px, o.monitor, sp->width_px(),
                                     sp->height_px()));
    const int bits = display_scene.output.encode.bits;
    if (sp->framebuffer_bits() != bits)
        throw InputError(SourceLocation{protocol.scene.string(), 0, 0, "display.bits"},
                         fmt::format("the scene encodes {}-bit code values but the window's framebuffer has {} bits "
                                     "per channel: the screen would not show the codes made for it.",
                                     bits, sp->framebuffer_bits()));
    screen = sp.get();
    return sp;
}

void capture_frame(const RunOptions& o, present::ScreenPresenter* screen, StimulusRenderer& renderer,
                   const p::ScheduledTrial& t, std::size_t row, std::size_t f, bool after_flip) {
    const std::filesystem::path dir = o.capture_dir;
    std::filesystem::create_directories(dir);
    const std::string base = fmt::format("trial{}-frame{}", row, f);
    if (screen && !o.capture_screen_file.empty()) {
        if (!after_flip) return;
        screen->sync_with_server();
        std::filesystem::copy_file(o.capture_screen_file, dir / (base + ".xwd"),
                                   std::filesystem::copy_options::overwrite_existing);
    } else if (screen) {
        if (after_flip) return;
        screen->capture_back(dir / (base + ".png"));
    } else {
        if (after_flip) return;
        const auto codes = renderer.codes(t.stimulus.frames[f], lights_of_frame(t.stimulus, f));
        std::vector<float> v(codes->rgb.size());
        const double max_code = static_cast<double>((1 << codes->bits) - 1);
        for (std::size_t i = 0; i < v.size(); ++i)
            v[i] = static_cast<float>(std::round(codes->rgb[i] / max_code * 255.0) / 255.0);
        s::write_png_rgb8(dir / (base + ".png"), codes->width, codes->height, v);
    }
}

}  // namespace atonlab::runner
