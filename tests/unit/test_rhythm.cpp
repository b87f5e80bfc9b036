// Light characters -> B(t). Expected on/off patterns are written out by hand
// from the nominal durations of docs/light-characters.md (flash Fl 0.5 s,
// eclipse in a group 1 s, LFl 2 s, Q 0.3/0.7 s, VQ 0.2/0.3 s, UQ 0.1/0.15 s,
// Oc eclipse 1 s, Morse dot 0.5 s / dash 1.5 s), and from IALA's published
// examples Oc(2) 13s = [1;1;1;10] and Oc(2+1) 12s = [1;1;1;4;1;4] (eclipse first).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/rhythm.h"

namespace {

using atonlab::InputError;
using atonlab::stimuli::parse_rhythm;
using atonlab::stimuli::Rhythm;
using atonlab::stimuli::rhythm_level;
using atonlab::stimuli::RhythmKnot;
using atonlab::stimuli::RhythmTiming;
using atonlab::stimuli::tabulate;

using Intervals = std::vector<std::pair<double, double>>;

/// Lit intervals in [0, period) read from the knots: where B(t) crosses 1/2.
/// With ramps centred on the nominal edges these are the nominal edges exactly.
Intervals lit_from_knots(const std::vector<RhythmKnot>& k, double period) {
    struct Edge {
        double t;
        bool rising;
    };
    std::vector<Edge> edges;
    for (std::size_t i = 1; i < k.size(); ++i) {
        const RhythmKnot& a = k[i - 1];
        const RhythmKnot& b = k[i];
        const bool rising = a.level <= 0.5 && 0.5 < b.level;
        const bool falling = a.level >= 0.5 && 0.5 > b.level;
        if (!rising && !falling) continue;
        const double t = b.t_s == a.t_s ? a.t_s : a.t_s + (0.5 - a.level) / (b.level - a.level) * (b.t_s - a.t_s);
        edges.push_back({t, rising});
    }
    Intervals out;
    double start = -1;
    for (const Edge& e : edges) {
        if (e.rising) {
            start = e.t;
        } else {
            const double a = start < 0 ? 0.0 : start;
            if (e.t > a) out.push_back({a, e.t});
            start = -1;
        }
    }
    if (start >= 0) out.push_back({start, period});
    return out;
}

/// Lit intervals found by sampling B(t) every dt seconds (threshold 1/2).
Intervals lit_by_sampling(const Rhythm& r, std::size_t channel, double dt) {
    Intervals out;
    const int n = static_cast<int>(std::lround(r.period_s / dt));
    bool on = false;
    double start = 0;
    for (int i = 0; i < n; ++i) {
        const double t = (i + 0.5) * dt;
        const bool lit = r.level(t, channel) >= 0.5;
        if (lit && !on) start = t - dt / 2;
        if (!lit && on) out.push_back({start, t - dt / 2});
        on = lit;
    }
    if (on) out.push_back({start, r.period_s});
    return out;
}

void expect_intervals(const Intervals& got, const Intervals& want, double tol) {
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
        EXPECT_NEAR(got[i].first, want[i].first, tol) << "interval " << i;
        EXPECT_NEAR(got[i].second, want[i].second, tol) << "interval " << i;
    }
}

double lit_total(const Intervals& v) {
    double s = 0;
    for (const auto& [a, b] : v) s += b - a;
    return s;
}

/// Knot invariants of the header: first at 0, last at period with the same
/// level, sorted, levels in [0, 1].
void expect_well_formed(const Rhythm& r) {
    ASSERT_FALSE(r.channels.empty());
    for (const auto& ch : r.channels) {
        ASSERT_GE(ch.knots.size(), 1u);
        EXPECT_EQ(ch.knots.front().t_s, 0.0);
        EXPECT_EQ(ch.knots.back().t_s, r.period_s);
        EXPECT_EQ(ch.knots.front().level, ch.knots.back().level);
        for (std::size_t i = 0; i < ch.knots.size(); ++i) {
            EXPECT_GE(ch.knots[i].level, 0.0);
            EXPECT_LE(ch.knots[i].level, 1.0);
            if (i > 0) {
                EXPECT_LE(ch.knots[i - 1].t_s, ch.knots[i].t_s);
            }
        }
    }
}

