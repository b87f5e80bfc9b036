// The gog encoding: gain-offset-gamma with black offset (Berns 1996),
// L = a + (b + k V)^gamma where b + k V > 0, else a (display_encodings.h;
// docs/display-calibration.md). Only a calibration makes it: its parameters are a
// fit's (calibration.h).
#include <fmt/format.h>

#include <cmath>

#include "atonlab/display/display_encodings.h"

namespace atonlab::display {
namespace {

// ChannelEncoding::parameter[]: a (cd/m²), b and k ((cd/m²)^(1/gamma)), gamma.
enum : std::size_t { kA, kB, kK, kGamma };
constexpr EncodingParameter kParameters[] = {{"a"}, {"b"}, {"k"}, {"gamma"}};

double gog_luminance(const ChannelEncoding& ch, double v) {
    const auto& p = ch.parameter;
    const double base = p[kB] + p[kK] * v;
    return base > 0.0 ? p[kA] + std::pow(base, p[kGamma]) : p[kA];
}

double gog_drive(const ChannelEncoding& ch, double L) {
    // L > L(0) >= a here, so the base is positive.
    const auto& p = ch.parameter;
    return (std::pow(L - p[kA], 1.0 / p[kGamma]) - p[kB]) / p[kK];
}

// p0 a, p1 b, p2 k, p3 1 / gamma (computed once here, as the CPU computes it).
constexpr std::string_view kGlsl = R"(double display_drive_gog(DisplayChannel c, double L) {
    return (display_pow(L - c.p0, c.p3) - c.p1) / c.p2;
})";

std::array<double, 6> gog_gpu(const ChannelEncoding& ch) {
    const auto& p = ch.parameter;
    return {p[kA], p[kB], p[kK], 1.0 / p[kGamma], 0.0, 0.0};
}

void gog_check(const ChannelEncoding& ch, const ChannelCheck& at) {
    const auto& p = ch.parameter;
    const std::string cn(at.channel);
    const char* const names[] = {"the GOG offset a", "the GOG offset b", "the GOG gain k", "the GOG gamma"};
    for (std::size_t i = 0; i < 4; ++i)
        if (!std::isfinite(p[i]))
            at.fail(fmt::format("gog.{}", kParameters[i].key), fmt::format("{} is not a finite number", names[i]));
    if (p[kK] <= 0.0)
        at.fail("gog.k", fmt::format("the GOG gain k must be positive (k = {} makes the {} channel's "
                                     "luminance fall or stay flat as the drive rises)",
                                     p[kK], cn));
    if (p[kGamma] <= 0.0)
        at.fail("gog.gamma", fmt::format("the GOG gamma must be positive (gamma = {} makes the {} "
                                         "channel's luminance fall as the drive rises)",
                                         p[kGamma], cn));
    if (p[kB] + p[kK] <= 0.0)
        at.fail("gog.b", fmt::format("b + k = {} is not positive: the {} channel never lights up", p[kB] + p[kK], cn));
    const double l0 = ch.min_cd_m2(), l1 = ch.max_cd_m2();
    if (!std::isfinite(l0) || !std::isfinite(l1))
        at.fail("gog.gamma", fmt::format("the {} channel's GOG curve is not finite", cn));
    if (l0 < 0.0) at.fail("gog.a", fmt::format("the {} channel's luminance at drive 0 is negative ({} cd/m²)", cn, l0));
    if (!(l1 > l0))
        at.fail("gog.k", fmt::format("the {} channel's GOG curve does not rise ({} to {} cd/m²)", cn, l0, l1));
}

}  // namespace

const DisplayEncoding& display_encoding_gog() {
    static const DisplayEncoding e{.name = "gog",
                                   .display_name = "GOG",
                                   .luminance_cd_m2 = gog_luminance,
                                   .drive_for = gog_drive,
                                   .glsl = kGlsl,
                                   .glsl_drive_function = "display_drive_gog",
                                   .parameters = kParameters,
                                   .check = gog_check,
                                   .gpu_parameters = gog_gpu};
    return e;
}

GogParams gog_params_of(const ChannelEncoding& channel) {
    const auto& p = channel.parameter;
    return GogParams{p[kA], p[kB], p[kK], p[kGamma]};
}

DisplayModel DisplayModel::gog(const std::array<GogParams, 3>& channels, std::string name) {
    DisplayModel d;
    d.name = std::move(name);
    for (std::size_t c = 0; c < 3; ++c) {
        d.channels[c].encoding = &display_encoding_gog();
        d.channels[c].parameter = {channels[c].a, channels[c].b, channels[c].k, channels[c].gamma, 0.0, 0.0};
    }
    d.sum_channels();
    return d;
}

}  // namespace atonlab::display
