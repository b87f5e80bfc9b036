// The frame clock (frame_clock.h; docs/running.md "Timing").
#include "atonlab/present/frame_clock.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace atonlab::present {

RefreshEstimate estimate_refresh(std::span<const double> t) {
    RefreshEstimate e;
    if (t.size() < 2) return e;
    std::vector<double> d;
    d.reserve(t.size() - 1);
    for (std::size_t i = 1; i < t.size(); ++i) d.push_back(t[i] - t[i - 1]);
    std::vector<double> sorted = d;
    std::sort(sorted.begin(), sorted.end());
    const std::size_t n = sorted.size();
    const double median = n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
    // Two passes (mean, then squared deviations) rather than Σx² − n·mean²: the
    // intervals are nearly equal, and the one-pass form loses their spread to
    // cancellation.
    double sum = 0.0;
    for (const double x : d) {
        if (median > 0.0 && x >= 0.5 * median && x <= 1.5 * median) {
            sum += x;
            ++e.valid;
        } else {
            ++e.rejected;
        }
    }
    if (e.valid == 0) return e;
    e.period_s = sum / e.valid;
    double ss = 0.0;
    for (const double x : d)
        if (x >= 0.5 * median && x <= 1.5 * median) ss += (x - e.period_s) * (x - e.period_s);
    e.sd_s = e.valid > 1 ? std::sqrt(ss / (e.valid - 1)) : 0.0;
    return e;
}

bool sync_sampling_done(const RefreshEstimate& e, const SyncCriteria& c) {
    return e.valid >= c.min_samples && e.sd_s < c.max_sd_s;
}

std::string sync_verdict(const RefreshEstimate& e, std::optional<double> nominal_hz, const SyncCriteria& c) {
    if (e.valid < c.min_samples)
        return fmt::format(
            "only {} of the flip intervals in {:g} s were regular ({} rejected as missed or doubled flips), fewer "
            "than the {} needed to trust the refresh period",
            e.valid, c.max_duration_s, e.rejected, c.min_samples);
    // Before the SD: flips at 3425 Hz are regular, and only their rate shows
    // that nothing waited for a refresh.
    if (!(e.hz() >= c.min_hz && e.hz() <= c.max_hz)) {
        const bool fast = e.hz() > c.max_hz;
        return fmt::format(
            "the flips came every {:.3f} ms ({:.1f} Hz), {} than any display refreshes ({:g} to {:g} Hz), so vertical "
            "sync seems {}: turn it on in the graphics driver's settings (Mesa: vblank_mode=3; NVIDIA: "
            "__GL_SYNC_TO_VBLANK=1) and in the compositor, or, on a display without a refresh such as Xvfb, pace the "
            "flips with --software-vsync HZ (testing only)",
            e.period_s * 1e3, e.hz(), fast ? "faster" : "slower", c.min_hz, c.max_hz,
            fast ? "off" : "broken (or the driver stalls every flip)");
    }
    if (!(e.sd_s < c.max_sd_s))
        return fmt::format(
            "the flip intervals vary too much to trust the frame timing: {:.3f} ms ± {:.3f} ms (SD) over {} flips, "
            "and the SD must be below {:.3f} ms (is vertical sync off, or a compositor in the way?)",
            e.period_s * 1e3, e.sd_s * 1e3, e.valid, c.max_sd_s * 1e3);
    if (nominal_hz && *nominal_hz > 0.0) {
        const double deviation = std::abs(e.hz() - *nominal_hz) / *nominal_hz;
        if (!(deviation < c.max_deviation))
            return fmt::format(
                "the measured refresh rate {:.3f} Hz differs from the nominal {:g} Hz by {:.1f} %, more than the "
                "{:g} % allowed (is vertical sync off?)",
                e.hz(), *nominal_hz, deviation * 100.0, c.max_deviation * 100.0);
    }
    return {};
}

int frames_for(double duration_s, double period_s, int min_frames) {
    if (!(period_s > 0.0)) throw std::invalid_argument("frames_for: the period must be > 0");
    const double n = std::round(duration_s / period_s);
    if (!(n < 1e9)) throw std::invalid_argument("frames_for: the duration is too long");
    return std::max(min_frames, static_cast<int>(std::max(0.0, n)));
}

int refreshes_in(double interval_s, double period_s) {
    return std::max(1, static_cast<int>(std::lround(interval_s / period_s)));
}

bool is_missed(double interval_s, double period_s) {
    return interval_s > 1.5 * period_s;
}

FrameClock::FrameClock(double period_s) : period_s_(period_s) {
    if (!(period_s > 0.0) || !std::isfinite(period_s))
        throw std::invalid_argument("FrameClock: the period must be > 0");
}

int FrameClock::flip(double t_s) {
    int refreshes = 0;
    bool missed = false;
    if (last_) {
        refreshes = refreshes_in(t_s - *last_, period_s_);
        missed = is_missed(t_s - *last_, period_s_);
    }
    if (!intervals_.empty()) {
        IntervalTiming& cur = intervals_.back();
        if (onset_pending_) {
            if (intervals_.size() >= 2 && intervals_[intervals_.size() - 2].offset_s == 0.0)
                intervals_[intervals_.size() - 2].offset_s = t_s;
            cur.onset_s = t_s;
            cur.late_onset = missed;
            onset_pending_ = false;
        }
        ++cur.flips;
        if (missed) {
            cur.missed = true;
            cur.dropped += refreshes - 1;
        }
    }
    last_ = t_s;
    return refreshes;
}

std::optional<double> FrameClock::predicted_next_flip_s() const {
    if (!last_) return std::nullopt;
    return *last_ + period_s_;
}

void FrameClock::begin(int frames) {
    if (frames < 1) throw std::invalid_argument("FrameClock::begin: an interval has at least one frame");
    IntervalTiming t;
    t.frames = frames;
    intervals_.push_back(t);
    onset_pending_ = true;
}

bool FrameClock::wants_flip() const {
    if (intervals_.empty()) return false;
    if (onset_pending_) return true;
    const IntervalTiming& cur = intervals_.back();
    // Refreshes from the onset to the next flip, as the clock predicts it.
    const double elapsed = (*last_ + period_s_ - cur.onset_s) / period_s_;
    return std::lround(elapsed) < cur.frames;
}

double FrameClock::next_flip_offset_s() const {
    if (intervals_.empty() || onset_pending_ || !last_) return 0.0;
    return *last_ + period_s_ - intervals_.back().onset_s;
}

void FrameClock::clear_intervals() {
    intervals_.clear();
    onset_pending_ = false;
}

}  // namespace atonlab::present