struct Case {
    const char* text;
    double period;
    Intervals lit;  ///< channel 0
};

// Each row: the on/off pattern derived by hand from the documented durations.
const std::vector<Case> cases = {
    {"Fl 5s", 5, {{0, 0.5}}},
    {"Fl(2) 10s", 10, {{0, 0.5}, {1.5, 2.0}}},  // two flashes, then 8 s dark
    {"Fl(3) 10s", 10, {{0, 0.5}, {1.5, 2.0}, {3.0, 3.5}}},
    {"Fl(2+1) 10s", 10, {{0, 0.5}, {1.5, 2.0}, {5.75, 6.25}}},  // (10 - 2.5) / 2 = 3.75 after each group
    {"LFl 10s", 10, {{0, 2}}},
    {"Q", 1, {{0, 0.3}}},                              // 60/min
    {"VQ", 0.5, {{0, 0.2}}},                           // 120/min
    {"UQ", 0.25, {{0, 0.1}}},                          // 240/min
    {"Q(3) 10s", 10, {{0, 0.3}, {1, 1.3}, {2, 2.3}}},  // east cardinal
    {"VQ(3) 5s", 5, {{0, 0.2}, {0.5, 0.7}, {1.0, 1.2}}},
    {"Q(6)+LFl 15s", 15, {{0, .3}, {1, 1.3}, {2, 2.3}, {3, 3.3}, {4, 4.3}, {5, 5.3}, {6, 8}}},  // south cardinal
    {"VQ(6)+LFl 10s", 10, {{0, .2}, {.5, .7}, {1, 1.2}, {1.5, 1.7}, {2, 2.2}, {2.5, 2.7}, {3, 5}}},
    {"IQ 10s", 10, {{0, .3}, {1, 1.3}, {2, 2.3}, {3, 3.3}, {4, 4.3}, {5, 5.3}, {6, 6.3}}},  // 3.7 s interruption
    {"Oc 4s", 4, {{1, 4}}},
    {"Oc(2) 13s", 13, {{1, 2}, {3, 13}}},            // IALA example [1;1;1;10]
    {"Oc(2+1) 12s", 12, {{1, 2}, {3, 7}, {8, 12}}},  // IALA example [1;1;1;4;1;4]
    {"Oc(3) 10s", 10, {{1, 2}, {3, 4}, {5, 10}}},
    {"Iso 4s", 4, {{0, 2}}},
    {"Mo(U) 15s", 15, {{0, 0.5}, {1.0, 1.5}, {2.0, 3.5}}},                  // dot dot dash
    {"Mo(A) 6s", 6, {{0, 0.5}, {1.0, 2.5}}},                                // dot dash, 3.5 s eclipse
    {"Mo(AR) 15s", 15, {{0, .5}, {1, 2.5}, {4, 4.5}, {5, 6.5}, {7, 7.5}}},  // .- gap(1.5) .-.
};

TEST(Rhythm, EachCharacterHasItsOnOffPatternByKnots) {
    for (const Case& c : cases) {
        SCOPED_TRACE(c.text);
        const Rhythm r = parse_rhythm(c.text);
        expect_well_formed(r);
        EXPECT_DOUBLE_EQ(r.period_s, c.period);
        ASSERT_EQ(r.channels.size(), 1u);
        expect_intervals(lit_from_knots(r.channels[0].knots, r.period_s), c.lit, 1e-9);
    }
}

TEST(Rhythm, EachCharacterHasItsOnOffPatternBySampling) {
    for (const Case& c : cases) {
        SCOPED_TRACE(c.text);
        const Rhythm r = parse_rhythm(c.text);
        const double dt = 1e-3;
        expect_intervals(lit_by_sampling(r, 0, dt), c.lit, dt);
    }
}

