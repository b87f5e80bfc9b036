// A display encoding of one file, outside the library: a pure power law between
// the channel's black and white, L = black + (white − black) V^gamma, with gamma
// its own parameter. Registered by its one line (register_display_encoding, the
// list's line for an encoding outside the library); test_encode.cpp's
// GpuEncode.AnEncodingOfOneFileIsReadEncodedAndStoredAsTheLibrarysAre draws with it.
#include <fmt/format.h>

#include <cmath>

#include "atonlab/display/display_encodings.h"

namespace atonlab::test {
namespace {

using namespace atonlab::display;

constexpr EncodingParameter kParameters[] = {{"gamma"}};

double toy_luminance(const ChannelEncoding& ch, double v) {
    return ch.black_cd_m2 + (ch.white_cd_m2 - ch.black_cd_m2) * std::pow(v, ch.parameter[0]);
}

double toy_drive(const ChannelEncoding& ch, double L) {
    return std::pow((L - ch.black_cd_m2) / (ch.white_cd_m2 - ch.black_cd_m2), 1.0 / ch.parameter[0]);
}

constexpr std::string_view kGlsl = R"(double display_drive_toy_gamma(DisplayChannel c, double L) {
    return display_pow((L - c.black_cd_m2) / (c.white_cd_m2 - c.black_cd_m2), c.p0);  // p0 = 1 / gamma
})";

std::array<double, 6> toy_gpu(const ChannelEncoding& ch) {
    return {1.0 / ch.parameter[0], 0.0, 0.0, 0.0, 0.0, 0.0};
}

void toy_check(const ChannelEncoding& ch, const ChannelCheck& at) {
    if (!(ch.parameter[0] > 0.0) || !std::isfinite(ch.parameter[0]))
        at.fail("gamma", fmt::format("the toy gamma must be a positive number, not {}", ch.parameter[0]));
}

DisplayModel toy_display(double peak_cd_m2, double black_cd_m2) {
    DisplayModel d = display_of_rec709_shares(*display_encoding_named("toy-gamma"), peak_cd_m2, black_cd_m2, "Toy");
    for (auto& ch : d.channels) ch.parameter[0] = 2.0;
    return d;
}

const DisplayEncoding kToyGamma{.name = "toy-gamma",
                                .display_name = "Toy",
                                .luminance_cd_m2 = toy_luminance,
                                .drive_for = toy_drive,
                                .glsl = kGlsl,
                                .glsl_drive_function = "display_drive_toy_gamma",
                                .from_peak_black = toy_display,
                                .parameters = kParameters,
                                .check = toy_check,
                                .gpu_parameters = toy_gpu};

// The registry line.
const bool kRegistered = register_display_encoding(kToyGamma);

}  // namespace
}  // namespace atonlab::test
