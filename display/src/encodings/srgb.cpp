// The srgb encoding: IEC 61966-2-1 decoding, scaled between the channel's black and
// white (display_encodings.h; docs/display-calibration.md).
#include <algorithm>
#include <cmath>

#include "atonlab/display/colour.h"
#include "atonlab/display/display_encodings.h"

namespace atonlab::display {
namespace {

// IEC 61966-2-1: the decoder's breakpoint 0.04045 maps to 0.04045 / 12.92 in linear light.
// Written the same way in the GLSL below, so that both sides round them to the same double.
constexpr double kSrgbLinearBreak = 0.0031308049535603713;  // 0.04045 / 12.92
constexpr double kSrgbInvGamma = 0.4166666666666666667;     // 1 / 2.4

double srgb_luminance(const ChannelEncoding& ch, double v) {
    return ch.black_cd_m2 + (ch.white_cd_m2 - ch.black_cd_m2) * srgb_decode(v);
}

double srgb_drive(const ChannelEncoding& ch, double L) {
    // The inverse of srgb_decode (colour.cpp) branch by branch. srgb_decode jumps up by
    // 2.3e-9 at V = 0.04045 (IEC 61966-2-1's rounded constants), so just above the break the
    // power branch's inverse is 3e-8 below 0.04045: the smallest drive reaching those L is
    // 0.04045 itself (issue 8; the drive must never decrease as L rises).
    const double t = (L - ch.black_cd_m2) / (ch.white_cd_m2 - ch.black_cd_m2);
    return t <= kSrgbLinearBreak ? 12.92 * t : std::max(1.055 * std::pow(t, kSrgbInvGamma) - 0.055, 0.04045);
}

constexpr std::string_view kGlsl = R"(double display_drive_srgb(DisplayChannel c, double L) {
    double t = (L - c.black_cd_m2) / (c.white_cd_m2 - c.black_cd_m2);
    // max(): the power branch dips 3e-8 below the break just above it (srgb_drive).
    return t <= 0.0031308049535603713LF ? 12.92LF * t
                                        : max(1.055LF * display_pow(t, 0.4166666666666666667LF) - 0.055LF, 0.04045LF);
})";

DisplayModel srgb_display(double peak_cd_m2, double black_cd_m2) {
    return DisplayModel::srgb(peak_cd_m2, black_cd_m2);
}

}  // namespace

const DisplayEncoding& display_encoding_srgb() {
    static const DisplayEncoding e{.name = "srgb",
                                   .display_name = "sRGB",
                                   .luminance_cd_m2 = srgb_luminance,
                                   .drive_for = srgb_drive,
                                   .glsl = kGlsl,
                                   .glsl_drive_function = "display_drive_srgb",
                                   .from_peak_black = srgb_display};
    return e;
}

DisplayModel DisplayModel::srgb(double peak_cd_m2, double black_cd_m2, std::string name) {
    return display_of_rec709_shares(display_encoding_srgb(), peak_cd_m2, black_cd_m2, std::move(name));
}

}  // namespace atonlab::display