TEST(Rhythm, DutyCycleIsNominalLitTimeOverPeriodWhateverTheRamp) {
    for (const double ramp : {0.0, 0.02, 0.09}) {
        for (const Case& c : cases) {
            SCOPED_TRACE(std::string(c.text) + " ramp " + std::to_string(ramp));
            const Rhythm r = parse_rhythm(c.text, RhythmTiming{ramp});
            EXPECT_NEAR(r.duty_cycle(), lit_total(c.lit) / c.period, 1e-12);
        }
    }
    // Spelled out for a few: Fl(2) 10s lit 2 x 0.5 s; Q(6)+LFl 15s lit 6 x 0.3 + 2 s.
    EXPECT_NEAR(parse_rhythm("Fl(2) 10s").duty_cycle(), 0.1, 1e-12);
    EXPECT_NEAR(parse_rhythm("Q(6)+LFl 15s").duty_cycle(), 3.8 / 15, 1e-12);
    EXPECT_NEAR(parse_rhythm("Iso 4s").duty_cycle(), 0.5, 1e-12);
    EXPECT_NEAR(parse_rhythm("Oc 4s").duty_cycle(), 0.75, 1e-12);
}

TEST(Rhythm, RampsAreCentredSoAFlashIntegratesToItsNominalDuration) {
    // Fl(2) 10s with a deliberately long 0.2 s ramp: the first flash is nominally
    // [0, 0.5], the second [1.5, 2.0]. Integrate B over [-0.3, 1.0] (first flash,
    // its rise straddles t = 0) and [1.0, 2.3] (second): each is 0.5 s.
    const Rhythm r = parse_rhythm("Fl(2) 10s", RhythmTiming{0.2});
    auto integrate = [&](double t0, double t1) {
        const int n = 200000;
        const double h = (t1 - t0) / n;
        double s = 0.5 * (r.level(t0) + r.level(t1));
        for (int i = 1; i < n; ++i) s += r.level(t0 + i * h);
        return s * h;
    };
    EXPECT_NEAR(integrate(-0.3, 1.0), 0.5, 1e-7);
    EXPECT_NEAR(integrate(1.0, 2.3), 0.5, 1e-7);
    // Centred: half level at the nominal edge, off/on at edge -/+ ramp/2.
    EXPECT_NEAR(r.level(0.0), 0.5, 1e-12);
    EXPECT_NEAR(r.level(-0.1), 0.0, 1e-12);
    EXPECT_NEAR(r.level(0.1), 1.0, 1e-12);
    EXPECT_NEAR(r.level(0.05), 0.75, 1e-12);
    EXPECT_NEAR(r.level(0.5), 0.5, 1e-12);
    EXPECT_NEAR(r.level(0.6), 0.0, 1e-12);
    EXPECT_NEAR(r.level(1.5), 0.5, 1e-12);
}

TEST(Rhythm, ZeroRampGivesJumpsTakingTheLevelAfterTheEdge) {
    const Rhythm r = parse_rhythm("Iso 4s", RhythmTiming{0.0});
    const std::vector<float> t = tabulate(r.channels[0], r.period_s, 8);  // t = 0, 0.5, ..., 3.5
    const std::vector<float> want{1, 1, 1, 1, 0, 0, 0, 0};
    EXPECT_EQ(t, want);
    EXPECT_EQ(r.level(1.999999), 1.0);
    EXPECT_EQ(r.level(2.0), 0.0);
    EXPECT_EQ(r.level(3.999999), 0.0);
    EXPECT_EQ(r.level(4.0), 1.0);
}

TEST(Rhythm, MorseUIsDotDotDash) {
    const Rhythm r = parse_rhythm("Mo(U) 15s");
    const Intervals lit = lit_from_knots(r.channels[0].knots, r.period_s);
    ASSERT_EQ(lit.size(), 3u);
    const double dot = lit[0].second - lit[0].first;
    EXPECT_NEAR(dot, 0.5, 1e-9);
    EXPECT_NEAR(lit[1].second - lit[1].first, dot, 1e-9);
    EXPECT_NEAR(lit[2].second - lit[2].first, 3 * dot, 1e-9);  // a dash is three dots
    EXPECT_NEAR(lit[1].first - lit[0].second, dot, 1e-9);      // one dot between elements
}

