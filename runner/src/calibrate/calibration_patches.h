#pragma once
// The patches `atonlab calibrate` shows (docs/calibration.md): full-screen
// uniform code values, 8 bits per channel. A patch's name is what the
// operator sees and what a readings file may give ("grey-128").
#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "atonlab/display/calibration.h"

namespace atonlab::runner {

struct Patch {
    std::string name;               ///< "black", "white", "grey-128", "red-064", ...
    display::Channel channel;       ///< grey for black, white and the grey ramp
    int code = 0;                   ///< code value of the lit channel(s)
    glm::ivec3 rgb{0};              ///< the code values sent (R, G, B)
    static constexpr int bits = 8;  ///< bits per channel of the codes
    static constexpr int max_code = 255;

    /// The drive level of the lit channel(s), code / 255, in [0, 1].
    double level() const { return static_cast<double>(code) / max_code; }
    /// What the operator is told: "grey 128/255 (50.2 %)".
    std::string description() const;
};

/// The measurement set: black, white, the grey ramp (grey_levels codes evenly
/// spaced over 0..255, black and white included; >= 9), then the red, green
/// and blue ramps (colour_levels codes over 0..255, black included and shared
/// with every ramp, so colour_levels - 1 patches each; >= 4). Throws InputError
/// (naming the option) for counts out of range.
std::vector<Patch> measurement_patches(int grey_levels = 17, int colour_levels = 9);

/// The check set: black, grey at 25, 50 and 75 % drive (codes 64, 128, 191) and white.
std::vector<Patch> check_patches();

}  // namespace atonlab::runner
