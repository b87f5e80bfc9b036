#pragma once
// Displayability: what a protocol's stimuli look like on its display before
// the first trial (docs/running.md, "Displayability"). For every condition, at
// both ends of its level range, each judged light is rendered at the display's
// geometry and calibration (the StimulusRenderer of the session) and
// summarised in code values: the peak code, the background's, how far the
// light rises above the background, whether it clips at the display's white,
// and the light it puts into the eye (lux).
//
// A condition "cannot produce a match" (or a threshold) on this display when
//  R1  a judged light rises fewer than kMinRiseCodes code values above the
//      background at the top of the level range (it cannot be seen there, and
//      the top is where it is brightest);
//  R2  the level stimulus puts no more light into the eye at the top of the
//      range than at the bottom (the display clips or hides it over the whole
//      range: the level changes nothing on the screen);
//  R3  (2AFC and adjust) at the top of the range the level stimulus is clipped
//      at the display's white and still puts less light into the eye than the
//      other stimulus (by more than 1%): no level in the range can make it the
//      brighter of the two.
// `atonlab run` refuses such a protocol (exit 2) unless --allow-undisplayable;
// `atonlab check` prints the same table and exits 0 or 2.
#include <string>
#include <vector>

#include "atonlab/protocols/protocol.h"
#include "run_session.h"

namespace atonlab::runner {

/// R1's limit: a light must rise at least this many code values above the background.
inline constexpr int kMinRiseCodes = 2;

/// One judged light at one level.
struct ShownLight {
    protocols::Role role = protocols::Role::Test;
    std::string light;         ///< the scene light's name
    int peak_code = 0;         ///< the highest code of any channel in its window
    int background_code = 0;   ///< the same with the judged lights off
    int rise_codes = 0;        ///< the most a pixel's channel lies above the lights-off frame
    bool clipped = false;      ///< a channel at the display's white
    double light_lux = 0.0;    ///< what it adds to the eye's illuminance within the observer's window, lx
};

/// A condition's stimulus at one end of its level range.
struct LevelEnd {
    double level = 0.0;  ///< in the procedure's units
    std::vector<ShownLight> lights;
    int white_code = 255;  ///< the display's white, 2^bits − 1
};

struct ConditionDisplayability {
    std::string name;
    int line = 0;         ///< the condition's line in the protocol
    LevelEnd low, high;   ///< the bottom and top of the level range
    /// Why the condition cannot produce a match on this display (R1-R3, with
    /// what to change), one clause each; empty when it can.
    std::vector<std::string> problems;
    bool displayable() const noexcept { return problems.empty(); }
};

struct Displayability {
    int width_px = 0, height_px = 0;
    double width_m = 0.0, viewing_distance_m = 0.0;
    double deg_per_px = 0.0;  ///< at the screen's centre
    int bits = 8;             ///< bits per channel of the codes
    std::vector<ConditionDisplayability> conditions;
    bool displayable() const noexcept;
};

/// Renders every condition at both ends of its level range (min_level and
/// max_level, or the constant-stimuli levels' extremes; else the procedure's
/// search range) on `renderer` (set up as the session's: display model and
/// window radius) and applies R1-R3. Throws InputError (a scene refused).
Displayability check_displayability(StimulusRenderer& renderer, const protocols::Protocol& protocol);

/// The table printed in the run header and by `atonlab check`: one line per
/// condition and end of its range.
std::string displayability_table(const Displayability& d);

/// One sentence per undisplayable condition (file:line: what is not
/// displayable and what to change), newline-separated; "" when all are.
std::string displayability_refusal(const Displayability& d, const std::string& protocol_file);

/// The JSON stored with the session (sessions.displayability_json; docs/store.md).
/// `allowed`: the session ran with --allow-undisplayable.
std::string displayability_json(const Displayability& d, bool allowed);

}  // namespace atonlab::runner