TEST(Rhythm, GroupingOfOc21IsTwoEclipsesThenOne) {
    const Rhythm r = parse_rhythm("Oc(2+1) 12s");
    // Dark intervals from the complement of the lit ones: [0,1], [2,3], then [7,8].
    const Intervals lit = lit_from_knots(r.channels[0].knots, r.period_s);
    ASSERT_EQ(lit.size(), 3u);
    const double gap_in_group = lit[0].first - 0.0;       // first eclipse
    const double between = lit[1].first - lit[0].second;  // second eclipse, 1 s of light before it
    const double third = lit[2].first - lit[1].second;    // the lone eclipse
    EXPECT_NEAR(gap_in_group, 1, 1e-9);
    EXPECT_NEAR(between, 1, 1e-9);
    EXPECT_NEAR(third, 1, 1e-9);
    EXPECT_NEAR(lit[0].second - lit[0].first, 1, 1e-9);  // short light inside the group of 2
    EXPECT_NEAR(lit[1].second - lit[1].first, 4, 1e-9);  // long light after each group
    EXPECT_NEAR(lit[2].second - lit[2].first, 4, 1e-9);
}

TEST(Rhythm, AlternatingWhiteRedIsTwoComplementaryChannels) {
    const Rhythm r = parse_rhythm("Al.WR 4s");
    expect_well_formed(r);
    ASSERT_EQ(r.channels.size(), 2u);
    EXPECT_EQ(r.channels[0].colour, "W");
    EXPECT_EQ(r.channels[1].colour, "R");
    expect_intervals(lit_from_knots(r.channels[0].knots, 4), {{0, 2}}, 1e-9);
    expect_intervals(lit_from_knots(r.channels[1].knots, 4), {{2, 4}}, 1e-9);
    for (int i = 0; i <= 4000; ++i) {
        const double t = i * 1e-3 - 0.5;
        EXPECT_NEAR(r.level(t, 0) + r.level(t, 1), 1.0, 1e-12) << "t = " << t;
    }
    EXPECT_NEAR(r.duty_cycle(0), 0.5, 1e-12);
    EXPECT_NEAR(r.duty_cycle(1), 0.5, 1e-12);
    EXPECT_TRUE(r.chart_colours.empty());
}

TEST(Rhythm, AlternatingFlashingAndOcculting) {
    const Rhythm fl = parse_rhythm("Al.Fl.WR 5s");
    ASSERT_EQ(fl.channels.size(), 2u);
    expect_intervals(lit_from_knots(fl.channels[0].knots, 5), {{0, 0.5}}, 1e-9);
    expect_intervals(lit_from_knots(fl.channels[1].knots, 5), {{2.5, 3.0}}, 1e-9);
    EXPECT_EQ(fl.text, "Al.Fl.WR 5s");

    // Each colour gets 3 s: eclipse 1 s then light 2 s.
    const Rhythm oc = parse_rhythm("Al.Oc.WG 6s");
    ASSERT_EQ(oc.channels.size(), 2u);
    EXPECT_EQ(oc.channels[1].colour, "G");
    expect_intervals(lit_from_knots(oc.channels[0].knots, 6), {{1, 3}}, 1e-9);
    expect_intervals(lit_from_knots(oc.channels[1].knots, 6), {{4, 6}}, 1e-9);

    // A repeated colour shares one channel: W lit in slots 1 and 3.
    const Rhythm wrw = parse_rhythm("Al.WRW 6s");
    ASSERT_EQ(wrw.channels.size(), 2u);
    EXPECT_NEAR(wrw.duty_cycle(0), 2.0 / 3, 1e-12);
    EXPECT_NEAR(wrw.duty_cycle(1), 1.0 / 3, 1e-12);
    const Rhythm bu = parse_rhythm("Al.BuY 2s");
    EXPECT_EQ(bu.channels[0].colour, "Bu");
    EXPECT_EQ(bu.channels[1].colour, "Y");
}

