// Light characters (IALA Recommendation E-110, "Rhythmic characters of lights")
// turned into the blink profile B(t) of K2012 §4.1 / §5.1.
//
// Where E-110 fixes a duration (long flash >= 2 s; quick 50-79, very quick
// 80-159, ultra quick >= 160 flashes a minute; Morse dash = 3 dots) we follow
// it; where it leaves a duration free we use the nominal values below, listed
// with the grammar in docs/light-characters.md. Keep the two in step.
//
// Every on/off edge becomes a linear ramp of RhythmTiming::ramp_s centred on
// the nominal edge. That is the nominal square wave convolved with a box of
// width ramp_s, so the integral of every flash (and the duty cycle) equals the
// nominal value exactly, whatever the ramp.
#include "atonlab/stimuli/rhythm.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <charconv>
#include <cmath>
#include <optional>
#include <utility>

#include "atonlab/stimuli/error.h"
#include "rhythm_grammar.h"

namespace atonlab::stimuli {
namespace {

using namespace rhythm_detail;

// ---- Nominal durations, seconds (docs/light-characters.md, "Timing") ----------

/// A flash and the eclipse between two flashes of one group.
struct FlashTiming {
    double flash_s;
    double eclipse_s;
    double cycle_s() const { return flash_s + eclipse_s; }
};

constexpr FlashTiming fl_timing{0.5, 1.0};   // E-110 leaves both free
constexpr FlashTiming lfl_timing{2.0, 2.0};  // E-110: a long flash lasts at least 2 s
constexpr FlashTiming q_timing{0.3, 0.7};    // 60 flashes/min (E-110: 50..79, usually 50 or 60)
constexpr FlashTiming vq_timing{0.2, 0.3};   // 120 flashes/min (E-110: 80..159, usually 100 or 120)
constexpr FlashTiming uq_timing{0.1, 0.15};  // 240 flashes/min (E-110: >= 160, usually 240..300)

constexpr double oc_eclipse_s = 1.0;        // occulting eclipse (IALA example Oc(2) 13s = 1,1,1,10)
constexpr double oc_light_between_s = 1.0;  // light between the eclipses of a group (same example)

constexpr double morse_dot_s = 0.5;
constexpr double morse_dash_s = 3 * morse_dot_s;        // E-110 / ITU: a dash is three dots
constexpr double morse_element_gap_s = morse_dot_s;     // ITU: one dot between dots and dashes
constexpr double morse_letter_gap_s = 3 * morse_dot_s;  // ITU: three dots between letters

/// Periods are decimals ("4.8s") and the nominal durations are not exact in
/// binary, so "at least" comparisons forgive this much rounding.
constexpr double slack_s = 1e-9;

/// Interrupted quick: the interruption lasts at least this many flash cycles.
constexpr double interruption_cycles = 3.0;

/// Rate limits of continuous quick lights, flashes per minute (E-110).
struct RateLimits {
    double min_per_min;
    double max_per_min;  ///< exclusive; for UQ set by the flash length (dark at least as long as the flash)
};

FlashTiming flash_timing(Kind k) {
    switch (k) {
        case Kind::flash:
            return fl_timing;
        case Kind::long_flash:
            return lfl_timing;
        case Kind::quick:
        case Kind::interrupted_quick:
            return q_timing;
        case Kind::very_quick:
        case Kind::interrupted_very_quick:
            return vq_timing;
        case Kind::ultra_quick:
        case Kind::interrupted_ultra_quick:
            return uq_timing;
        default:
            assert(false && "not a flashing class");
            return fl_timing;
    }
}

RateLimits rate_limits(Kind k) {
    switch (k) {
        case Kind::quick:
            return {50, 80};
        case Kind::very_quick:
            return {80, 160};
        default:
            return {160, 60.0 / (2 * uq_timing.flash_s)};  // eclipse at least as long as the flash
    }
}

/// One phase of the nominal square wave: lit or dark for dur_s seconds.
struct Phase {
    bool lit;
    double dur_s;
};

/// A lit interval [a_s, b_s) of the nominal square wave, 0 <= a < b <= period.
struct Interval {
    double a_s;
    double b_s;
};

// ---- Layout: nominal phases over one period -----------------------------------

std::string element_text(const Element& e) {
    std::string s = kind_name(e.kind);
    if (e.kind == Kind::morse) return s + "(" + e.morse + ")";
    if (!e.groups.empty()) {
        s += "(";
        for (std::size_t i = 0; i < e.groups.size(); ++i) s += (i ? "+" : "") + std::to_string(e.groups[i]);
        s += ")";
    }
    return s;
}

/// Builds the phases of one element (or a "+" sequence of flashing elements)
/// over period_s, starting at t = 0 with the first flash (flashing, Morse, Iso)
/// or the first eclipse (occulting), as light lists write phases.
class Layout {
public:
    /// shares > 1: the pattern fills one colour's share of an alternating period.
    Layout(std::string_view src, std::string body, int shares = 1)
        : src_(src), body_(std::move(body)), shares_(shares) {}

