#pragma once
// The display encodings: the one list of the laws a display channel can follow
// (docs/architecture.md "How to add a display encoding"). An encoding is one file,
// display/src/encodings/NAME.cpp, defining display_encoding_NAME(): its name (a
// scene's `[display] encoding`, a calibration's fit JSON, `atonlab tonemap
// --encoding`, Python's `Frame.display["encoding"]`), its CPU law (L(V) and its
// inverse: the reference), its parameters (their keys in the fit JSON, their checks
// and their GPU packing), its GLSL twin and, for a law a peak and a black define,
// the display it makes from them. The GPU's dispatch over the encodings and their
// GLSL functions are generated from this list (display_encodings_glsl), so the CPU
// and the GPU cannot disagree on which law a channel follows.
#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/display/display_model.h"

namespace atonlab::display {

/// One of an encoding's own parameters: ChannelEncoding::parameter[i] is the
/// i-th of its encoding's `parameters`.
struct EncodingParameter {
    std::string_view key;  ///< its key in a calibration's fit JSON channel ("gamma")
    /// Its value for a fit JSON channel written before the parameter was stored
    /// (null: the key is required). Given the channel (black, white read) and the display's peak, cd/m².
    double (*missing)(const ChannelEncoding& channel, double display_peak_cd_m2) = nullptr;
};

/// Where an encoding's check of one channel reports a problem: fail() throws
/// InputError at `where`'s key + "." + channel + "." + key, naming the display.
struct ChannelCheck {
    const SourceLocation& where;
    std::string_view display;  ///< DisplayModel::name
    std::string_view channel;  ///< "red", "green" or "blue"
    [[noreturn]] void fail(const std::string& key, const std::string& message) const;
    /// As fail(), for a key of the whole display ("peak_cd_m2").
    [[noreturn]] void fail_display(const std::string& key, const std::string& message) const;
};

struct DisplayEncoding {
    std::string_view name = {};          ///< as files and options spell it ("srgb")
    std::string_view display_name = {};  ///< DisplayModel::name of a display made with it and no name of its own
    /// The CPU law: L(V) in cd/m² for V already clamped to [0, 1] (ChannelEncoding::luminance_cd_m2).
    double (*luminance_cd_m2)(const ChannelEncoding& channel, double drive) = nullptr;
    /// Its inverse for L within (L(0), L(1)] (ChannelEncoding::drive_for clamps the result to [0, 1]).
    double (*drive_for)(const ChannelEncoding& channel, double L_cd_m2) = nullptr;
    /// Its GLSL: the definition of `double NAME(DisplayChannel c, double L)`, the twin of
    /// drive_for, with any helper it needs (display_encode.glsl's display_pow,
    /// display_log, display_exp and display_lut[] are in scope). It reads its parameters as
    /// c.p0 … c.p5 (gpu_parameters) and its knots from display_lut[3 * (c.lut_first + i)].
    std::string_view glsl = {};
    std::string_view glsl_drive_function = {};  ///< the NAME the glsl defines
    /// The display the law makes from a peak and a black alone (cd/m²; Rec.709
    /// channel shares); null for the laws only a calibration gives (gog, lut).
    DisplayModel (*from_peak_black)(double peak_cd_m2, double black_cd_m2) = nullptr;
    /// Its own parameters, in ChannelEncoding::parameter's order (at most kEncodingParameters).
    std::span<const EncodingParameter> parameters = {};
    /// Its knots' key in the fit JSON (the `[drive, cd_m2]` pairs of ChannelEncoding::lut);
    /// empty for a law without knots.
    std::string_view knots_key = {};
    /// Its checks of a channel's parameters and knots, before the display's peak and black
    /// are checked (null: none). A law made from a black and a white
    /// has those checked afterwards against the display's.
    void (*check)(const ChannelEncoding& channel, const ChannelCheck& at) = nullptr;
    /// The channel's parameters as the GPU reads them, p0 … p5 (null: parameter[] as it is).
    std::array<double, 6> (*gpu_parameters)(const ChannelEncoding& channel) = nullptr;
    /// The channel's knots as the GPU reads them, three doubles each (null: none).
    std::vector<double> (*gpu_knots)(const ChannelEncoding& channel) = nullptr;
};

/// Every encoding: the library's, in their list's order, then any registered.
std::span<const DisplayEncoding* const> display_encodings();
/// The encoding of that name; throws std::logic_error for a name no encoding has
/// (for names spelled in code: input goes through display_encoding_named).
const DisplayEncoding& display_encoding(std::string_view name);
const DisplayEncoding* display_encoding_named(std::string_view name);
/// Its place in display_encodings(): the kind the GPU reads (GpuDisplayChannel::kind).
int display_encoding_index(const DisplayEncoding& encoding);
/// Adds an encoding defined outside the library (a test's, a lab's own law) to the
/// list: the list's line for it. Call it before the first shader is compiled (at
/// static initialisation, as a registrar object does). Returns true; throws
/// std::logic_error for a name already taken.
bool register_display_encoding(const DisplayEncoding& encoding);

/// A display whose three channels follow `encoding`, each with its Rec.709 share
/// (rec709_channel_share) of peak and black (cd/m²): the display from_peak_black
/// makes, but for the encoding's own parameters, which it sets afterwards.
DisplayModel display_of_rec709_shares(const DisplayEncoding& encoding, double peak_cd_m2, double black_cd_m2,
                                      std::string name);
/// Rec.709's luminance share of channel c (0 red, 1 green, 2 blue), from the primaries
/// (colour.h), so that the three sum to Y exactly as luminance_of_linear_rgb computes it.
double rec709_channel_share(int channel);

/// The display an encoding's name makes from peak and black (the laws with
/// from_peak_black); nullopt for an unknown name or a fitted law.
std::optional<DisplayModel> display_from_encoding(std::string_view name, double peak_cd_m2, double black_cd_m2);
/// The names display_from_encoding takes (all names when `all`), each in
/// `quote`, as "a or b" / "a, b, c or d": for error messages and help texts.
std::string display_encoding_choices(std::string_view quote, bool all = false);
/// The encoding every channel of `display` follows; nullptr when they differ.
const DisplayEncoding* display_encoding_of(const DisplayModel& display);

/// GLSL: each encoding's glsl, then display_drive_by_kind(DisplayChannel c, double L)
/// calling each one's glsl_drive_function for its kind. display_encode.glsl includes it
/// as "display_encodings.glsl" (stimuli's shader loader makes it from this list).
std::string display_encodings_glsl();

}  // namespace atonlab::display