TEST(Rhythm, FixedLightIsAlwaysOn) {
    const Rhythm r = parse_rhythm("F");
    EXPECT_EQ(r.period_s, 0.0);
    ASSERT_EQ(r.channels.size(), 1u);
    ASSERT_EQ(r.channels[0].knots.size(), 1u);
    for (double t : {-1e9, -1.0, 0.0, 0.3, 1e12}) EXPECT_EQ(r.level(t), 1.0);
    EXPECT_EQ(r.duty_cycle(), 1.0);
    EXPECT_EQ(parse_rhythm("F R").chart_colours, "R");
    // Period 0: the first knot's level, whatever t.
    EXPECT_EQ(rhythm_level({{0, 0.7}}, 0, 123.0), 0.7);
}

TEST(Rhythm, PeriodicInTimeIncludingNegativeAndHugeTimes) {
    const Rhythm r = parse_rhythm("Fl(2) 10s");
    for (double t : {0.0, 0.25, 1.49, 1.75, 3.3, 9.99}) {
        for (int k = -3; k <= 3; ++k) EXPECT_NEAR(r.level(t + 10.0 * k), r.level(t), 1e-12) << t << " " << k;
    }
    EXPECT_EQ(r.level(-8.25), 1.0);            // -8.25 + 10 = 1.75: inside the second flash
    EXPECT_EQ(r.level(-0.25), 0.0);            // 9.75: final eclipse
    EXPECT_NEAR(r.level(-1e-30), 0.5, 1e-12);  // just before the wrap: the centred rise
    EXPECT_EQ(r.level(5e9 + 0.25), 1.0);       // exact double, phase 0.25

    // Oc 3s: dark [0, 1], lit [1, 3]. 1e17 + 16 is an exact double whose phase is
    // 2 s (1e17 = 1 mod 3, 16 = 1 mod 3); t - 3 floor(t / 3) in double gives -4
    // there (t / 3 rounds up by 1.33), so only an exact reduction finds the light on.
    const Rhythm oc = parse_rhythm("Oc 3s");
    EXPECT_EQ(oc.level(1e17 + 16), 1.0);
    EXPECT_NEAR(oc.level(-(1e17 + 16)), 0.5, 1e-12);  // phase -2 = 1 mod 3: the centred edge
    EXPECT_EQ(oc.level(std::nan("")), oc.channels[0].knots[0].level);
    EXPECT_EQ(oc.level(INFINITY), oc.channels[0].knots[0].level);
}

TEST(Rhythm, TabulateSamplesOnePeriodUniformly) {
    const Rhythm r = parse_rhythm("Fl(2) 10s", RhythmTiming{0.0});
    const std::vector<float> t = tabulate(r.channels[0], r.period_s, 20);  // every 0.5 s
    ASSERT_EQ(t.size(), 20u);
    // t = 0 on, 0.5 off (the flash ends), 1.0 off, 1.5 on, 2.0 off, ...
    EXPECT_EQ(t[0], 1.0f);
    EXPECT_EQ(t[1], 0.0f);
    EXPECT_EQ(t[2], 0.0f);
    EXPECT_EQ(t[3], 1.0f);
    for (std::size_t i = 4; i < 20; ++i) EXPECT_EQ(t[i], 0.0f) << i;
}