    std::vector<Phase> build(const std::vector<Element>& els, double period_s) {
        phases_.clear();
        if (els.size() > 1) return sequence(els, period_s);
        const Element& e = els.front();
        switch (e.kind) {
            case Kind::occulting:
                return occulting(e, period_s);
            case Kind::isophase:
                return {{true, period_s / 2}, {false, period_s / 2}};
            case Kind::morse:
                return morse(e, period_s);
            case Kind::interrupted_quick:
            case Kind::interrupted_very_quick:
            case Kind::interrupted_ultra_quick:
                return interrupted(e, period_s);
            default:
                return flashing(e, period_s);
        }
    }

private:
    void push(bool lit, double dur_s) { phases_.push_back({lit, dur_s}); }
    double used() const {
        double s = 0;
        for (const Phase& ph : phases_) s += ph.dur_s;
        return s;
    }
    /// strict: the period must exceed needed_s; otherwise it may equal it.
    [[noreturn]] void too_short(double period_s, double needed_s, bool strict) const {
        const char* cmp = strict ? "more than" : "at least";
        if (shares_ > 1)
            fail(src_, fmt::format("the period {} s is too short for {}: each colour's {} s share needs "
                                   "{} {} s (see docs/light-characters.md)",
                                   num(period_s * shares_), body_, num(period_s), cmp, num(needed_s)));
        fail(src_, fmt::format("the period {} s is too short for {}: its nominal durations need {} {} s "
                               "(see docs/light-characters.md)",
                               num(period_s), body_, cmp, num(needed_s)));
    }
    /// n flashes of t separated by t.eclipse_s.
    void group_of_flashes(int n, const FlashTiming& t) {
        for (int i = 0; i < n; ++i) {
            if (i > 0) push(false, t.eclipse_s);
            push(true, t.flash_s);
        }
    }

    std::vector<Phase> flashing(const Element& e, double period_s) {
        const FlashTiming t = flash_timing(e.kind);
        const std::vector<int> groups = e.groups.empty() ? std::vector<int>{1} : e.groups;
        if (groups.size() == 1 && groups[0] == 1) {
            // Single flash: flashing means the eclipse is longer than the flash (E-110).
            if (e.groups.empty() && is_quick(e.kind)) {
                const RateLimits r = rate_limits(e.kind);
                const double per_min = 60.0 / period_s;
                if (per_min < r.min_per_min || per_min >= r.max_per_min)
                    fail(src_, fmt::format("{} flashes {} to {} times a minute, so its period must be "
                                           "in ({}, {}] s, not {} s",
                                           body_, num(r.min_per_min), num(r.max_per_min), num(60.0 / r.max_per_min),
                                           num(60.0 / r.min_per_min), num(period_s)));
            } else if (!(period_s - t.flash_s > t.flash_s)) {
                too_short(period_s, 2 * t.flash_s, true);
            }
            push(true, t.flash_s);
            push(false, period_s - t.flash_s);
            return phases_;
        }
        // Groups, composite groups (IALA example Oc(2+1) 12s = 1,1,1,4,1,4): every
        // group is followed by the same long eclipse, which must be at least twice
        // the eclipse inside a group so that the grouping is seen.
        double inside = 0;
        for (int n : groups) inside += n * t.flash_s + (n - 1) * t.eclipse_s;
        const double count = static_cast<double>(groups.size());
        const double long_s = (period_s - inside) / count;
        if (!(long_s >= 2 * t.eclipse_s - slack_s)) too_short(period_s, inside + count * 2 * t.eclipse_s, false);
        for (int n : groups) {
            group_of_flashes(n, t);
            push(false, long_s);
        }
        return phases_;
    }

