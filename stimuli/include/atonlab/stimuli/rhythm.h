#pragma once
// Light rhythms: IALA light characters as printed on charts ("Fl(2) 10s",
// "Oc(2+1) 12s", "Al.WR 4s", "Mo(U) 15s", "Q(6)+LFl 15s", "F") turned into a
// periodic intensity factor B(t) in [0, 1] with finite on/off ramps (K2012 §4.1
// "blink profile", §5.1). Nominal durations follow IALA Recommendation E-110
// where it fixes them and documented defaults where it does not (rhythm.cpp).
#include <string>
#include <string_view>
#include <vector>

namespace atonlab::stimuli {

/// One knot of a piecewise-linear periodic function.
struct RhythmKnot {
    double t_s;    ///< time within the period, seconds, 0 <= t_s <= period
    double level;  ///< relative intensity in [0, 1]
};

/// The intensity of one colour of a light character over one period.
/// Knots are sorted by time, the first at t = 0 and the last at t = period,
/// with equal levels (periodic). A fixed light has period 0 and one knot {0, 1}.
struct RhythmChannel {
    std::string colour;  ///< IALA chart letter ("W", "R", ...) for Al. characters; empty = the light's own colour
    std::vector<RhythmKnot> knots;
};

struct RhythmTiming {
    double ramp_s = 0.02;  ///< rise and fall time of each flash (10%..90% is not used: a linear ramp of this length)
};

/// A parsed light character.
struct Rhythm {
    std::string text;      ///< the normalised chart text, e.g. "Fl(2) 10s"
    double period_s = 0;   ///< 0 for a fixed light
    std::vector<RhythmChannel> channels;  ///< one per colour (one unless "Al.")
    /// Colour letters written on the chart after a non-alternating character
    /// ("R" in "Fl(2) R 10s", "WRG" for a sectored "Fl.WRG.10s"); informational
    /// only: the light's colour comes from the scene. Empty for "Al." characters,
    /// whose colours are in channels[i].colour.
    std::string chart_colours;

    /// B(t) of channel c at time t_s (seconds, any real; taken modulo the period).
    double level(double t_s, std::size_t channel = 0) const;
    /// Fraction of the period the channel is lit (integral of B over a period / period).
    double duty_cycle(std::size_t channel = 0) const;
};

/// Parses a chart light character. Throws InputError (no location; the caller
/// adds file/line/key) with a sentence saying what is wrong for an invalid one.
Rhythm parse_rhythm(std::string_view text, const RhythmTiming& timing = {});

/// Level at time t of a piecewise-linear periodic knot list (the CPU reference
/// of the GLSL rhythm_level() in shaders/light_model.glsl): binary search then
/// linear interpolation; t wrapped into [0, period) with a floor that is exact for negative t.
double rhythm_level(const std::vector<RhythmKnot>& knots, double period_s, double t_s);

/// Uniformly tabulated B(t) over one period, n samples at t = i * period / n.
std::vector<float> tabulate(const RhythmChannel& channel, double period_s, int n);

}  // namespace atonlab::stimuli
