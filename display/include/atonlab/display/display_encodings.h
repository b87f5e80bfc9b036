#pragma once
// The display encodings: the one list of the transfer laws a display channel
// can follow (docs/architecture.md "How to add a display encoding"). Each entry
// pairs the law's name (a scene's [display] transfer, a calibration's fit JSON,
// `atonlab tonemap --display`) with its CPU law (L(V) and its inverse, the
// reference) and the name of its GLSL twin in stimuli/shaders/display_encode.glsl;
// the GPU's dispatch over them is generated from this list
// (display_encodings_glsl), so the two cannot disagree on which law a kind is.
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "atonlab/display/display_model.h"

namespace atonlab::display {

struct DisplayEncoding {
    TransferKind kind;
    std::string_view name;          ///< as files and options spell it ("srgb")
    std::string_view display_name;  ///< DisplayModel::name of a display made with it and no name of its own
    /// The CPU law: L(V) in cd/m² for V already clamped to [0, 1] (ChannelTransfer::luminance_cd_m2).
    double (*luminance_cd_m2)(const ChannelTransfer& channel, double drive);
    /// Its inverse for L within (L(0), L(1)] (ChannelTransfer::drive_for clamps the result to [0, 1]).
    double (*drive_for)(const ChannelTransfer& channel, double L_cd_m2);
    /// The GLSL twin of drive_for in display_encode.glsl: double f(DisplayChannel c, double L).
    std::string_view glsl_drive_function;
    /// The display the law makes from a peak and a black alone (cd/m²; Rec.709
    /// channel shares); null for the laws only a calibration gives (gog, lut).
    DisplayModel (*from_peak_black)(double peak_cd_m2, double black_cd_m2);
};

/// Every encoding, in TransferKind's order.
std::span<const DisplayEncoding> display_encodings();
const DisplayEncoding& display_encoding(TransferKind kind);
const DisplayEncoding* display_encoding_named(std::string_view name);

/// The display a transfer name makes from peak and black (the laws with
/// from_peak_black); nullopt for an unknown name or a fitted law.
std::optional<DisplayModel> display_from_transfer(std::string_view name, double peak_cd_m2, double black_cd_m2);
/// The names display_from_transfer takes (all names when `all`), each in
/// `quote`, as "a or b" / "a, b, c or d": for error messages and help texts.
std::string display_encoding_choices(std::string_view quote, bool all = false);
/// The encoding every channel of `display` follows; nullptr when they differ.
const DisplayEncoding* display_encoding_of(const DisplayModel& display);

/// GLSL: display_drive_by_kind(DisplayChannel c, double L), calling each
/// encoding's glsl_drive_function for its kind. display_encode.glsl includes it
/// as "display_encodings.glsl" (stimuli's shader loader makes it from this list).
std::string display_encodings_glsl();

}  // namespace atonlab::display