    std::vector<Phase> sequence(const std::vector<Element>& els, double period_s) {
        // "Q(6)+LFl 15s": the elements follow each other at the rhythm of the one
        // before (the long flash comes where the 7th quick flash would).
        double longest_eclipse = 0;
        for (std::size_t k = 0; k < els.size(); ++k) {
            const Element& e = els[k];
            if (!is_flashing(e.kind))
                fail(src_, fmt::format("only flashing classes (Fl, LFl, Q, VQ, UQ) can be joined "
                                       "with '+', not {}",
                                       kind_name(e.kind)));
            if (e.groups.size() > 1)
                fail(src_, fmt::format("the composite group {} cannot be joined with '+'", element_text(e)));
            const FlashTiming t = flash_timing(e.kind);
            if (k > 0) {
                const double gap = flash_timing(els[k - 1].kind).eclipse_s;
                push(false, gap);
                longest_eclipse = std::max(longest_eclipse, gap);
            }
            const int n = e.groups.empty() ? 1 : e.groups[0];
            group_of_flashes(n, t);
            if (n > 1) longest_eclipse = std::max(longest_eclipse, t.eclipse_s);
        }
        const double inside = used();
        if (!(period_s - inside >= 2 * longest_eclipse - slack_s))
            too_short(period_s, inside + 2 * longest_eclipse, false);
        push(false, period_s - inside);
        return phases_;
    }

    std::vector<Phase> occulting(const Element& e, double period_s) {
        // The dark twin of flashing: eclipses of oc_eclipse_s separated by
        // oc_light_between_s inside a group; each group followed by a long light.
        const std::vector<int> groups = e.groups.empty() ? std::vector<int>{1} : e.groups;
        if (groups.size() == 1 && groups[0] == 1) {
            // Occulting means the light is longer than the eclipse (E-110).
            if (!(period_s - oc_eclipse_s > oc_eclipse_s)) too_short(period_s, 2 * oc_eclipse_s, true);
            push(false, oc_eclipse_s);
            push(true, period_s - oc_eclipse_s);
            return phases_;
        }
        double inside = 0;
        for (int n : groups) inside += n * oc_eclipse_s + (n - 1) * oc_light_between_s;
        const double count = static_cast<double>(groups.size());
        const double long_s = (period_s - inside) / count;
        if (!(long_s >= 2 * oc_light_between_s - slack_s))
            too_short(period_s, inside + count * 2 * oc_light_between_s, false);
        for (int n : groups) {
            for (int i = 0; i < n; ++i) {
                if (i > 0) push(true, oc_light_between_s);
                push(false, oc_eclipse_s);
            }
            push(true, long_s);
        }
        return phases_;
    }

    std::vector<Phase> morse(const Element& e, double period_s) {
        double longest_gap = 0;
        for (std::size_t l = 0; l < e.morse.size(); ++l) {
            if (l > 0) {
                push(false, morse_letter_gap_s);
                longest_gap = morse_letter_gap_s;
            }
            const std::string code = morse_code(e.morse[l]);
            for (std::size_t s = 0; s < code.size(); ++s) {
                if (s > 0) {
                    push(false, morse_element_gap_s);
                    longest_gap = std::max(longest_gap, morse_element_gap_s);
                }
                push(true, code[s] == '.' ? morse_dot_s : morse_dash_s);
            }
        }
        // The eclipse that ends the period must stand out from the gaps inside it;
        // a single dot/dash ("Mo(E)", "Mo(T)") must at least be shorter than its eclipse.
        const double inside = used();
        const double min_final = longest_gap > 0 ? 2 * longest_gap : inside;
        if (!(period_s - inside >= min_final - slack_s && period_s - inside > 0))
            too_short(period_s, inside + min_final, false);
        push(false, period_s - inside);
        return phases_;
    }

