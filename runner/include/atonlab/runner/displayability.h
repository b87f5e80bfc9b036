#pragma once
// Displayability: what a protocol's stimuli give the observer on its display
// before the first trial (docs/running.md, "Displayability"). For every
// condition, at both ends of its level range, each judged light is rendered at
// the display's geometry and calibration (the StimulusRenderer of the session)
// together with the same frame without the judged lights (the same moment and
// dither frame), both decoded through the display model to displayed
// luminance (cd/m²). A light's contribution is what it adds to the eye's
// illuminance over the model observer's window (radius 0.5°, observer.h):
// E = Σ (L − L_off) · Ω_px, lux; the display's resolution for it is one code
// step at the pixel where it adds most: the displayed luminance of raising the
// channels it raises there by one code over the lights-off codes, times Ω_px
// (lux): the least light the display can add there.
//
// A condition "cannot produce a match" (or a threshold) on this display when
//  R1  a judged light adds nothing, or less than the display's resolution, at
//      the end of the level range where it adds most (the level stimulus) or
//      at the top (the other stimulus): it cannot be seen;
//  R2  the level stimulus adds the same light at both ends of the range
//      (within the display's resolution: the display clips or hides it over
//      the whole range; the level changes nothing on the screen);
//  R3  (2AFC and adjust) at the end where the level stimulus is brightest it
//      is clipped at the display's white and still adds less light than the
//      other stimulus (by more than 1 %): no level in the range can make it
//      the brighter of the two;
//  R4  (2AFC and adjust) the range does not straddle the other stimulus: at
//      the end where the level stimulus is dimmest it already adds at least
//      the other's light, or at its brightest end (not clipped) no more; the
//      sentence names the bound to move and about where (the level where the
//      two would be equal, interpolated between the ends: log10 of the light
//      linear in the level on a log10 level scale, the light itself on a
//      linear one).
//  R5  (2AFC and adjust) under a display.out_of_gamut other than
//      keep-luminance, a judged light at either end loses more than the
//      protocol's display.max_out_of_gamut_loss (5 %) of its window's light to
//      the choice: a brightness match on a colour that gave up luminance.
// `atonlab run` refuses such a protocol (exit 2, before the study file is
// created) unless --allow-undisplayable; `atonlab check` prints the same table
// and exits 0 or 2.
#include <glm/vec3.hpp>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "atonlab/protocols/protocol.h"
#include "atonlab/runner/check_command.h"
#include "atonlab/runner/session/stimulus_renderer.h"

