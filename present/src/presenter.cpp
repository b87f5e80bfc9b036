// The flip loop both presenters share, and the virtual (headless) presenter
// (presenter.h; docs/running.md "Timing").
#include "atonlab/present/presenter.h"

#include <algorithm>
#include <cmath>
#include <chrono>
#include <stdexcept>
#include <thread>

namespace atonlab::present {

Played Presenter::play(std::span<const Step> steps, const Screen& then, const PlayOptions& o) {
    std::vector<std::unique_ptr<Prepared>> prepared;
    prepared.reserve(steps.size());
    for (const Step& s : steps) prepared.push_back(prepare(s.screen));
    const std::unique_ptr<Prepared> after = prepare(then);

    Played out;
    // The screen before sat still (a key was awaited, frames were rendered):
    // the first onset starts afresh and cannot be late.
    clock_.idle();
    clock_.clear_intervals();
    bool stall_pending = o.stall_frames > 0;
    bool stop = false;
    do {
        for (std::size_t i = 0; i < steps.size() && !stop; ++i) {
            clock_.begin(std::max(1, steps[i].frames));
            out.step_of.push_back(i);
            bool onset = true;
            while (clock_.wants_flip()) {
                draw(*prepared[i], clock_.next_flip_offset_s());
                if (onset && steps[i].stimulus && o.before_onset) o.before_onset(i);
                clock_.flip(flip());
                if (onset && steps[i].stimulus) {
                    if (o.after_onset) o.after_onset(i);
                    if (stall_pending) {
                        stall(o.stall_frames);
                        stall_pending = false;
                    }
                }
                onset = false;
                if ((o.stop && o.stop(input_)) || interrupted()) {
                    stop = true;
                    break;
                }
            }
        }
    } while (o.loop && !stop);
    out.stopped = stop;
    clock_.begin(1);
    out.step_of.push_back(steps.size());
    draw(*after, 0.0);
    clock_.flip(flip());
    out.intervals = clock_.intervals();
    return out;
}

std::optional<InputEvent> Presenter::wait(const Screen* screen, double since_s, std::optional<double> deadline_s,
                                          const std::function<bool(const InputEvent&)>& accept) {
    if (screen) {
        const std::unique_ptr<Prepared> p = prepare(*screen);
        clock_.idle();
        clock_.clear_intervals();
        draw(*p, 0.0);
        clock_.flip(flip());
    }
    input_.drop_before(since_s);
    if (!has_person()) {
        if (deadline_s) wait_events(*deadline_s);
        return std::nullopt;
    }
    for (;;) {
        if (auto e = input_.take_first(since_s, accept)) return e;
        if (interrupted()) return std::nullopt;
        const double now = now_s();
        if (deadline_s && now >= *deadline_s) return std::nullopt;
        // Wake at least every 0.25 s to check the interrupt (a signal).
        wait_events(deadline_s ? std::min(*deadline_s, now + 0.25) : now + 0.25);
    }
}

std::vector<ShowTiming> Presenter::time_showing(const Screen& screen, int times, double extra_s) {
    std::vector<ShowTiming> out;
    clock_.idle();
    clock_.clear_intervals();
    flip();  // the first showing starts right after a refresh, as a trial's flips do
    for (int i = 0; i < times; ++i) {
        Screen fresh = screen;  // a new picture object: uploaded again, not taken from the presenter's cache
        if (screen.picture) fresh.picture = std::make_shared<stimuli::EncodedImage>(*screen.picture);
        const double t0 = now_s();
        const std::unique_ptr<Prepared> p = prepare(fresh);
        const double t1 = now_s();
        draw(*p, 0.0);
        if (extra_s > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(extra_s));
        finish();
        const double t2 = now_s();
        flip();
        out.push_back({t1 - t0, t2 - t1});
    }
    return out;
}

// ---------------------------------------------------------------------------
// VirtualPresenter

VirtualPresenter::VirtualPresenter(double refresh_hz, int width_px, int height_px)
    : Presenter(1.0 / refresh_hz), hz_(refresh_hz), width_(width_px), height_(height_px) {
    if (!(refresh_hz > 0.0) || !std::isfinite(refresh_hz))
        throw std::invalid_argument("VirtualPresenter: the refresh rate must be > 0");
}

void VirtualPresenter::advance_to(double t_s) {
    now_ = std::max(now_, t_s);
}

std::unique_ptr<Presenter::Prepared> VirtualPresenter::prepare(const Screen&) {
    return std::make_unique<Prepared>();
}

double VirtualPresenter::flip() {
    // The next refresh k / hz at or after the clock, and after the last flip.
    // Times are k / hz for an integer k (so 48 refreshes at 60 Hz are 0.8 s
    // to the last bit); the 1e-7 keeps a clock that is a refresh time up to
    // rounding on that refresh.
    const double k = std::max(std::ceil(now_ * hz_ - 1e-7), last_k_ + 1.0);
    last_k_ = k;
    now_ = k / hz_;
    return now_;
}

void VirtualPresenter::stall(int frames) {
    // As a real display: the loop sleeps `frames` periods after a flip, and the
    // next swap waits for the refresh after that: `frames` refreshes are lost.
    now_ = std::max(now_, (last_k_ + frames + 0.5) / hz_);
}

void VirtualPresenter::wait_events(double until_s) {
    advance_to(until_s);
}

}  // namespace atonlab::present
