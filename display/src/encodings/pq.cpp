// The pq encoding: the SMPTE ST 2084 EOTF (absolute), each channel its Rec.709
// share of it, clipped to the display's black and peak (display_encodings.h;
// docs/display-calibration.md).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "atonlab/display/display_encodings.h"

namespace atonlab::display {
namespace {

// SMPTE ST 2084:2014 constants, eq 4.1/5.1 of the standard; all are exact binary fractions,
// written the same way in the GLSL below.
constexpr double kPqM1 = 2610.0 / 16384.0;         // 0.1593017578125
constexpr double kPqM2 = 2523.0 / 4096.0 * 128.0;  // 78.84375
constexpr double kPqC1 = 3424.0 / 4096.0;          // 0.8359375 = c3 - c2 + 1
constexpr double kPqC2 = 2413.0 / 4096.0 * 32.0;   // 18.8515625
constexpr double kPqC3 = 2392.0 / 4096.0 * 32.0;   // 18.6875
constexpr double kPqPeak = 10000.0;                // cd/m² at signal 1

// ChannelEncoding::parameter[0]: the channel's weight, its share of an achromatic stimulus.
// A fit JSON channel written before the weight was stored: its share of the peak.
constexpr EncodingParameter kParameters[] = {
    {"pq_weight", [](const ChannelEncoding& ch, double peak_cd_m2) { return ch.white_cd_m2 / peak_cd_m2; }}};

double pq_luminance(const ChannelEncoding& ch, double v) {
    return std::clamp(ch.parameter[0] * pq_eotf_cd_m2(v), ch.black_cd_m2, ch.white_cd_m2);
}

double pq_drive(const ChannelEncoding& ch, double L) {
    const double ym1 = std::pow((L / ch.parameter[0]) / kPqPeak, kPqM1);
    return std::pow((kPqC1 + kPqC2 * ym1) / (1.0 + kPqC3 * ym1), kPqM2);
}

// p0: the weight. The inverse EOTF of L / weight.
constexpr std::string_view kGlsl = R"(double display_drive_pq(DisplayChannel c, double L) {
    double ym1 = display_pow((L / c.p0) / 10000.0LF, 0.1593017578125LF);
    return display_pow((0.8359375LF + 18.8515625LF * ym1) / (1.0LF + 18.6875LF * ym1), 78.84375LF);
})";

void pq_check(const ChannelEncoding& ch, const ChannelCheck& at) {
    const double weight = ch.parameter[0];
    if (!std::isfinite(weight) || weight <= 0.0)
        at.fail("pq_weight", fmt::format("the {} channel's PQ weight must be positive", at.channel));
    if (ch.white_cd_m2 > weight * kPqPeak * (1.0 + 1e-12))
        at.fail_display("peak_cd_m2", fmt::format("a PQ display cannot show more than {} cd/m²", kPqPeak));
}

DisplayModel pq_display(double peak_cd_m2, double black_cd_m2) {
    return DisplayModel::pq(peak_cd_m2, black_cd_m2);
}

}  // namespace

const DisplayEncoding& display_encoding_pq() {
    static const DisplayEncoding e{.name = "pq",
                                   .display_name = "PQ",
                                   .luminance_cd_m2 = pq_luminance,
                                   .drive_for = pq_drive,
                                   .glsl = kGlsl,
                                   .glsl_drive_function = "display_drive_pq",
                                   .from_peak_black = pq_display,
                                   .parameters = kParameters,
                                   .check = pq_check};
    return e;
}

double pq_eotf_cd_m2(double signal) {
    const double n = std::isnan(signal) ? 0.0 : std::clamp(signal, 0.0, 1.0);
    const double p = std::pow(n, 1.0 / kPqM2);
    return kPqPeak * std::pow(std::max(p - kPqC1, 0.0) / (kPqC2 - kPqC3 * p), 1.0 / kPqM1);
}

double pq_inverse_eotf(double L_cd_m2) {
    const double y = std::isnan(L_cd_m2) ? 0.0 : std::clamp(L_cd_m2 / kPqPeak, 0.0, 1.0);
    const double ym1 = std::pow(y, kPqM1);
    return std::pow((kPqC1 + kPqC2 * ym1) / (1.0 + kPqC3 * ym1), kPqM2);
}

DisplayModel DisplayModel::pq(double peak_cd_m2, double black_cd_m2, std::string name) {
    DisplayModel d = display_of_rec709_shares(display_encoding_pq(), peak_cd_m2, black_cd_m2, std::move(name));
    for (int c = 0; c < 3; ++c) d.channels[static_cast<std::size_t>(c)].parameter[0] = rec709_channel_share(c);
    return d;
}

}  // namespace atonlab::display