namespace atonlab::runner {

/// W1's limit: a judged light clipped at the display's white that loses more
/// than this share of its window's light there is warned of. Stored with the
/// session (displayability_json's "thresholds") so the shares can be judged later.
inline constexpr double kWhiteLossWarningShare = 0.01;

/// One judged light at one level.
struct ShownLight {
    protocols::Role role = protocols::Role::Test;
    std::string light;     ///< the scene light's name
    int peak_code = 0;     ///< the highest code of any channel in its window
    bool clipped = false;  ///< a channel at the display's white where the lights-off frame is not
    /// The lights-off codes (R, G, B) and displayed luminance (cd/m²) at the
    /// pixel where the light adds most (under its centre where it adds none).
    glm::ivec3 background_code{0};
    double background_cd_m2 = 0.0;
    /// E: the light it adds to the eye's illuminance within the observer's
    /// window, Σ (L − L_off) · Ω_px, lx; negative where it takes light away.
    double added_lux = 0.0;
    /// The display's resolution there: one code step of the channels it
    /// raises at that pixel, over the lights-off codes, times Ω_px, lx.
    double resolution_lux = 0.0;
    /// Of the light the tone mapper asks the window to show (Σ over the window of
    /// the pixels' target luminance, the CPU reference on the frame's HDR image,
    /// minus the lights-off frame's, times Ω_px), the share the display's white
    /// cuts (a target above white, shown at white: issue 44's clipping) ...
    double white_loss_share = 0.0;
    /// ... and the share display.out_of_gamut takes beyond that (0 under
    /// keep-luminance): the luminance a colour gives up to keep its colour.
    double gamut_loss_share = 0.0;
};

/// A condition's stimulus at one end of its level range.
struct LevelEnd {
    double level = 0.0;  ///< in the procedure's units
    std::vector<ShownLight> lights;
    int white_code = 255;  ///< the display's white, 2^bits − 1
    std::string out_of_gamut = "keep-luminance";  ///< its scene's display.out_of_gamut
};

struct ConditionDisplayability {
    std::string name;
    int line = 0;        ///< the condition's line in the protocol
    LevelEnd low, high;  ///< the bottom and top of the level range
    /// 2AFC and adjust: the level where the level stimulus would add as much
    /// light as the other, interpolated between the ends (R4); nullopt where
    /// the ends do not give one (a light adds none, or the same at both ends).
    std::optional<double> equal_level;
    /// Why the condition cannot produce a match on this display (R1-R5, with
    /// what to change), one clause each; empty when it can.
    std::vector<std::string> problems;
    /// W1: a judged light clipped at the display's white loses more than
    /// kWhiteLossWarningShare (1 %) of its light there (the share named): the
    /// match may lie. `atonlab check` prints them as warnings and, under
    /// --strict, refuses.
    std::vector<std::string> warnings;
    bool displayable() const noexcept { return problems.empty(); }
};

struct Displayability {
    int width_px = 0, height_px = 0;
    double width_m = 0.0, viewing_distance_m = 0.0;
    double deg_per_px = 0.0;         ///< at the screen's centre
    double window_radius_deg = 0.5;  ///< the observer's window the light is summed over, degrees
    int bits = 8;                    ///< bits per channel of the codes
    /// display.out_of_gamut of the scene (docs/tone-mapping.md "Out of gamut: colour or luminance").
    std::string out_of_gamut = "keep-luminance";
    /// R5's limit: the protocol's display.max_out_of_gamut_loss.
    double max_out_of_gamut_loss = 0.05;
    std::vector<ConditionDisplayability> conditions;
    bool displayable() const noexcept;
};

/// Renders every condition at both ends of its level range (min_level and
/// max_level, or the constant-stimuli levels' extremes; else the procedure's
/// search range) on `renderer` (set up as the session's: display model and
/// window radius) and applies R1-R4. Throws InputError (a scene refused).
Displayability check_displayability(StimulusRenderer& renderer, const protocols::Protocol& protocol);

/// `atonlab check`'s work without its output (the Python module's
/// atonlab.check): the protocol loaded, its display set, the study file's
/// calibration read, then make_context() called (a GL 4.5 context must be
/// current after it) and every condition rendered. Throws InputError and
/// store::StoreError.
Displayability check_protocol(const CheckOptions& options, const std::function<void()>& make_context);

/// The table printed in the run header and by `atonlab check`: one line per
/// condition and end of its range.
std::string displayability_table(const Displayability& d);

/// One sentence per undisplayable condition (file:line: what is not
/// displayable and what to change), newline-separated; "" when all are.
std::string displayability_refusal(const Displayability& d, const std::string& protocol_file);

/// One line per warning (W1), "atonlab: warning: file:line: condition "NAME": ...",
/// newline-separated; "" when there are none.
std::string displayability_warnings(const Displayability& d, const std::string& protocol_file);

/// The JSON stored with the session (sessions.displayability_json; docs/store.md).
/// `allowed`: the session ran with --allow-undisplayable.
/// presentation_json: on screen, the presentation margin measured before the
/// first trial (session/presentation_margin.h), stored as "presentation";
/// empty: none (headless), stored as null.
std::string displayability_json(const Displayability& d, bool allowed, const std::string& presentation_json = {});

}  // namespace atonlab::runner
