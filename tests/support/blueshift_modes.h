#pragma once
// The blueshift settings the tone-mapping tests sweep (tonemap.h): 0 off,
// 1 σ of the adaptation luminance, 2 σ of each pixel's own luminance.
#include "atonlab/display/tonemap.h"

namespace atonlab::test {

inline constexpr int kBlueshiftModes[] = {0, 1, 2};

inline void set_blueshift(display::ToneMapSettings& s, int mode) {
    s.blueshift = mode != 0;
    s.blueshift_luminance = mode == 1 ? display::BlueshiftLuminance::adaptation : display::BlueshiftLuminance::pixel;
}

inline const char* blueshift_label(int mode) {
    return mode == 0 ? "off" : mode == 1 ? "adaptation" : "pixel";
}

}  // namespace atonlab::test