TEST(Rhythm, ChartSpellingsAreAcceptedAndNormalised) {
    const std::vector<std::pair<const char*, const char*>> same = {
        {"Fl(2) 10s", "Fl(2) 10s"},
        {"Fl.(2) 10s", "Fl(2) 10s"},
        {"Gp Fl(2) 10s", "Fl(2) 10s"},
        {"Fl(2)10s", "Fl(2) 10s"},
        {"Fl(2) 10 s", "Fl(2) 10s"},
        {"Fl(2) 10sec", "Fl(2) 10s"},
        {"fl(2) 10 SEC", "Fl(2) 10s"},
        {"Gr.Fl.(2).10s", "Fl(2) 10s"},
        {"Fl(2) R 10s", "Fl(2) R 10s"},
        {"Fl.G.3s", "Fl G 3s"},
        {"Iso W 4s", "Iso W 4s"},
        {"L.Fl.10s", "LFl 10s"},
        {"Gp Occ(3) 10s", "Oc(3) 10s"},
        {"Q(6)+L.Fl 15s", "Q(6)+LFl 15s"},
        {"V.Q(3) 5s", "VQ(3) 5s"},
        {"Qk.Fl", "Q"},
        {"V.Qk.Fl.", "VQ"},
        {"Mo (a) 6s", "Mo(A) 6s"},
        {"Fl 2.5s", "Fl 2.5s"},
        {"Fl.WRG.10s", "Fl WRG 10s"},
        {"Alt.WR 4s", "Al.WR 4s"},
        {"Q 1s", "Q 1s"},
        {"I.Q 10s", "IQ 10s"},
    };
    for (const auto& [in, norm] : same) {
        SCOPED_TRACE(in);
        EXPECT_EQ(parse_rhythm(in).text, norm);
    }
    // Colour letters are recorded but do not change the rhythm.
    const Rhythm red = parse_rhythm("Fl(2) R 10s");
    const Rhythm plain = parse_rhythm("Fl(2) 10s");
    EXPECT_EQ(red.chart_colours, "R");
    ASSERT_EQ(red.channels.size(), 1u);
    EXPECT_TRUE(red.channels[0].colour.empty());
    ASSERT_EQ(red.channels[0].knots.size(), plain.channels[0].knots.size());
    for (std::size_t i = 0; i < plain.channels[0].knots.size(); ++i) {
        EXPECT_EQ(red.channels[0].knots[i].t_s, plain.channels[0].knots[i].t_s);
        EXPECT_EQ(red.channels[0].knots[i].level, plain.channels[0].knots[i].level);
    }
    EXPECT_EQ(parse_rhythm("Fl.G.3s").chart_colours, "G");
    EXPECT_EQ(parse_rhythm("Fl(2) Bu 10s").chart_colours, "Bu");
}

/// The message must say what is wrong and quote the offending part.
void expect_rejected(const char* text, const std::vector<std::string>& mentions, RhythmTiming timing = {}) {
    SCOPED_TRACE(text);
    try {
        parse_rhythm(text, timing);
        ADD_FAILURE() << "accepted an invalid rhythm";
    } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find(std::string("rhythm '") + text + "'"), std::string::npos) << m;
        for (const std::string& s : mentions) EXPECT_NE(m.find(s), std::string::npos) << "'" << s << "' in: " << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
}

