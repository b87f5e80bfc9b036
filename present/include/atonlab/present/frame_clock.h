#pragma once
// The frame clock of the full-screen runner (docs/running.md, "Timing"): the
// refresh period measured from flip timestamps, durations counted in whole
// refreshes, missed deadlines detected, and the moment the next flip will be
// seen predicted. Pure arithmetic on timestamps (seconds on one monotonic
// clock), so every rule is unit-tested with synthetic timestamps
// (tests/unit/test_frame_clock.cpp); the presenters feed it real (GLFW) or
// virtual (headless) flips.
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace atonlab::present {

/// The refresh period estimated from consecutive flip timestamps, after
/// Psychtoolbox's sync test (Screen('GetFlipInterval'): the mean of many
/// flip-to-flip intervals, with their standard deviation as the quality).
struct RefreshEstimate {
    double period_s = 0.0;  ///< mean of the kept intervals, s
    double sd_s = 0.0;      ///< their sample standard deviation, s
    int valid = 0;          ///< intervals kept
    int rejected = 0;       ///< intervals rejected: outside [0.5, 1.5] × the median (a missed or doubled flip)
    double hz() const noexcept { return period_s > 0.0 ? 1.0 / period_s : 0.0; }
};

/// Intervals between consecutive timestamps; an interval outside [0.5, 1.5]
/// times their median is a missed refresh (or a swap that did not wait) and is
/// rejected; the mean and the sample SD (n − 1) of the rest. Fewer than two
/// timestamps: an empty estimate (valid = 0).
RefreshEstimate estimate_refresh(std::span<const double> flip_times_s);

/// When the start-up measurement stops and whether it passes. Defaults:
/// Psychtoolbox's sync test asks for at least 50 valid samples within 5 s; the
/// SD and the agreement with the mode's nominal rate are ours (docs/running.md).
struct SyncCriteria {
    int min_samples = 50;
    double max_sd_s = 0.001;      ///< the kept intervals' SD must be below this, s
    double max_deviation = 0.02;  ///< |measured − nominal| / nominal must be below this
    double max_duration_s = 5.0;  ///< stop sampling after this long, pass or fail
    /// The plausible refresh rates, Hz: displays refresh at 24 to 360 Hz
    /// (500 Hz panels exist); a measured rate outside this range means the
    /// flips are not tied to a refresh (vertical sync off, a virtual display)
    /// or a driver stalls every flip.
    double min_hz = 20.0;
    double max_hz = 500.0;
};


/// Sampling may stop: enough valid samples with an SD already below the maximum.
bool sync_sampling_done(const RefreshEstimate& e, const SyncCriteria& c);

/// Empty when the measurement passes; otherwise one sentence saying why.
/// nominal_hz: the display mode's refresh rate, when it has one (> 0).
/// A rate outside [c.min_hz, c.max_hz] is refused first, whatever the mode
/// says: flips faster than any display refreshes (or slower) mean vertical
/// sync is off or broken, and the sentence says how to turn it on.
std::string sync_verdict(const RefreshEstimate& e, std::optional<double> nominal_hz, const SyncCriteria& c);

/// Whole refreshes for a duration: round(duration / period), at least `min_frames`.
int frames_for(double duration_s, double period_s, int min_frames = 0);

/// Refreshes between two flips `interval_s` apart: round(interval / period), at least 1.
int refreshes_in(double interval_s, double period_s);

/// A flip interval longer than 1.5 periods: at least one refresh was missed.
bool is_missed(double interval_s, double period_s);

/// The timing of one run of content (an interval of a stimulus, a blank, the
/// fixation) as the flips saw it.
struct IntervalTiming {
    int frames = 0;           ///< refreshes asked for
    int flips = 0;            ///< flips made while it was up
    double onset_s = 0.0;     ///< timestamp of its first flip
    double offset_s = 0.0;    ///< timestamp of the flip that replaced it (0 until then)
    int dropped = 0;          ///< refreshes missed at its flips (its onset flip included)
    bool missed = false;      ///< a flip of it came > 1.5 periods after the one before
    bool late_onset = false;  ///< its onset flip itself was late
    double duration_s() const noexcept { return offset_s > onset_s ? offset_s - onset_s : 0.0; }
};

/// Counts refreshes for a sequence of intervals, flip by flip.
///
/// begin(frames) asks for an interval of `frames` refreshes starting at the
/// next flip; after each flip() wants_flip() says whether the next flip still
/// belongs to it. An interval ends when the next flip is predicted at or after
/// onset + frames × period: a late flip (a stall) shortens the rest of the
/// interval so that its offset stays on time where it can, instead of showing
/// every planned flip late.
class FrameClock {
public:
    explicit FrameClock(double period_s);

    double period_s() const noexcept { return period_s_; }
    /// Records a flip seen at t_s. Returns the refreshes since the previous
    /// flip (0 for the first). The interval in progress (if any) is charged:
    /// its onset for the first flip after begin(), a missed deadline and the
    /// refreshes dropped when the flip came more than 1.5 periods late. The
    /// previous interval, if this flip replaced it, gets its offset.
    int flip(double t_s);

    /// The screen sat still (no flips were due, e.g. while waiting for a
    /// key): the next flip starts afresh and cannot be late.
    void idle() noexcept { last_.reset(); }

    bool has_flipped() const noexcept { return last_.has_value(); }
    double last_flip_s() const noexcept { return last_.value_or(0.0); }
    /// When the next flip will be seen: the last flip + one period (the first
    /// flip: unknown, nullopt).
    std::optional<double> predicted_next_flip_s() const;

    /// Starts an interval of `frames` (≥ 1) refreshes at the next flip; the
    /// interval before it, if any, ends at that flip.
    void begin(int frames);
    /// The next flip still belongs to the current interval (true before its onset).
    bool wants_flip() const;
    /// The time within the current interval at which the next flip will be
    /// seen (0 for its onset flip): where an animated stimulus is sampled.
    double next_flip_offset_s() const;
    /// Every interval begun, in order (the last is the current one); an
    /// interval's offset is set by the first flip of the next.
    const std::vector<IntervalTiming>& intervals() const noexcept { return intervals_; }
    /// Forgets the intervals (not the last flip: the next onset is still
    /// judged against it).
    void clear_intervals();

private:
    double period_s_;
    std::optional<double> last_;
    bool onset_pending_ = false;
    std::vector<IntervalTiming> intervals_;
};

}  // namespace atonlab::present
