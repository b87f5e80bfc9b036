#pragma once
// The CPU transfer laws of display_encodings.h, defined in display_model.cpp
// beside the constants and the interpolation they share. Not installed.
#include "atonlab/display/display_model.h"

namespace atonlab::display::transfer_law {

// L(V) for V in [0, 1], cd/m²; drive(L) for L in (L(0), L(1)] (unclamped).
double srgb_luminance(const ChannelTransfer& ch, double v);
double srgb_drive(const ChannelTransfer& ch, double L);
double gog_luminance(const ChannelTransfer& ch, double v);
double gog_drive(const ChannelTransfer& ch, double L);
double lut_luminance(const ChannelTransfer& ch, double v);
double lut_drive(const ChannelTransfer& ch, double L);
double pq_luminance(const ChannelTransfer& ch, double v);
double pq_drive(const ChannelTransfer& ch, double L);

}  // namespace atonlab::display::transfer_law