TEST(Rhythm, InvalidCharactersAreRejectedWithASentence) {
    expect_rejected("", {"empty"});
    expect_rejected("   ", {"empty"});
    expect_rejected("Fl(0) 5s", {"a group must have at least one flash"});
    expect_rejected("Oc(0) 5s", {"at least one eclipse"});
    expect_rejected("Fl(2+0) 5s", {"at least one flash"});
    expect_rejected("Xy 5s", {"'Xy'", "not a light class"});
    expect_rejected("W 5s", {"'W'", "not a light class"});
    expect_rejected("Fl", {"Fl needs a period"});
    expect_rejected("Fl(2)", {"Fl(2) needs a period"});
    expect_rejected("Mo(U)", {"needs a period"});
    expect_rejected("Q(3)", {"Q(3) needs a period"});
    expect_rejected("IQ", {"needs a period"});
    expect_rejected("Fl(2) 10s 8M", {"unexpected '8M' at the end"});
    expect_rejected("Fl(2) 10s R", {"unexpected 'R' at the end"});
    expect_rejected("Fl 0s", {"positive", "'0 s'"});
    expect_rejected("Fl -5s", {"positive", "'-5 s'"});
    expect_rejected("Fl 10", {"'10'", "unit"});
    expect_rejected("Fl 10 min", {"'10'", "unit"});
    expect_rejected("Fl(2) 2s", {"2 s", "too short", "Fl(2)", "at least 4 s"});
    expect_rejected("Fl 1s", {"1 s", "too short", "Fl", "more than 1 s"});
    expect_rejected("Fl(2+1) 6s", {"6 s", "too short", "Fl(2+1)"});
    expect_rejected("Oc 2s", {"too short", "Oc"});
    expect_rejected("Q(6)+LFl 8s", {"too short", "Q(6)+LFl"});
    expect_rejected("Mo(A) 2s", {"too short", "Mo(A)"});
    expect_rejected("IQ 3s", {"too short", "IQ"});
    expect_rejected("Q 5s", {"Q flashes 50 to 80 times a minute", "not 5 s"});
    expect_rejected("VQ 1s", {"VQ", "not 1 s"});
    expect_rejected("Mo(1) 10s", {"Morse code '1'", "letters A to Z"});
    expect_rejected("Mo(U2) 10s", {"Morse code 'U2'"});
    expect_rejected("Mo() 10s", {"at least one letter"});
    expect_rejected("Mo 10s", {"Mo(U)"});
    expect_rejected("F 10s", {"fixed", "no period"});
    expect_rejected("Fl(2.5) 10s", {"'2.5'", "whole number"});
    expect_rejected("Fl(2 10s", {"not closed"});
    expect_rejected("Fl(a) 10s", {"'(a)'"});
    expect_rejected("Fl(2) X 10s", {"'X' is not a colour"});
    expect_rejected("Fl # 5s", {"unexpected character '#'"});
    expect_rejected("Oc+Fl 10s", {"'+'", "not Oc"});
    expect_rejected("Fl(2+1)+LFl 20s", {"composite group Fl(2+1)"});
    expect_rejected("Q(6)+ 15s", {"'+'"});
    expect_rejected("Iso(2) 4s", {"Iso takes no group count", "'Iso(2)'"});
    expect_rejected("IQ(3) 10s", {"IQ takes no group count"});
    expect_rejected("Al.WR", {"alternating light needs a period"});
    expect_rejected("Al.W 4s", {"at least two colour letters"});
    expect_rejected("Al.WW 4s", {"two different colours"});
    expect_rejected("Al.Q.WR 4s", {"alternating Q"});
    expect_rejected("Al.Fl(2).WR 10s", {"without a group"});
    expect_rejected("Al.Fl.WR 1.5s", {"too short", "0.75 s share"});
    expect_rejected("Al.Xz 4s", {"'Xz'"});
    expect_rejected("Fl 10s", {"ramp time 0.6 s", "shortest phase (0.5 s)"}, RhythmTiming{0.6});
}

TEST(Rhythm, BoundaryPeriodsAreAccepted) {
    // The smallest periods the documented rules allow, to pin the rules down.
    EXPECT_NO_THROW(parse_rhythm("Fl(2) 4s"));    // 2 s group + 2 s (= 2 x 1 s) eclipse
    EXPECT_NO_THROW(parse_rhythm("Mo(A) 3.5s"));  // 2.5 s + 1 s (= 2 x 0.5 s)
    EXPECT_NO_THROW(parse_rhythm("Q 1.2s"));      // 50/min
    EXPECT_NO_THROW(parse_rhythm("VQ 0.75s"));    // 80/min
    EXPECT_NO_THROW(parse_rhythm("IQ 4.3s"));     // 2 flashes + 3 cycles
    EXPECT_NO_THROW(parse_rhythm("Fl 1.2s"));     // 0.7 s eclipse > 0.5 s flash
    // Decimal periods that equal the minimum only up to binary rounding.
    EXPECT_NO_THROW(parse_rhythm("VQ(9) 4.8s"));        // 9 x 0.2 + 8 x 0.3 + 2 x 0.3
    EXPECT_NO_THROW(parse_rhythm("VQ(6)+LFl 5.6s"));    // 6 x 0.2 + 6 x 0.3 + 2 + 2 x 0.3
    EXPECT_NO_THROW(parse_rhythm("Q(9) 9.7s"));         // 9 x 0.3 + 8 x 0.7 + 2 x 0.7
    EXPECT_THROW(parse_rhythm("Q 0.75s"), InputError);  // 80/min is VQ, not Q
    EXPECT_THROW(parse_rhythm("LFl 4s"), InputError);   // dark must be longer than the 2 s flash
}

}  // namespace
