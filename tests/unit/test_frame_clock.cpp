// The full-screen runner's frame clock (present/include/atonlab/present/frame_clock.h)
// and the flip loop every presenter runs (presenter.h), on synthetic
// timestamps: the refresh estimate and its SD against closed forms, the sync
// test's verdicts, durations in whole frames, missed deadlines and dropped
// refreshes, the predicted flip times an animated stimulus is sampled at, and
// the headless virtual display's exact k / rate flips.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "atonlab/present/frame_clock.h"
#include "atonlab/present/presenter.h"

namespace atonlab::present {
namespace {

constexpr double kP = 1.0 / 60.0;

std::vector<double> regular(int n, double period, double t0 = 10.0) {
    std::vector<double> t;
    for (int i = 0; i < n; ++i) t.push_back(t0 + i * period);
    return t;
}

TEST(RefreshEstimate, AlternatingJitterHasAKnownMeanAndSd) {
    // t_i = i P + (−1)^i δ: the intervals alternate P − 2δ, P + 2δ. Over an even
    // number of intervals the mean is P and the sample SD is 2δ √(n / (n − 1)).
    const double delta = 0.0002;
    std::vector<double> t;
    const int n = 101;  // 100 intervals
    for (int i = 0; i < n; ++i) t.push_back(5.0 + i * kP + (i % 2 ? -delta : delta));
    const RefreshEstimate e = estimate_refresh(t);
    EXPECT_EQ(e.valid, 100);
    EXPECT_EQ(e.rejected, 0);
    EXPECT_NEAR(e.period_s, kP, 1e-12);
    EXPECT_NEAR(e.sd_s, 2.0 * delta * std::sqrt(100.0 / 99.0), 1e-12);
    EXPECT_NEAR(e.hz(), 60.0, 1e-8);
}

TEST(RefreshEstimate, MissedAndDoubledFlipsAreRejected) {
    std::vector<double> t = regular(60, kP);
    // Two missed vblanks: intervals of two periods (every later flip shifts).
    for (std::size_t i = 20; i < t.size(); ++i) t[i] += kP;
    for (std::size_t i = 40; i < t.size(); ++i) t[i] += kP;
    EXPECT_EQ(estimate_refresh(t).rejected, 2);
    EXPECT_EQ(estimate_refresh(t).valid, 57);
    EXPECT_NEAR(estimate_refresh(t).period_s, kP, 1e-12);
    EXPECT_NEAR(estimate_refresh(t).sd_s, 0.0, 1e-12);
    // A swap that did not wait: an extra timestamp 1 ms after flip 9. Its 1 ms
    // interval is rejected; the P − 1 ms after it is within half a period and
    // is kept, so the mean over the 58 kept intervals is (57 P + P − 1 ms) / 58.
    t.insert(t.begin() + 10, t[9] + 0.001);
    const RefreshEstimate e = estimate_refresh(t);
    EXPECT_EQ(e.rejected, 3);
    EXPECT_EQ(e.valid, 57);
    EXPECT_NEAR(e.period_s, (56 * kP + (kP - 0.001)) / 57, 1e-12);
}

TEST(RefreshEstimate, TooFewTimestampsGiveNoEstimate) {
    EXPECT_EQ(estimate_refresh(std::vector<double>{}).valid, 0);
    EXPECT_EQ(estimate_refresh(std::vector<double>{1.0}).valid, 0);
    const RefreshEstimate two = estimate_refresh(std::vector<double>{1.0, 1.0 + kP});
    EXPECT_EQ(two.valid, 1);
    EXPECT_NEAR(two.period_s, kP, 1e-15);
    EXPECT_EQ(two.sd_s, 0.0);
}

TEST(SyncTest, PassesACleanDisplayAndRefusesWithOneSentence) {
    SyncCriteria c;  // 50 samples, SD < 1 ms, within 2 % of nominal
    const RefreshEstimate clean = estimate_refresh(regular(60, kP));
    EXPECT_TRUE(sync_sampling_done(clean, c));
    EXPECT_EQ(sync_verdict(clean, 60.0, c), "");
    EXPECT_EQ(sync_verdict(clean, std::nullopt, c), "") << "no nominal rate: nothing to compare";
    EXPECT_EQ(sync_verdict(clean, 0.0, c), "") << "a mode without a rate (Xvfb) says 0";

    // 60 Hz measured where the mode says 75 Hz: 20 % off.
    const std::string wrong_rate = sync_verdict(clean, 75.0, c);
    EXPECT_NE(wrong_rate.find("60.000 Hz"), std::string::npos) << wrong_rate;
    EXPECT_NE(wrong_rate.find("75 Hz"), std::string::npos) << wrong_rate;
    EXPECT_EQ(wrong_rate.find('\n'), std::string::npos);

    // Timestamps jittered uniformly by ±2 ms (a fixed pseudo-random sequence):
    // intervals P ± 4 ms, all kept, SD ≈ 4 ms / √6 ≈ 1.6 ms, above 1 ms.
    std::vector<double> t;
    std::uint32_t lcg = 12345;
    for (int i = 0; i < 200; ++i) {
        lcg = lcg * 1664525u + 1013904223u;
        t.push_back(i * kP + 0.004 * (lcg / 4294967296.0 - 0.5));
    }
    const RefreshEstimate jittery = estimate_refresh(t);
    EXPECT_EQ(jittery.rejected, 0);
    EXPECT_GT(jittery.sd_s, 0.0012);
    EXPECT_LT(jittery.sd_s, 0.0021);
    EXPECT_FALSE(sync_sampling_done(jittery, c));
    EXPECT_NE(sync_verdict(jittery, 60.0, c).find("vary too much"), std::string::npos);

    // 20 intervals only.
    const RefreshEstimate few = estimate_refresh(regular(21, kP));
    EXPECT_FALSE(sync_sampling_done(few, c));
    EXPECT_NE(sync_verdict(few, 60.0, c).find("only 20"), std::string::npos) << sync_verdict(few, 60.0, c);

    // A relaxed SD (a virtual display paced by a timer) lets the jittery one pass.
    SyncCriteria relaxed = c;
    relaxed.max_sd_s = 0.01;
    EXPECT_EQ(sync_verdict(jittery, 60.0, relaxed), "");
}

TEST(SyncTest, RefusesFlipRatesNoDisplayRefreshesAtAndSaysVsyncSeemsOff) {
    SyncCriteria c;  // plausible 20 to 500 Hz
    // Flips that did not wait for a refresh: 0.3 ms apart (3333 Hz; Xvfb
    // without --software-vsync measured 0.29 ms), 1 ms (1000 Hz); and a rate no
    // display refreshes at, 10 Hz. Regular, so the SD test alone would pass them.
    for (const double period : {0.0003, 0.00029, 0.001, 0.1}) {
        const RefreshEstimate e = estimate_refresh(regular(100, period));
        ASSERT_EQ(e.valid, 99);
        ASSERT_LT(e.sd_s, c.max_sd_s);
        for (const std::optional<double> nominal : {std::optional<double>(), std::optional<double>(1.0 / period)}) {
            const std::string why = sync_verdict(e, nominal, c);
            EXPECT_NE(why.find("vertical sync seems"), std::string::npos) << period << ": " << why;
            EXPECT_NE(why.find("--software-vsync"), std::string::npos) << why;
            EXPECT_NE(why.find("20 to 500 Hz"), std::string::npos) << why;
            EXPECT_EQ(why.find('\n'), std::string::npos);
        }
    }
    EXPECT_NE(sync_verdict(estimate_refresh(regular(100, 0.0003)), std::nullopt, c).find("faster"), std::string::npos);
    EXPECT_NE(sync_verdict(estimate_refresh(regular(100, 0.1)), std::nullopt, c).find("slower"), std::string::npos);

    // Real refresh rates pass, with or without a nominal rate, jittered by
    // ±0.1 ms (intervals P ± 0.2 ms, SD 0.2 ms, under the 1 ms limit; over an
    // even number of intervals the mean is P exactly).
    for (const double hz : {60.0, 120.0, 144.0, 240.0}) {
        std::vector<double> t;
        for (int i = 0; i < 101; ++i) t.push_back(3.0 + i / hz + (i % 2 ? 1e-4 : -1e-4));
        const RefreshEstimate e = estimate_refresh(t);
        EXPECT_NEAR(e.hz(), hz, 1e-6 * hz);
        EXPECT_EQ(sync_verdict(e, std::nullopt, c), "") << hz;
        EXPECT_EQ(sync_verdict(e, hz, c), "") << hz;
    }
    // Just inside the range accepted, just beyond it refused (1 % either side:
    // the rate from summed intervals is exact to ~1e-12, not to the last bit).
    EXPECT_EQ(sync_verdict(estimate_refresh(regular(100, 1.0 / 495.0)), std::nullopt, c), "");
    EXPECT_EQ(sync_verdict(estimate_refresh(regular(100, 1.0 / 20.2)), std::nullopt, c), "");
    EXPECT_NE(sync_verdict(estimate_refresh(regular(100, 1.0 / 505.0)), std::nullopt, c), "");
    EXPECT_NE(sync_verdict(estimate_refresh(regular(100, 1.0 / 19.8)), std::nullopt, c), "");
}

TEST(FrameClock, DurationsAreWholeRefreshes) {
    EXPECT_EQ(frames_for(0.5, kP), 30);
    EXPECT_EQ(frames_for(0.51, kP), 31);          // 30.6 frames
    EXPECT_EQ(frames_for(0.505, kP), 30);         // 30.3
    EXPECT_EQ(frames_for(0.5, 1.0 / 59.94), 30);  // 29.97
    EXPECT_EQ(frames_for(0.5, 1.0 / 144.0), 72);
    EXPECT_EQ(frames_for(0.004, kP), 0);
    EXPECT_EQ(frames_for(0.004, kP, 1), 1) << "a stimulus is shown for at least one refresh";
    EXPECT_EQ(frames_for(0.0, kP), 0);
    EXPECT_EQ(refreshes_in(kP, kP), 1);
    EXPECT_EQ(refreshes_in(2.9 * kP, kP), 3);
    EXPECT_EQ(refreshes_in(0.2 * kP, kP), 1);
    EXPECT_FALSE(is_missed(1.49 * kP, kP));
    EXPECT_TRUE(is_missed(1.51 * kP, kP));
}

TEST(FrameClock, OnTimeFlipsGiveExactOnsetsAndOffsets) {
    FrameClock c(kP);
    const double t0 = 100.0;
    c.begin(3);
    int flips = 0;
    double t = t0;
    std::vector<double> offsets;
    while (c.wants_flip()) {
        offsets.push_back(c.next_flip_offset_s());
        c.flip(t);
        t += kP;
        ++flips;
    }
    EXPECT_EQ(flips, 3);
    ASSERT_EQ(offsets.size(), 3u);
    // The predicted time of each flip within the interval: 0, P, 2P.
    EXPECT_DOUBLE_EQ(offsets[0], 0.0);
    EXPECT_NEAR(offsets[1], kP, 1e-12);
    EXPECT_NEAR(offsets[2], 2 * kP, 1e-12);
    c.begin(2);
    while (c.wants_flip()) {
        c.flip(t);
        t += kP;
    }
    c.begin(1);
    c.flip(t);
    const auto& iv = c.intervals();
    ASSERT_EQ(iv.size(), 3u);
    EXPECT_DOUBLE_EQ(iv[0].onset_s, t0);
    EXPECT_NEAR(iv[0].duration_s(), 3 * kP, 1e-12);
    EXPECT_NEAR(iv[1].duration_s(), 2 * kP, 1e-12);
    EXPECT_EQ(iv[1].flips, 2);
    for (const IntervalTiming& i : iv) {
        EXPECT_FALSE(i.missed);
        EXPECT_EQ(i.dropped, 0);
    }
}

TEST(FrameClock, AStallIsAMissedDeadlineAndTheOffsetStaysOnTimeWherePossible) {
    // 10 frames; after the onset flip the loop stalls 4 refreshes: the second
    // flip comes at onset + 5P (4 refreshes dropped). The interval then needs
    // flips until the one predicted at onset + 10P, which is the offset.
    FrameClock c(kP);
    c.begin(10);
    const double on = 7.0;
    c.flip(on);
    ASSERT_TRUE(c.wants_flip());
    c.flip(on + 5 * kP);
    int more = 0;
    double t = on + 5 * kP;
    while (c.wants_flip()) {
        t += kP;
        c.flip(t);
        ++more;
    }
    EXPECT_EQ(more, 4) << "flips at 6P..9P; the next one (10P) is the offset";
    c.begin(1);
    c.flip(t + kP);
    const IntervalTiming& i = c.intervals().front();
    EXPECT_TRUE(i.missed);
    EXPECT_FALSE(i.late_onset);
    EXPECT_EQ(i.dropped, 4);
    EXPECT_EQ(i.flips, 6);
    EXPECT_NEAR(i.duration_s(), 10 * kP, 1e-12) << "the offset is on time";
}

TEST(FrameClock, ALateOnsetIsChargedToTheIntervalItStarts) {
    FrameClock c(kP);
    c.begin(2);  // the fixation
    c.flip(0.0);
    c.flip(kP);
    c.begin(2);  // the stimulus: its onset is 3 refreshes after the last fixation flip
    c.flip(4 * kP);
    EXPECT_TRUE(c.intervals()[1].late_onset);
    EXPECT_TRUE(c.intervals()[1].missed);
    EXPECT_EQ(c.intervals()[1].dropped, 2);
    EXPECT_NEAR(c.intervals()[0].duration_s(), 4 * kP, 1e-12) << "the fixation stayed up until it";
    EXPECT_FALSE(c.intervals()[0].missed);
}

TEST(FrameClock, AfterIdlingTheFirstFlipIsNotLate) {
    FrameClock c(kP);
    c.begin(1);
    c.flip(1.0);
    c.idle();  // the screen sat still for a key
    c.clear_intervals();
    c.begin(3);
    c.flip(9.0);
    EXPECT_FALSE(c.intervals()[0].missed);
    EXPECT_EQ(c.intervals()[0].dropped, 0);
}

// --- The flip loop, on the virtual (headless) display ---------------------------

Screen blank() {
    return Screen{};
}

TEST(VirtualPresenter, FlipsLandOnWholeRefreshesOfTheNominalRate) {
    VirtualPresenter v(60.0, 320, 180);
    v.advance_to(30.0);  // after a 30 s adaptation
    // A two-interval trial: fixation 0.8 s, 0.5 s, blank 0.5 s, 0.5 s.
    const std::vector<Step> steps{{blank(), 48, false}, {blank(), 30, true}, {blank(), 30, true}, {blank(), 30, true}};
    const Played p = v.play(steps, blank());
    ASSERT_EQ(p.intervals.size(), 5u);
    EXPECT_EQ(p.step_of, (std::vector<std::size_t>{0, 1, 2, 3, 4}));
    // k / 60 exactly: 30.8 s is refresh 1848.
    EXPECT_EQ(p.intervals[0].onset_s, 1800.0 / 60.0);
    EXPECT_EQ(p.intervals[1].onset_s, 1848.0 / 60.0);
    EXPECT_EQ(p.intervals[1].onset_s, 30.8);
    EXPECT_EQ(p.intervals[4].onset_s, 1938.0 / 60.0);
    for (std::size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(p.intervals[i].flips, steps[i].frames) << i;
        EXPECT_FALSE(p.intervals[i].missed) << i;
        EXPECT_NEAR(p.intervals[i].duration_s(), steps[i].frames / 60.0, 1e-12) << i;
    }
    EXPECT_EQ(v.now_s(), 1938.0 / 60.0);
    // The next sequence cannot flip on the same refresh as the last one.
    const Played q = v.play(std::vector<Step>{{blank(), 1, true}}, blank());
    EXPECT_EQ(q.intervals[0].onset_s, 1939.0 / 60.0);
}

TEST(VirtualPresenter, AnInjectedStallDropsThatManyRefreshes) {
    VirtualPresenter v(60.0, 320, 180);
    PlayOptions o;
    o.stall_frames = 5;
    std::vector<std::size_t> onsets;
    o.after_onset = [&](std::size_t step) { onsets.push_back(step); };
    const std::vector<Step> steps{{blank(), 10, false}, {blank(), 30, true}, {blank(), 30, true}};
    const Played p = v.play(steps, blank(), o);
    EXPECT_EQ(onsets, (std::vector<std::size_t>{1, 2}));
    EXPECT_FALSE(p.intervals[0].missed) << "the fixation is not stalled";
    EXPECT_TRUE(p.intervals[1].missed);
    EXPECT_EQ(p.intervals[1].dropped, 5);
    EXPECT_FALSE(p.intervals[1].late_onset);
    EXPECT_NEAR(p.intervals[1].duration_s(), 0.5, 1e-12) << "the offset stays on its refresh";
    EXPECT_FALSE(p.intervals[2].missed) << "the stall happens once";
}

TEST(VirtualPresenter, StopEndsALoopAndNoPersonEverAnswers) {
    VirtualPresenter v(100.0, 64, 64);
    int flips = 0;
    PlayOptions o;
    o.loop = true;
    o.stop = [&](const InputQueue&) { return ++flips == 25; };
    const Played p = v.play(std::vector<Step>{{blank(), 10, true}, {blank(), 10, true}}, blank(), o);
    EXPECT_TRUE(p.stopped);
    EXPECT_EQ(p.step_of, (std::vector<std::size_t>{0, 1, 0, 2}));
    EXPECT_EQ(p.intervals[2].flips, 5);
    const double before = v.now_s();
    EXPECT_FALSE(v.wait(nullptr, 0.0, before + 2.0, [](const InputEvent&) { return true; }).has_value());
    EXPECT_DOUBLE_EQ(v.now_s(), before + 2.0);
}

}  // namespace
}  // namespace atonlab::present
