#include "calibration_patches.h"

#include <fmt/format.h>

#include <cmath>

#include "atonlab/stimuli/error.h"

namespace atonlab::runner {
namespace {

Patch make_patch(display::Channel channel, int code) {
    Patch p;
    p.channel = channel;
    p.code = code;
    switch (channel) {
        case display::Channel::red:
            p.rgb = {code, 0, 0};
            break;
        case display::Channel::green:
            p.rgb = {0, code, 0};
            break;
        case display::Channel::blue:
            p.rgb = {0, 0, code};
            break;
        default:
            p.rgb = glm::ivec3(code);
    }
    if (channel == display::Channel::grey && code == 0)
        p.name = "black";
    else if (channel == display::Channel::grey && code == Patch::max_code)
        p.name = "white";
    else
        p.name = fmt::format("{}-{:03d}", display::channel_name(channel), code);
    return p;
}

/// n codes evenly spaced over 0..255, rounded to the nearest code (halves up).
std::vector<int> ramp_codes(int n) {
    std::vector<int> codes;
    for (int i = 0; i < n; ++i)
        codes.push_back(static_cast<int>(std::floor(static_cast<double>(i) * Patch::max_code / (n - 1) + 0.5)));
    return codes;
}

}  // namespace

std::string Patch::description() const {
    if (name == "black" || name == "white") return fmt::format("{} ({} {} {})", name, rgb.r, rgb.g, rgb.b);
    return fmt::format("{} {}/{} ({:.1f} %)", display::channel_name(channel), code, max_code, 100.0 * level());
}

std::vector<Patch> measurement_patches(int grey_levels, int colour_levels) {
    if (grey_levels < 9 || grey_levels > 256)
        throw InputError(
            SourceLocation::command_line("--grey-levels"),
            fmt::format("the grey ramp needs 9 to 256 levels (black and white included), not {}.", grey_levels));
    if (colour_levels < 4 || colour_levels > 256)
        throw InputError(
            SourceLocation::command_line("--colour-levels"),
            fmt::format("each colour ramp needs 4 to 256 levels (black included) for a fit, not {}.", colour_levels));
    std::vector<Patch> out{make_patch(display::Channel::grey, 0), make_patch(display::Channel::grey, Patch::max_code)};
    for (int code : ramp_codes(grey_levels))
        if (code != 0 && code != Patch::max_code) out.push_back(make_patch(display::Channel::grey, code));
    for (const auto ch : {display::Channel::red, display::Channel::green, display::Channel::blue})
        for (int code : ramp_codes(colour_levels))
            if (code != 0) out.push_back(make_patch(ch, code));
    return out;
}

std::vector<Patch> check_patches() {
    std::vector<Patch> out;
    // 25, 50, 75 % of 255 are 63.75, 127.5, 191.25: the nearest codes (halves up).
    for (int code : {0, 64, 128, 191, Patch::max_code}) out.push_back(make_patch(display::Channel::grey, code));
    return out;
}

}  // namespace atonlab::runner
