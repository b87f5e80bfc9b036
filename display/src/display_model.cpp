#include "atonlab/display/display_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <span>

#include "atonlab/display/colour.h"
#include "atonlab/display/display_encodings.h"
#include "transfer_laws.h"

namespace atonlab::display {
namespace {

// ---------------------------------------------------------------------------
// Constants shared with stimuli/shaders/display_encode.glsl. Every literal here is
// written the same way there, so that both sides round it to the same double.

// SMPTE ST 2084:2014 (PQ) constants, eq 4.1/5.1 of the standard; all are exact binary fractions.
constexpr double kPqM1 = 2610.0 / 16384.0;         // 0.1593017578125
constexpr double kPqM2 = 2523.0 / 4096.0 * 128.0;  // 78.84375
constexpr double kPqC1 = 3424.0 / 4096.0;          // 0.8359375 = c3 - c2 + 1
constexpr double kPqC2 = 2413.0 / 4096.0 * 32.0;   // 18.8515625
constexpr double kPqC3 = 2392.0 / 4096.0 * 32.0;   // 18.6875
constexpr double kPqPeak = 10000.0;                // cd/m² at signal 1

// IEC 61966-2-1: the decoder's breakpoint 0.04045 maps to 0.04045 / 12.92 in linear light.
constexpr double kSrgbLinearBreak = 0.0031308049535603713;  // 0.04045 / 12.92
constexpr double kSrgbInvGamma = 0.4166666666666666667;     // 1 / 2.4

const char* channel_name(int c) {
    static constexpr const char* names[3] = {"red", "green", "blue"};
    return names[c];
}

/// Rec.709 luminance weight of channel c, derived from the primaries (colour.h),
/// so that Σ channels = Y exactly as luminance_of_linear_rgb computes it.
double rec709_weight(int c) {
    return rec709_rgb_to_xyz()[c][1];
}

double srgb_encode_exact(double t) {
    // The inverse of srgb_decode (colour.cpp) branch by branch. srgb_decode jumps up by
    // 2.3e-9 at V = 0.04045 (IEC 61966-2-1's rounded constants), so just above the break the
    // power branch's inverse is 3e-8 below 0.04045: the smallest drive reaching those L is
    // 0.04045 itself (issue 8; the drive must never decrease as L rises).
    return t <= kSrgbLinearBreak ? 12.92 * t : std::max(1.055 * std::pow(t, kSrgbInvGamma) - 0.055, 0.04045);
}

// ---------------------------------------------------------------------------
// Monotone cubic interpolation (Fritsch & Carlson 1980, with the Fritsch–Butland
// weighted harmonic mean at interior knots and the three-point shape-preserving
// end condition, as in SciPy's PchipInterpolator). Slopes are local: knot j's
// slope needs only the intervals beside it, so nothing has to be cached.

double sign_of(double x) {
    return static_cast<double>((x > 0.0) - (x < 0.0));
}

double pchip_end_slope(double h0, double h1, double d0, double d1) {
    double m = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
    if (sign_of(m) != sign_of(d0)) {
        m = 0.0;
    } else if (sign_of(d0) != sign_of(d1) && std::abs(m) > 3.0 * std::abs(d0)) {
        m = 3.0 * d0;
    }
    return m;
}

double pchip_slope(std::span<const LutPoint> p, std::size_t j) {
    const std::size_t n = p.size();
    auto h = [&](std::size_t k) { return p[k + 1].drive - p[k].drive; };
    auto d = [&](std::size_t k) { return (p[k + 1].cd_m2 - p[k].cd_m2) / h(k); };
    if (n == 2) return d(0);
    if (j == 0) return pchip_end_slope(h(0), h(1), d(0), d(1));
    if (j == n - 1) return pchip_end_slope(h(n - 2), h(n - 3), d(n - 2), d(n - 3));
    const double dl = d(j - 1), dr = d(j);
    if (dl <= 0.0 || dr <= 0.0) return 0.0;  // a flat side (data are non-decreasing): keep it flat
    const double w1 = 2.0 * h(j) + h(j - 1), w2 = h(j) + 2.0 * h(j - 1);
    return (w1 + w2) / (w1 / dl + w2 / dr);
}

/// Cubic Hermite segment in power form: L(t) - L0 = t (c1 + t (c2 + t c3)), t in [0, 1].
struct HermiteSegment {
    double c1, c2, c3;
    double eval(double t) const { return t * (c1 + t * (c2 + t * c3)); }
    double deriv(double t) const { return c1 + t * (2.0 * c2 + t * 3.0 * c3); }
};

HermiteSegment hermite(double h, double L0, double L1, double m0, double m1) {
    const double delta = L1 - L0;
    return {h * m0, 3.0 * delta - 2.0 * h * m0 - h * m1, -2.0 * delta + h * m0 + h * m1};
}

double lut_luminance(std::span<const LutPoint> p, double v) {
    assert(p.size() >= 2);
    if (v <= p.front().drive) return p.front().cd_m2;
    if (v >= p.back().drive) return p.back().cd_m2;
    std::size_t lo = 0, hi = p.size() - 1;
    while (hi - lo > 1) {
        const std::size_t mid = (lo + hi) / 2;
        if (p[mid].drive <= v) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    const double h = p[hi].drive - p[lo].drive;
    const auto seg = hermite(h, p[lo].cd_m2, p[hi].cd_m2, pchip_slope(p, lo), pchip_slope(p, hi));
    return p[lo].cd_m2 + seg.eval((v - p[lo].drive) / h);
}

/// Solves seg.eval(t) = y for t in [0, 1] with y in (0, delta]: Newton steps,
/// falling back to bisection whenever a step leaves the bracket. The GLSL twin
/// (display_lut_drive) runs the same iteration.
double solve_segment(const HermiteSegment& seg, double y, double delta) {
    double lo = 0.0, hi = 1.0;
    double t = y / delta;
    for (int i = 0; i < 64; ++i) {
        const double f = seg.eval(t) - y;
        if (f < 0.0) {
            lo = t;
        } else {
            hi = t;
        }
        double next = t - f / seg.deriv(t);
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // also catches a zero derivative (NaN/inf)
        const bool done = std::abs(next - t) <= 1e-15 || hi - lo <= 1e-15;
        t = next;
        if (done) break;
    }
    return t;
}

double lut_drive(std::span<const LutPoint> p, double L) {
    // Called with L strictly inside (L(0), L(1)): find the first segment with L0 < L <= L1.
    std::size_t lo = 0, hi = p.size() - 1;
    while (hi - lo > 1) {
        const std::size_t mid = (lo + hi) / 2;
        if (p[mid].cd_m2 < L) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    const double h = p[hi].drive - p[lo].drive;
    const double delta = p[hi].cd_m2 - p[lo].cd_m2;
    const auto seg = hermite(h, p[lo].cd_m2, p[hi].cd_m2, pchip_slope(p, lo), pchip_slope(p, hi));
    return p[lo].drive + solve_segment(seg, L - p[lo].cd_m2, delta) * h;
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
// PQ.

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

// ---------------------------------------------------------------------------
// One channel.

// The laws (display_encodings.h pairs each with its GLSL twin).

namespace transfer_law {

double srgb_luminance(const ChannelTransfer& ch, double v) {
    return ch.black_cd_m2 + (ch.white_cd_m2 - ch.black_cd_m2) * srgb_decode(v);
}
double srgb_drive(const ChannelTransfer& ch, double L) {
    return srgb_encode_exact((L - ch.black_cd_m2) / (ch.white_cd_m2 - ch.black_cd_m2));
}

double gog_luminance(const ChannelTransfer& ch, double v) {
    const double base = ch.gog.b + ch.gog.k * v;
    return base > 0.0 ? ch.gog.a + std::pow(base, ch.gog.gamma) : ch.gog.a;
}
double gog_drive(const ChannelTransfer& ch, double L) {
    // L > L(0) >= a here, so the base is positive.
    return (std::pow(L - ch.gog.a, 1.0 / ch.gog.gamma) - ch.gog.b) / ch.gog.k;
}

double lut_luminance(const ChannelTransfer& ch, double v) {
    return display::lut_luminance(ch.lut, v);
}
double lut_drive(const ChannelTransfer& ch, double L) {
    return L >= ch.max_cd_m2() ? 1.0 : display::lut_drive(ch.lut, L);
}

double pq_luminance(const ChannelTransfer& ch, double v) {
    return std::clamp(ch.pq_weight * pq_eotf_cd_m2(v), ch.black_cd_m2, ch.white_cd_m2);
}
double pq_drive(const ChannelTransfer& ch, double L) {
    const double ym1 = std::pow((L / ch.pq_weight) / kPqPeak, kPqM1);
    return std::pow((kPqC1 + kPqC2 * ym1) / (1.0 + kPqC3 * ym1), kPqM2);
}

}  // namespace transfer_law

// ---------------------------------------------------------------------------
// One channel.

double ChannelTransfer::luminance_cd_m2(double drive) const {
    const double v = std::isnan(drive) ? 0.0 : std::clamp(drive, 0.0, 1.0);
    return display_encoding(kind).luminance_cd_m2(*this, v);
}

double ChannelTransfer::min_cd_m2() const {
    return luminance_cd_m2(0.0);
}
double ChannelTransfer::max_cd_m2() const {
    return luminance_cd_m2(1.0);
}

double ChannelTransfer::drive_for(double L_cd_m2) const {
    const double lmin = min_cd_m2(), lmax = max_cd_m2();
    // Below (or at) black, and NaN: drive 0, the smallest drive that gives L(0).
    if (!(L_cd_m2 > lmin)) return 0.0;
    const double L = std::min(L_cd_m2, lmax);
    return std::clamp(display_encoding(kind).drive_for(*this, L), 0.0, 1.0);
}

// ---------------------------------------------------------------------------
// The display.

DisplayModel DisplayModel::srgb(double peak_cd_m2, double black_cd_m2, std::string name) {
    DisplayModel d;
    d.name = std::move(name);
    d.peak_cd_m2 = peak_cd_m2;
    d.black_cd_m2 = black_cd_m2;
    for (int c = 0; c < 3; ++c) {
        auto& ch = d.channels[static_cast<std::size_t>(c)];
        ch.kind = TransferKind::srgb;
        ch.black_cd_m2 = rec709_weight(c) * black_cd_m2;
        ch.white_cd_m2 = rec709_weight(c) * peak_cd_m2;
    }
    return d;
}

DisplayModel DisplayModel::pq(double peak_cd_m2, double black_cd_m2, std::string name) {
    DisplayModel d;
    d.name = std::move(name);
    d.peak_cd_m2 = peak_cd_m2;
    d.black_cd_m2 = black_cd_m2;
    for (int c = 0; c < 3; ++c) {
        auto& ch = d.channels[static_cast<std::size_t>(c)];
        ch.kind = TransferKind::pq;
        ch.pq_weight = rec709_weight(c);
        ch.black_cd_m2 = rec709_weight(c) * black_cd_m2;
        ch.white_cd_m2 = rec709_weight(c) * peak_cd_m2;
    }
    return d;
}

namespace {
void sum_channels(DisplayModel& d) {
    d.peak_cd_m2 = 0.0;
    d.black_cd_m2 = 0.0;
    for (const auto& ch : d.channels) {
        d.peak_cd_m2 += ch.max_cd_m2();
        d.black_cd_m2 += ch.min_cd_m2();
    }
}
}  // namespace

DisplayModel DisplayModel::gog(const std::array<GogParams, 3>& channels, std::string name) {
    DisplayModel d;
    d.name = std::move(name);
    for (std::size_t c = 0; c < 3; ++c) {
        d.channels[c].kind = TransferKind::gog;
        d.channels[c].gog = channels[c];
    }
    sum_channels(d);
    return d;
}

DisplayModel DisplayModel::lut(const std::array<std::vector<LutPoint>, 3>& channels, std::string name) {
    DisplayModel d;
    d.name = std::move(name);
    for (std::size_t c = 0; c < 3; ++c) {
        d.channels[c].kind = TransferKind::lut;
        d.channels[c].lut = channels[c];
    }
    // LUTs too short to evaluate are left for validate() to report.
    bool ok = true;
    for (const auto& ch : d.channels) ok = ok && ch.lut.size() >= 2;
    if (ok) sum_channels(d);
    return d;
}

void DisplayModel::validate(const SourceLocation& where) const {
    auto fail = [&](const std::string& field, const std::string& message) {
        SourceLocation at = where;
        at.key = where.key.empty() ? field : where.key + "." + field;
        throw InputError(at, fmt::format("display '{}': {}", name, message));
    };
    auto finite = [](double x) { return std::isfinite(x); };

    // Each channel's own parameters first (a NaN gamma would otherwise surface as a NaN peak),
    // then the display's peak and black, then the channels against them.
    for (int c = 0; c < 3; ++c) {
        const auto& ch = channels[static_cast<std::size_t>(c)];
        const std::string cn = channel_name(c);
        switch (ch.kind) {
            default:
                break;  // the laws made from a black and a white: checked against the display's below
            case TransferKind::gog: {
                const auto& g = ch.gog;
                const std::string key = cn + ".gog.";
                if (!finite(g.a)) fail(key + "a", "the GOG offset a is not a finite number");
                if (!finite(g.b)) fail(key + "b", "the GOG offset b is not a finite number");
                if (!finite(g.k)) fail(key + "k", "the GOG gain k is not a finite number");
                if (!finite(g.gamma)) fail(key + "gamma", "the GOG gamma is not a finite number");
                if (g.k <= 0.0)
                    fail(key + "k", fmt::format("the GOG gain k must be positive (k = {} makes the {} channel's "
                                                "luminance fall or stay flat as the drive rises)",
                                                g.k, cn));
                if (g.gamma <= 0.0)
                    fail(key + "gamma", fmt::format("the GOG gamma must be positive (gamma = {} makes the {} "
                                                    "channel's luminance fall as the drive rises)",
                                                    g.gamma, cn));
                if (g.b + g.k <= 0.0)
                    fail(key + "b",
                         fmt::format("b + k = {} is not positive: the {} channel never lights up", g.b + g.k, cn));
                const double l0 = ch.min_cd_m2(), l1 = ch.max_cd_m2();
                if (!finite(l0) || !finite(l1))
                    fail(key + "gamma", fmt::format("the {} channel's GOG curve is not finite", cn));
                if (l0 < 0.0)
                    fail(key + "a",
                         fmt::format("the {} channel's luminance at drive 0 is negative ({} cd/m²)", cn, l0));
                if (!(l1 > l0))
                    fail(key + "k",
                         fmt::format("the {} channel's GOG curve does not rise ({} to {} cd/m²)", cn, l0, l1));
                break;
            }
            case TransferKind::lut: {
                const auto& p = ch.lut;
                const std::string key = cn + ".lut";
                if (p.size() < 2)
                    fail(key, fmt::format("the {} channel's LUT needs at least 2 entries, it has {}", cn, p.size()));
                if (p.size() > 65536)
                    fail(key,
                         fmt::format("the {} channel's LUT has {} entries; at most 65536 are allowed", cn, p.size()));
                for (std::size_t i = 0; i < p.size(); ++i) {
                    const std::string entry = fmt::format("{}[{}]", key, i);
                    if (!finite(p[i].drive) || p[i].drive < 0.0 || p[i].drive > 1.0)
                        fail(entry + ".drive",
                             fmt::format("entry {} of the {} channel's LUT has drive {}, outside [0, 1]", i, cn,
                                         p[i].drive));
                    if (!finite(p[i].cd_m2) || p[i].cd_m2 < 0.0)
                        fail(entry + ".cd_m2",
                             fmt::format("entry {} of the {} channel's LUT has luminance {} cd/m²; it "
                                         "must be a finite number >= 0",
                                         i, cn, p[i].cd_m2));
                    if (i > 0 && !(p[i].drive > p[i - 1].drive))
                        fail(entry + ".drive",
                             fmt::format(
                                 "entry {} of the {} channel's LUT has drive {}, not above entry {}'s {}: drives "
                                 "must increase strictly",
                                 i, cn, p[i].drive, i - 1, p[i - 1].drive));
                    if (i > 0 && p[i].cd_m2 < p[i - 1].cd_m2)
                        fail(
                            entry + ".cd_m2",
                            fmt::format("entry {} of the {} channel's LUT has {} cd/m², less than entry {}'s {} cd/m²: "
                                        "luminance must not fall as the drive rises",
                                        i, cn, p[i].cd_m2, i - 1, p[i - 1].cd_m2));
                }
                if (p.front().drive != 0.0)
                    fail(key + "[0].drive", fmt::format("the {} channel's LUT must start at drive 0", cn));
                if (p.back().drive != 1.0)
                    fail(fmt::format("{}[{}].drive", key, p.size() - 1),
                         fmt::format("the {} channel's LUT must end at drive 1", cn));
                if (!(p.back().cd_m2 > p.front().cd_m2))
                    fail(key, fmt::format("the {} channel's LUT does not rise from drive 0 to drive 1", cn));
                break;
            }
        }
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
        if (display_encoding(ch.kind).from_peak_black == nullptr) continue;
        if (!finite(ch.black_cd_m2) || ch.black_cd_m2 < 0.0)
            fail(cn + ".black_cd_m2", fmt::format("the {} channel's black must be zero or more cd/m²", cn));
        if (!finite(ch.white_cd_m2) || ch.white_cd_m2 <= ch.black_cd_m2)
            fail(cn + ".white_cd_m2", fmt::format("the {} channel's white ({} cd/m²) must be above its black ({} cd/m²)",
                                                  cn, ch.white_cd_m2, ch.black_cd_m2));
        if (ch.kind == TransferKind::pq) {
            if (!finite(ch.pq_weight) || ch.pq_weight <= 0.0)
                fail(cn + ".pq_weight", fmt::format("the {} channel's PQ weight must be positive", cn));
            if (ch.white_cd_m2 > ch.pq_weight * kPqPeak * (1.0 + 1e-12))
                fail("peak_cd_m2", fmt::format("a PQ display cannot show more than {} cd/m²", kPqPeak));
        }
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
        g.pq_weight = ch.pq_weight;
        g.a = ch.gog.a;
        g.b = ch.gog.b;
        g.k = ch.gog.k;
        g.gamma = ch.gog.gamma;
        g.inv_gamma = 1.0 / ch.gog.gamma;
        g.kind = static_cast<std::int32_t>(ch.kind);
        if (ch.kind == TransferKind::lut) {
            g.lut_first = first;
            g.lut_count = static_cast<std::int32_t>(ch.lut.size());
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
        if (ch.kind != TransferKind::lut) continue;
        for (std::size_t j = 0; j < ch.lut.size(); ++j) {
            out.push_back(ch.lut[j].drive);
            out.push_back(ch.lut[j].cd_m2);
            out.push_back(pchip_slope(ch.lut, j));
        }
    }
    if (out.empty()) out.assign(3, 0.0);
    return out;
}

}  // namespace atonlab::display
