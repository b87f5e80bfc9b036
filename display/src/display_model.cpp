#include "atonlab/display/display_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <cassert>
#include <cmath>

#include "atonlab/display/colour.h"
#include "atonlab/display/display_encodings.h"

namespace atonlab::display {
namespace {

const char* channel_name(int c) {
    static constexpr const char* names[3] = {"red", "green", "blue"};
    return names[c];
}

// ---------------------------------------------------------------------------
// Dither: integer hashing only, so the CPU and the GPU agree bit for bit.

/// "lowbias32" integer hash (C. Wellons, hash-prospector): full avalanche, no float.
std::uint32_t hash32(std::uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

/// Index 0..4095 of (x, y) in the 64×64 Bayer (ordered-dither) matrix: each
/// 2×2 level contributes the digit of [[0, 2], [3, 1]], the finest level most
/// significant. Every 64×64 window holds each index exactly once.
std::uint32_t bayer64(std::uint32_t x, std::uint32_t y) {
    std::uint32_t v = 0;
    for (std::uint32_t i = 0; i < 6; ++i) {
        const std::uint32_t xb = (x >> i) & 1u, yb = (y >> i) & 1u;
        v = (v << 2) | (((xb ^ yb) << 1) | yb);
    }
    return v;
}

void check_bits(int bits) {
    if (bits < 1 || bits > 16)
        throw InputError(SourceLocation{"", 0, 0, "bits"},
                         fmt::format("the frame buffer depth must be 1 to 16 bits per channel, not {}", bits));
}

}  // namespace

// ---------------------------------------------------------------------------
// One channel: its encoding's law (display_encodings.h).

double ChannelEncoding::luminance_cd_m2(double drive) const {
    const double v = std::isnan(drive) ? 0.0 : std::clamp(drive, 0.0, 1.0);
    return encoding->luminance_cd_m2(*this, v);
}

double ChannelEncoding::min_cd_m2() const {
    return luminance_cd_m2(0.0);
}
double ChannelEncoding::max_cd_m2() const {
    return luminance_cd_m2(1.0);
}

double ChannelEncoding::drive_for(double L_cd_m2) const {
    const double lmin = min_cd_m2(), lmax = max_cd_m2();
    // Below (or at) black, and NaN: drive 0, the smallest drive that gives L(0).
    if (!(L_cd_m2 > lmin)) return 0.0;
    const double L = std::min(L_cd_m2, lmax);
    return std::clamp(encoding->drive_for(*this, L), 0.0, 1.0);
}

bool ChannelEncoding::follows(std::string_view encoding_name) const {
    return encoding->name == encoding_name;
}

// ---------------------------------------------------------------------------
// The display.

void DisplayModel::sum_channels() {
    peak_cd_m2 = 0.0;
    black_cd_m2 = 0.0;
    for (const auto& ch : channels) {
        peak_cd_m2 += ch.max_cd_m2();
        black_cd_m2 += ch.min_cd_m2();
    }
}

void DisplayModel::validate(const SourceLocation& where) const {
    auto fail = [&](const std::string& field, const std::string& message) {
        ChannelCheck{where, name, {}}.fail_display(field, message);
    };
    auto finite = [](double x) { return std::isfinite(x); };

    // Each channel's own parameters first (a NaN gamma would otherwise surface as a NaN peak),
    // then the display's peak and black, then the channels against them.
    for (int c = 0; c < 3; ++c) {
        const auto& ch = channels[static_cast<std::size_t>(c)];
        if (ch.encoding->check != nullptr) ch.encoding->check(ch, ChannelCheck{where, name, channel_name(c)});
    }

    if (!finite(peak_cd_m2) || peak_cd_m2 <= 0.0)
        fail("peak_cd_m2", fmt::format("the peak luminance must be a positive number of cd/m², not {}", peak_cd_m2));
    if (!finite(black_cd_m2) || black_cd_m2 < 0.0)
        fail("black_cd_m2", fmt::format("the black luminance must be zero or more cd/m², not {}", black_cd_m2));
    if (black_cd_m2 >= peak_cd_m2)
        fail("black_cd_m2",
             fmt::format("the black luminance ({} cd/m²) must be below the peak ({} cd/m²)", black_cd_m2, peak_cd_m2));

    // The channels of the laws made from a black and a white alone (sRGB, PQ;
    // display_encodings.h): their share of black and peak.
    for (int c = 0; c < 3; ++c) {
        const auto& ch = channels[static_cast<std::size_t>(c)];
        const std::string cn = channel_name(c);
        if (ch.encoding->from_peak_black == nullptr) continue;
        if (!finite(ch.black_cd_m2) || ch.black_cd_m2 < 0.0)
            fail(cn + ".black_cd_m2", fmt::format("the {} channel's black must be zero or more cd/m²", cn));
        if (!finite(ch.white_cd_m2) || ch.white_cd_m2 <= ch.black_cd_m2)
            fail(cn + ".white_cd_m2",
                 fmt::format("the {} channel's white ({} cd/m²) must be above its black ({} cd/m²)", cn, ch.white_cd_m2,
                             ch.black_cd_m2));
    }

    // The channels add up to the display's white and black.
    double sum_max = 0.0, sum_min = 0.0;
    for (const auto& ch : channels) {
        sum_max += ch.max_cd_m2();
        sum_min += ch.min_cd_m2();
    }
    if (std::abs(sum_max - peak_cd_m2) > 1e-6 * peak_cd_m2)
        fail("peak_cd_m2", fmt::format("the peak ({} cd/m²) is not the sum of the channels' full-drive luminances "
                                       "({} cd/m²)",
                                       peak_cd_m2, sum_max));
    if (std::abs(sum_min - black_cd_m2) > 1e-6 * peak_cd_m2)
        fail("black_cd_m2", fmt::format("the black ({} cd/m²) is not the sum of the channels' zero-drive luminances "
                                        "({} cd/m²)",
                                        black_cd_m2, sum_min));
}

double DisplayModel::channel_luminance_cd_m2(int channel, double drive) const {
    assert(channel >= 0 && channel < 3);
    return channels[static_cast<std::size_t>(channel)].luminance_cd_m2(drive);
}

double DisplayModel::drive_for_luminance(int channel, double L_cd_m2) const {
    assert(channel >= 0 && channel < 3);
    return channels[static_cast<std::size_t>(channel)].drive_for(L_cd_m2);
}

// ---------------------------------------------------------------------------
// The encoder.

double dither_threshold(glm::ivec2 pixel, std::uint32_t frame, int channel, std::uint32_t seed) {
    // Per channel and seed: a tile offset and a phase (so R, G, B and runs are decorrelated).
    const std::uint32_t key = hash32(seed + 0x9e3779b9u * (static_cast<std::uint32_t>(channel) + 1u));
    const std::uint32_t x = static_cast<std::uint32_t>(pixel.x) + (key & 63u);
    const std::uint32_t y = static_cast<std::uint32_t>(pixel.y) + ((key >> 6) & 63u);
    // Bayer rank in the top 12 bits (+ half a step: the centre of its stratum), then
    // the frame's golden-ratio shift (0x9e3779b9 = 2^32 (sqrt 5 - 1) / 2) and the phase.
    const std::uint32_t phase =
        (bayer64(x & 63u, y & 63u) << 20) + 0x80000u + frame * 0x9e3779b9u + hash32(key ^ 0x5bd1e995u);
    return static_cast<double>(phase >> 8) * 0x1p-24;
}

glm::dvec3 channel_weights(const DisplayModel& display) {
    glm::dvec3 w(0.0);
    for (int c = 0; c < 3; ++c) w[c] = display.channels[static_cast<std::size_t>(c)].max_cd_m2();
    return w / (w.r + w.g + w.b);
}

glm::ivec3 encode_pixel(const DisplayModel& display, glm::dvec3 relative_rgb, glm::ivec2 pixel, std::uint32_t frame,
                        const EncodeSettings& settings) {
    check_bits(settings.bits);
    const int max_code = (1 << settings.bits) - 1;
    // By default luminance wins over chroma (docs/tone-mapping.md "Adding light never darkens"
    // and "Out of gamut: colour or luminance").
    const glm::dvec3 shown = fit_to_gamut(relative_rgb, channel_weights(display), settings.out_of_gamut);
    glm::ivec3 code(0);
    for (int c = 0; c < 3; ++c) {
        const auto& ch = display.channels[static_cast<std::size_t>(c)];
        const double d = shown[c];
        const double v = ch.drive_for(d * ch.max_cd_m2());
        const double u = settings.dither == Dither::none ? 0.5 : dither_threshold(pixel, frame, c, settings.seed);
        const double q = std::floor(v * static_cast<double>(max_code) + u);
        code[c] = static_cast<int>(std::clamp(q, 0.0, static_cast<double>(max_code)));
    }
    return code;
}

glm::dvec3 displayed_luminance_rgb(const DisplayModel& display, glm::ivec3 code, int bits) {
    check_bits(bits);
    const int max_code = (1 << bits) - 1;
    glm::dvec3 L(0.0);
    for (int c = 0; c < 3; ++c) {
        const double v = static_cast<double>(std::clamp(code[c], 0, max_code)) / static_cast<double>(max_code);
        L[c] = display.channels[static_cast<std::size_t>(c)].luminance_cd_m2(v);
    }
    return L;
}

double displayed_luminance_cd_m2(const DisplayModel& display, glm::ivec3 code, int bits) {
    const glm::dvec3 L = displayed_luminance_rgb(display, code, bits);
    return L.r + L.g + L.b;
}

// ---------------------------------------------------------------------------
// GPU parameters.

GpuDisplayParams gpu_display_params(const DisplayModel& display, const EncodeSettings& settings) {
    display.validate();
    check_bits(settings.bits);
    GpuDisplayParams p{};
    std::int32_t first = 0;
    for (std::size_t c = 0; c < 3; ++c) {
        const auto& ch = display.channels[c];
        auto& g = p.channel[c];
        g.black_cd_m2 = ch.min_cd_m2();
        g.white_cd_m2 = ch.max_cd_m2();
        const std::array<double, 6> parameter =
            ch.encoding->gpu_parameters != nullptr ? ch.encoding->gpu_parameters(ch) : ch.parameter;
        std::copy(parameter.begin(), parameter.end(), g.parameter);
        g.kind = display_encoding_index(*ch.encoding);
        if (ch.encoding->gpu_knots != nullptr) {
            g.lut_first = first;
            g.lut_count = static_cast<std::int32_t>(ch.encoding->gpu_knots(ch).size() / 3);
            first += g.lut_count;
        }
    }
    p.bits = settings.bits;
    p.dither = static_cast<std::int32_t>(settings.dither);
    p.seed = settings.seed;
    p.out_of_gamut = static_cast<std::uint32_t>(settings.out_of_gamut);
    return p;
}

std::vector<double> gpu_display_lut(const DisplayModel& display) {
    std::vector<double> out;
    for (const auto& ch : display.channels) {
        if (ch.encoding->gpu_knots == nullptr) continue;
        const std::vector<double> knots = ch.encoding->gpu_knots(ch);
        out.insert(out.end(), knots.begin(), knots.end());
    }
    if (out.empty()) out.assign(3, 0.0);
    return out;
}

}  // namespace atonlab::display
