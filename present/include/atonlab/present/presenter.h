#pragma once
// Where a session's screens go (docs/running.md): the Presenter interface that
// run_session drives, with two implementations sharing every timing rule.
//
//  - VirtualPresenter (headless, EGL): nothing is shown; flips happen on a
//    virtual clock at the protocol's nominal refresh rate (a flip at every
//    k / rate seconds), so the stored onsets and durations are those a perfect
//    display would have given.
//  - ScreenPresenter (screen_presenter.h, GLFW): a full-screen window, vertical
//    sync, every flip timestamped.
//
// Both run the same flip loop (Presenter::play): a sequence of steps, each a
// screen held for a number of refreshes counted by the FrameClock, then the
// screen that follows it; the presenters only differ in how a flip happens and
// when it is seen. Times are seconds on the presenter's own clock (now_s()).
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "atonlab/present/frame_clock.h"
#include "atonlab/present/input.h"
#include "atonlab/present/text.h"
#include "atonlab/stimuli/display_pipeline.h"

namespace atonlab::present {

using Code3 = std::array<std::uint16_t, 3>;

/// Coverage (text, the fixation mark) blended in `ink` code values with its
/// top-left corner at (x, y), row 0 at the top of the screen.
struct Overlay {
    std::shared_ptr<const TextBitmap> coverage;
    int x = 0;
    int y = 0;
    Code3 ink{0, 0, 0};
};

/// What one flip shows: a picture of code values (a rendered frame), or one
/// code everywhere, with overlays drawn after it (after display encoding).
struct Screen {
    /// A frame's code values (row 0 at the top), or null for `background` everywhere.
    std::shared_ptr<const stimuli::EncodedImage> picture;
    Code3 background{0, 0, 0};
    int bits = 8;  ///< the depth of `background` and the overlays' ink codes
    std::vector<Overlay> overlays;
    /// An animated picture (lights with a rhythm): animate(t_s) renders, off
    /// screen, the frame seen t_s seconds after its step's onset (the predicted
    /// flip time); present(x, y) then draws it into the bound framebuffer with
    /// its lower-left corner at (x, y). Replaces `picture` on screen; the
    /// virtual presenter draws nothing.
    std::function<void(double t_s)> animate;
    std::function<void(int x, int y)> present;
};

/// A screen held for `frames` refreshes.
struct Step {
    Screen screen;
    int frames = 1;
    bool stimulus = false;  ///< part of the stimulus: its late flips mark the trial
};

struct PlayOptions {
    /// Show the steps again and again (method of adjustment) until stop() holds.
    bool loop = false;
    /// Asked after every flip: true ends the steps at once (a key was pressed).
    std::function<bool(const InputQueue&)> stop;
    /// Test-only: after the onset flip of the first stimulus step, stall the
    /// loop for this many refresh periods (docs/running.md, "Testing").
    int stall_frames = 0;
    /// Test-only: called with a stimulus step's index when its onset is drawn,
    /// before the flip (the back buffer holds what the flip will show) ...
    std::function<void(std::size_t step)> before_onset;
    /// ... and after the onset flip (the display shows it).
    std::function<void(std::size_t step)> after_onset;
};

/// One showing of a screen, timed by Presenter::time_showing(), s.
struct ShowTiming {
    double upload_s = 0.0;  ///< prepare(): its picture's codes to the GPU, the overlays blended
    double draw_s = 0.0;    ///< draw() (an animated picture rendered) and finish(): the GPU done
    double show_s() const noexcept { return upload_s + draw_s; }
};

/// What play() did: one interval per step shown (every pass when looping),
/// then the interval of the screen that followed them (its onset = the last
/// step's offset).
struct Played {
    std::vector<IntervalTiming> intervals;
    std::vector<std::size_t> step_of;  ///< the step index of each interval (the last: steps.size())
    bool stopped = false;              ///< stop() or the interrupt ended it early
};

class Presenter {
public:
    /// A presenter's resources for one screen (GPU buffers on screen), made
    /// before a flip loop starts.
    struct Prepared {
        virtual ~Prepared() = default;
    };

