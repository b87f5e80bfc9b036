#pragma once
// What a session shows, on whichever presenter it runs (docs/running.md,
// "On screen"): the text screens (instructions, breaks, the end, the pause
// and its confirm-to-quit), the adaptation countdown before a block, and each
// trial: the fixation, the stimulus counted in frames, the response screen,
// and the answer (a person's key or button, timestamped, or an observer's
// after its response time). run_session.cpp decides what is stored.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "atonlab/present/presenter.h"
#include "atonlab/present/text.h"
#include "atonlab/protocols/observer.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/runner/session/run_options.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::present {
class ScreenPresenter;
}  // namespace atonlab::present

namespace atonlab::runner {

class StimulusRenderer;

struct SessionDisplayOptions {
    bool person = false;                  ///< a person answers (keys, gamepad); else an observer's answers are given
    bool trace = false;                   ///< print what the screen waits for (tests drive the keys from it)
    const present::Font* font = nullptr;  ///< on screen: the font of every text
    present::ScreenPresenter* screen = nullptr;  ///< on screen: the presenter's own hooks (captures)
};

/// How a trial's presentation ended.
enum class TrialEnd : std::uint8_t {
    answered,     ///< an answer (the person's, or the observer's)
    timeout,      ///< no answer within response_timeout_s
    paused,       ///< the quit key: the pause screen comes next, the trial is shown again unless the session ends
    interrupted,  ///< a signal
};

/// One step of a trial as its flips showed it; times from the stimulus onset, s.
struct ShownStep {
    int frame = -1;  ///< the stimulus frame it showed, or -1 for a blank
    double onset_s = 0.0;
    double duration_s = 0.0;
    int flips = 0;    ///< flips made while it was up
    int dropped = 0;  ///< refreshes missed at its flips
};

/// The frames a trial asked for and what the flips gave: whole refreshes at
/// the measured (on screen) or nominal (headless) rate.
struct FramesShown {
    double refresh_hz = 0.0;
    int stimulus_frames = 0;
    int inter_stimulus_frames = 0;
    int inter_trial_frames = 0;
    double presented_s = 0.0;      ///< the stimulus's onset to its offset, s
    std::vector<ShownStep> shown;  ///< the steps from the onset (16 at most)
};

/// One trial as it was shown.
struct TrialShown {
    TrialEnd end = TrialEnd::answered;
    std::optional<protocols::Response> response;
    std::string input;                   ///< the key or button pressed ("" for an observer or a timeout)
    double onset_s = 0.0;                ///< the stimulus onset, session clock (s)
    double response_time_s = 0.0;        ///< onset to answer (or to the timeout), s
    double answer_after_offset_s = 0.0;  ///< the answer after the stimulus ended, s (< 0: during it)
    int dropped_frames = 0;              ///< refreshes missed at the stimulus's flips (onsets and offset included)
    bool missed_deadline = false;        ///< a stimulus flip came > 1.5 periods late
    /// The frames asked for and what the flips gave; none before the trial was presented.
    std::optional<FramesShown> frames;
};

/// Test hooks (docs/running.md, "Testing").
struct TrialHooks {
    int stall_frames = 0;  ///< stall after the stimulus onset
    /// Called with each stimulus frame's index when its onset is drawn, before
    /// the flip, and after the onset flip.
    std::function<void(std::size_t frame)> before_frame_onset;
    std::function<void(std::size_t frame)> after_frame_onset;
};

class SessionDisplay {
public:
    /// clock_origin_s: the session clock at the presenter's time now (a resumed
    /// session goes on from its last answer).
    SessionDisplay(present::Presenter& presenter, StimulusRenderer& renderer, const protocols::Protocol& protocol,
                   const stimuli::Scene& display_scene, SessionDisplayOptions options, double clock_origin_s);

    present::Presenter& presenter() noexcept { return presenter_; }
    /// The session clock now, s.
    double now_s();
    /// Moves a virtual presenter's clock to session time t (headless resume).
    void set_clock(double t_s);

    /// A text screen dismissed with `continue` (nothing shown without a person
    /// or with empty text). `footer`: a line under it (progress). Returns
    /// false when the person ended the session there (quit, confirmed).
    bool text_screen(const std::string& text, const std::string& footer, std::string_view what);
    /// The adaptation before a block run: the condition's scene with every
    /// light off, for `seconds`, with a countdown (skippable with `continue`
    /// where the protocol allows). Returns false when the person ended the session.
    bool adapt(const protocols::Condition& condition, double seconds);
    /// The pause screen after the quit key: true when the person confirms the
    /// end of the session (quit again), false to go on.
    bool confirm_quit(const std::string& progress);
    /// Shows a trial. fixation: with the inter-trial fixation before it (not
    /// between the actions of one adjustment). observer_answer: the observer's
    /// answer (without a person); the person's is read from the input.
    TrialShown present(const protocols::ScheduledTrial& trial, const protocols::Condition& condition, bool fixation,
                       const std::optional<protocols::Answer>& observer_answer, const TrialHooks& hooks);

    /// The text ink codes and the luminance they give (cd/m²), for the report.
    std::string luminance_note() const;
    /// The pixel height of a line of text.
    double text_px() const noexcept { return text_px_; }

private:
    present::Screen background_screen(const protocols::Condition& c);
    present::Overlay text_overlay(const std::string& text, present::Code3 ink, double y_fraction,
                                  double scale = 1.0) const;
    present::Overlay fixation_overlay() const;
    std::string keys_text(protocols::Action a) const;
    void trace(const std::string& line) const;

    present::Presenter& presenter_;
    StimulusRenderer& renderer_;
    const protocols::Protocol& protocol_;
    SessionDisplayOptions options_;
    double clock_offset_s_;  ///< session clock − presenter clock
    int bits_ = 8;
    present::Code3 text_ink_{0, 0, 0}, cue_ink_{0, 0, 0};
    double text_luminance_cd_m2_ = 0.0, cue_luminance_cd_m2_ = 0.0;
    double text_px_ = 24.0;
    double pixels_per_degree_ = 0.0;
    std::vector<SceneOverride> all_off_;  ///< every light dark and disc gone (StimulusRenderer::all_off)
};

/// Frame f of a stimulus as the screen shows it (`bits` per channel): its
/// codes, rendered once; or, where a light has a rhythm, rendered at each
/// flip's time (Screen::animate). Headless an empty screen (nothing is drawn).
present::Screen stimulus_screen(StimulusRenderer& renderer, const protocols::Stimulus& stimulus, std::size_t f,
                                int bits, bool on_screen);

/// Opens the full-screen presenter for a session (RunOptions' on-screen
/// options) and checks the screen fits the protocol: its size is the
/// protocol's [display] (else the pixels per degree would be wrong) and its
/// framebuffer has the encoder's bits. Throws gl::ContextUnavailable,
/// DisplayTimingRefused, InputError.
std::unique_ptr<present::Presenter> open_screen(const RunOptions& options, const protocols::Protocol& protocol,
                                                const stimuli::Scene& display_scene, present::ScreenPresenter*& screen);

/// Test hook (--capture-trial): frame `f` of trial `t` (stored as trial_index
/// `row`) into options.capture_dir: trialROW-frameF.xwd, a copy of
/// --capture-screen-file after the onset flip (after_flip); or
/// trialROW-frameF.png, the window's back buffer drawn for the onset flip
/// (!after_flip), or headless the frame's codes.
void capture_frame(const RunOptions& options, present::ScreenPresenter* screen, StimulusRenderer& renderer,
                   const protocols::ScheduledTrial& t, std::size_t row, std::size_t f, bool after_flip);

}  // namespace atonlab::runner