    std::vector<Phase> interrupted(const Element& e, double period_s) {
        // Quick flashes at the nominal rate for as long as the period allows while
        // leaving an interruption of at least interruption_cycles cycles.
        const FlashTiming t = flash_timing(e.kind);
        const double c = t.cycle_s();
        const double room = period_s - t.flash_s - interruption_cycles * c;
        const int n = room >= -slack_s ? 1 + static_cast<int>(std::floor((room + slack_s) / c)) : 0;
        if (n < 2) too_short(period_s, c + t.flash_s + interruption_cycles * c, false);
        group_of_flashes(n, t);
        push(false, period_s - used());
        return phases_;
    }

    std::string_view src_;
    std::string body_;
    int shares_;
    std::vector<Phase> phases_;
};

// ---- Knots: the ramped, periodic B(t) of one channel --------------------------

/// Length of [lo, hi] covered by the periodic lit set (intervals repeat every period).
double lit_measure(const std::vector<Interval>& lit, double period_s, double lo, double hi) {
    double m = 0;
    for (const Interval& iv : lit)
        for (int k = -1; k <= 1; ++k) {
            const double a = iv.a_s + k * period_s;
            const double b = iv.b_s + k * period_s;
            m += std::max(0.0, std::min(b, hi) - std::max(a, lo));
        }
    return m;
}

bool lit_after(const std::vector<Interval>& lit, double t) {  // on [t, t + eps)
    for (const Interval& iv : lit)
        if (iv.a_s <= t && t < iv.b_s) return true;
    return false;
}
bool lit_before(const std::vector<Interval>& lit, double t) {  // on (t - eps, t]
    for (const Interval& iv : lit)
        if (iv.a_s < t && t <= iv.b_s) return true;
    return false;
}

std::vector<RhythmKnot> knots_from_intervals(const std::vector<Interval>& lit, double period_s, double ramp_s) {
    std::vector<RhythmKnot> k;
    if (ramp_s == 0) {
        // Jumps: two knots at the same time (rhythm_level is right-continuous there).
        std::vector<double> edges;
        for (const Interval& iv : lit)
            for (double e : {iv.a_s, iv.b_s})
                if (e > 0 && e < period_s) edges.push_back(e);
        std::sort(edges.begin(), edges.end());
        edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
        const double first = lit_after(lit, 0) ? 1 : 0;
        k.push_back({0, first});
        for (double e : edges) {
            k.push_back({e, lit_before(lit, e) ? 1.0 : 0.0});
            k.push_back({e, lit_after(lit, e) ? 1.0 : 0.0});
        }
        k.push_back({period_s, lit_before(lit, period_s) ? 1.0 : 0.0});
        k.push_back({period_s, first});
        k.erase(
            std::unique(k.begin(), k.end(),
                        [](const RhythmKnot& x, const RhythmKnot& y) { return x.t_s == y.t_s && x.level == y.level; }),
            k.end());
        return k;
    }
    // The square wave convolved with a box of width ramp_s is piecewise linear
    // with breaks at every edge +- ramp_s / 2; evaluate it exactly there.
    const double h = ramp_s / 2;
    auto level_at = [&](double t) {
        const double l = lit_measure(lit, period_s, t - h, t + h) / ramp_s;
        // Snap rounding noise so that plateaus are exactly 0 and 1.
        if (l < 1e-12) return 0.0;
        if (l > 1 - 1e-12) return 1.0;
        return l;
    };
    auto wrap = [&](double t) {
        double w = std::fmod(t, period_s);
        if (w < 0) w += period_s;
        return w >= period_s ? 0.0 : w;
    };
    std::vector<double> ts{0};
    for (const Interval& iv : lit)
        for (double e : {iv.a_s, iv.b_s}) {
            ts.push_back(wrap(e - h));
            ts.push_back(wrap(e + h));
        }
    std::sort(ts.begin(), ts.end());
    ts.erase(std::unique(ts.begin(), ts.end()), ts.end());
    for (double t : ts) k.push_back({t, level_at(t)});
    k.push_back({period_s, k.front().level});
    return k;
}

std::vector<Interval> lit_intervals(const std::vector<Phase>& phases, double offset_s) {
    std::vector<Interval> out;
    double t = offset_s;
    for (const Phase& ph : phases) {
        if (ph.lit) {
            if (!out.empty() && out.back().b_s == t)
                out.back().b_s = t + ph.dur_s;
            else
                out.push_back({t, t + ph.dur_s});
        }
        t += ph.dur_s;
    }
    return out;
}

void check_ramp(std::string_view src, const std::vector<Phase>& phases, double ramp_s) {
    for (const Phase& ph : phases)
        if (ph.dur_s < ramp_s)
            fail(src, fmt::format("the ramp time {} s is longer than its shortest phase ({} s)", num(ramp_s),
                                  num(ph.dur_s)));
}

}  // namespace

// ---- Public API --------------------------------------------------------------

Rhythm parse_rhythm(std::string_view text, const RhythmTiming& timing) {
    if (!(timing.ramp_s >= 0) || !std::isfinite(timing.ramp_s))
        fail(text, fmt::format("the ramp time must be a finite number >= 0, not {}", timing.ramp_s));
    const Parsed p = parse_character(text);

    Rhythm r;
    std::string colours;
    for (const std::string& c : p.colours) colours += c;

    if (p.alternating) {
        // "Al.Fl.WR 5s": the period is shared equally among the colours in the
        // order written; each share shows the class's single-element pattern.
        Kind base = Kind::fixed;
        if (p.elements.size() > 1 || (p.elements.size() == 1 && !p.elements[0].groups.empty()))
            fail(text,
                 "alternating lights are supported with a single class without a group "
                 "(Al.WR, Al.Fl.WR, Al.LFl.WR, Al.Oc.WR, Al.Iso.WR)");
        if (!p.elements.empty()) base = p.elements[0].kind;
        if (!(base == Kind::fixed || base == Kind::flash || base == Kind::long_flash || base == Kind::occulting ||
              base == Kind::isophase))
            fail(text,
                 fmt::format("alternating {} is not supported (use Al. with F, Fl, LFl, Oc or Iso)", kind_name(base)));
        if (p.colours.size() < 2) fail(text, "an alternating light needs at least two colour letters, e.g. 'Al.WR 4s'");
        if (std::all_of(p.colours.begin(), p.colours.end(), [&](const std::string& c) { return c == p.colours[0]; }))
            fail(text, "an alternating light needs at least two different colours");
        if (!p.period_s) fail(text, "an alternating light needs a period, e.g. 'Al.WR 4s'");
        r.period_s = *p.period_s;
        const double slot_s = r.period_s / static_cast<double>(p.colours.size());
        const std::string base_text = base == Kind::fixed ? "" : std::string(kind_name(base)) + ".";
        r.text = "Al." + base_text + colours + " " + num(r.period_s) + "s";

        std::vector<Phase> slot;
        if (base == Kind::fixed) {
            slot = {{true, slot_s}};
        } else {
            Element e;
            e.kind = base;
            const std::string al_text = r.text.substr(0, r.text.find(' '));
            slot = Layout(text, al_text, static_cast<int>(p.colours.size())).build({e}, slot_s);
        }
        check_ramp(text, slot, timing.ramp_s);
        std::vector<std::string> order;
        for (const std::string& c : p.colours)
            if (std::find(order.begin(), order.end(), c) == order.end()) order.push_back(c);
        for (const std::string& c : order) {
            std::vector<Interval> lit;
            for (std::size_t s = 0; s < p.colours.size(); ++s) {
                if (p.colours[s] != c) continue;
                const std::vector<Interval> part = lit_intervals(slot, static_cast<double>(s) * slot_s);
                for (const Interval& iv : part) {
                    if (!lit.empty() && lit.back().b_s == iv.a_s)
                        lit.back().b_s = iv.b_s;
                    else
                        lit.push_back(iv);
                }
            }
            // The last slot ends at period_s by construction; avoid a rounding sliver past it.
            for (Interval& iv : lit) iv.b_s = std::min(iv.b_s, r.period_s);
            r.channels.push_back({c, knots_from_intervals(lit, r.period_s, timing.ramp_s)});
        }
        return r;
    }

    std::string body;
    for (std::size_t i = 0; i < p.elements.size(); ++i) body += (i ? "+" : "") + element_text(p.elements[i]);
    r.chart_colours = colours;
    const Element& first = p.elements.front();

    if (p.elements.size() == 1 && first.kind == Kind::fixed) {
        if (p.period_s)
            fail(text, fmt::format("a fixed light (F) has no period, but '{} s' is given", num(*p.period_s)));
        r.text = colours.empty() ? "F" : "F " + colours;
        r.period_s = 0;
        r.channels.push_back({"", {{0, 1}}});
        return r;
    }
    for (const Element& e : p.elements)
        if (e.kind == Kind::fixed) fail(text, "F (fixed) cannot be joined with '+'");

    double period_s = 0;
    if (p.period_s) {
        period_s = *p.period_s;
    } else if (p.elements.size() == 1 && is_quick(first.kind) && first.groups.empty()) {
        period_s = flash_timing(first.kind).cycle_s();  // continuous Q/VQ/UQ: one flash cycle
    } else {
        fail(text, fmt::format("{} needs a period, e.g. '{} 10s'", body, body));
    }

    const std::vector<Phase> phases = Layout(text, body).build(p.elements, period_s);
    check_ramp(text, phases, timing.ramp_s);
    std::vector<Interval> lit = lit_intervals(phases, 0);
    for (Interval& iv : lit) iv.b_s = std::min(iv.b_s, period_s);

    r.period_s = period_s;
    r.text = body;
    if (!colours.empty()) r.text += " " + colours;
    if (p.period_s) r.text += " " + num(period_s) + "s";
    r.channels.push_back({"", knots_from_intervals(lit, period_s, timing.ramp_s)});
    return r;
}

double rhythm_level(const std::vector<RhythmKnot>& knots, double period_s, double t_s) {
    assert(!knots.empty());
    if (knots.empty()) return 0;
    if (!(period_s > 0) || !std::isfinite(t_s)) return knots.front().level;
    // Wrap into [0, period). std::fmod is exact in IEEE 754 (no rounding), so this
    // equals t - period * floor(t / period) computed exactly, for negative t too;
    // only the "+ period" for negative t rounds, and when it rounds up to the
    // period itself the exact phase was within half an ulp of it: use 0, which
    // has the same level. For |t| beyond about 2^53 * ulp(period) the input t
    // itself no longer resolves the phase; the result is still a level in [0, 1].
    double w = std::fmod(t_s, period_s);
    if (w < 0) w += period_s;
    if (w >= period_s) w = 0;
    // First knot strictly after w; with two knots at one time (ramp 0) this takes
    // the level after the jump.
    const auto it =
        std::upper_bound(knots.begin(), knots.end(), w, [](double t, const RhythmKnot& k) { return t < k.t_s; });
    if (it == knots.begin()) return it->level;
    if (it == knots.end()) return knots.back().level;
    const RhythmKnot& k1 = *it;
    const RhythmKnot& k0 = *(it - 1);
    const double f = (w - k0.t_s) / (k1.t_s - k0.t_s);
    return k0.level + f * (k1.level - k0.level);
}

std::vector<float> tabulate(const RhythmChannel& channel, double period_s, int n) {
    assert(n > 0);
    std::vector<float> out;
    if (n <= 0) return out;
    out.reserve(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
        out.push_back(static_cast<float>(rhythm_level(channel.knots, period_s, i * period_s / n)));
    return out;
}

double Rhythm::level(double t_s, std::size_t channel) const {
    return rhythm_level(channels.at(channel).knots, period_s, t_s);
}

double Rhythm::duty_cycle(std::size_t channel) const {
    const std::vector<RhythmKnot>& k = channels.at(channel).knots;
    if (!(period_s > 0)) return k.front().level;
    // Exact integral of the piecewise-linear B(t): trapezoids between knots.
    double area = 0;
    for (std::size_t i = 1; i < k.size(); ++i) area += 0.5 * (k[i].level + k[i - 1].level) * (k[i].t_s - k[i - 1].t_s);
    return area / period_s;
}

}  // namespace atonlab::stimuli