    virtual ~Presenter() = default;
    Presenter(const Presenter&) = delete;
    Presenter& operator=(const Presenter&) = delete;

    virtual bool on_screen() const = 0;
    /// The refresh period used to count frames, s (measured on screen, nominal headless).
    double period_s() const noexcept { return clock_.period_s(); }
    virtual double now_s() = 0;
    virtual int width_px() const = 0;
    virtual int height_px() const = 0;

    /// Shows the steps back to back, each for its number of refreshes, then
    /// `then` with one flip, which stays up. The first step's onset is the next
    /// flip (the screen before sat still: its onset is never late).
    Played play(std::span<const Step> steps, const Screen& then, const PlayOptions& options = {});

    /// Shows `screen` (one flip; nullptr: leave what is up) and waits until an
    /// event seen at or after since_s is accepted (returned; it and every event
    /// before it are taken from the queue), until deadline_s passes (nullopt),
    /// or until the interrupt holds (nullopt). A presenter with no person
    /// (virtual) returns nullopt at once, its clock moved to the deadline.
    std::optional<InputEvent> wait(const Screen* screen, double since_s, std::optional<double> deadline_s,
                                   const std::function<bool(const InputEvent&)>& accept);

    /// How long showing `screen` takes, `times` times (docs/running.md,
    /// "Presentation margin"): right after a flip, the screen is prepared as new
    /// (its picture uploaded afresh), drawn as for its onset and finished (the
    /// GPU's work done), then flipped. The flip's wait for the refresh is not
    /// timed: it is the margin. extra_s: test-only, a sleep added to each draw.
    std::vector<ShowTiming> time_showing(const Screen& screen, int times, double extra_s = 0.0);

    InputQueue& input() noexcept { return input_; }
    /// Checked between flips and while waiting: true ends play() and wait() early (a signal).
    void set_interrupt(std::function<bool()> interrupt) { interrupt_ = std::move(interrupt); }

protected:
    explicit Presenter(double period_s) : clock_(period_s) {}

    virtual std::unique_ptr<Prepared> prepare(const Screen& screen) = 0;
    /// Draws a prepared screen for the flip seen t_s after its step's onset.
    virtual void draw(const Prepared& screen, double t_s) = 0;
    /// Waits until the GPU has done everything drawn so far (on screen glFinish).
    virtual void finish() {}
    /// Presents what was drawn; returns when the flip was seen (s).
    virtual double flip() = 0;
    /// Test-only stall: lose `frames` refresh periods before the next flip.
    virtual void stall(int frames) = 0;
    /// Waits for input until until_s (or an event), filling input().
    virtual void wait_events(double until_s) = 0;
    /// A person can answer here.
    virtual bool has_person() const = 0;

    void set_period(double period_s) { clock_ = FrameClock(period_s); }
    bool interrupted() const { return interrupt_ && interrupt_(); }

    FrameClock clock_;
    InputQueue input_;
    std::function<bool()> interrupt_;
};

/// Headless: a virtual display refreshing at `refresh_hz`; every flip lands on
/// the next k / refresh_hz after the clock (set_clock), nothing is drawn, and
/// no person answers.
class VirtualPresenter final : public Presenter {
public:
    VirtualPresenter(double refresh_hz, int width_px, int height_px);
    bool on_screen() const override { return false; }
    double now_s() override { return now_; }
    int width_px() const override { return width_; }
    int height_px() const override { return height_; }
    /// Moves the virtual clock (it never goes back).
    void advance_to(double t_s);

protected:
    std::unique_ptr<Prepared> prepare(const Screen&) override;
    void draw(const Prepared&, double) override {}
    double flip() override;
    void stall(int frames) override;
    void wait_events(double until_s) override;
    bool has_person() const override { return false; }

private:
    double hz_;
    int width_, height_;
    double now_ = 0.0;
    double last_k_ = -1.0;  ///< the refresh index of the last flip (an integer)
};

}  // namespace atonlab::present
