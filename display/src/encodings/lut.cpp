// The lut encoding: measured (V, L) pairs, monotone cubic (Fritsch–Carlson PCHIP)
// interpolation between them (display_encodings.h; docs/display-calibration.md).
// Only a calibration makes it: its knots are a photometer's readings.
#include <fmt/format.h>

#include <cassert>
#include <cmath>
#include <span>

#include "atonlab/display/display_encodings.h"

namespace atonlab::display {
namespace {

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

double knots_luminance(std::span<const LutPoint> p, double v) {
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

double knots_drive(std::span<const LutPoint> p, double L) {
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

double lut_luminance(const ChannelEncoding& ch, double v) {
    return knots_luminance(ch.lut, v);
}

double lut_drive(const ChannelEncoding& ch, double L) {
    return L >= ch.max_cd_m2() ? 1.0 : knots_drive(ch.lut, L);
}

// The knots (drive, cd/m², slope) are in display_lut[] from c.lut_first (lut_knots below).
constexpr std::string_view kGlsl =
    R"(// Exact inverse of the monotone cubic through the LUT knots, for black < L < white.
double display_lut_drive(DisplayChannel c, double L) {
    int lo = 0;
    int hi = c.lut_count - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (display_lut[3 * (c.lut_first + mid) + 1] < L) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    int i0 = 3 * (c.lut_first + lo);
    int i1 = 3 * (c.lut_first + hi);
    double v0 = display_lut[i0], L0 = display_lut[i0 + 1], m0 = display_lut[i0 + 2];
    double v1 = display_lut[i1], L1 = display_lut[i1 + 1], m1 = display_lut[i1 + 2];
    double h = v1 - v0;
    double delta = L1 - L0;
    double c1 = h * m0;
    double c2 = 3.0LF * delta - 2.0LF * h * m0 - h * m1;
    double c3 = -2.0LF * delta + h * m0 + h * m1;
    double y = L - L0;
    // Newton steps, bisection whenever a step leaves the bracket (solve_segment above).
    double tlo = 0.0LF, thi = 1.0LF;
    double t = y / delta;
    for (int i = 0; i < 64; ++i) {
        double f = t * (c1 + t * (c2 + t * c3)) - y;
        if (f < 0.0LF) {
            tlo = t;
        } else {
            thi = t;
        }
        double next = t - f / (c1 + t * (2.0LF * c2 + t * 3.0LF * c3));
        if (!(next > tlo && next < thi)) next = 0.5LF * (tlo + thi);
        bool done = abs(next - t) <= 1e-15LF || thi - tlo <= 1e-15LF;
        t = next;
        if (done) break;
    }
    return v0 + t * h;
}

double display_drive_lut(DisplayChannel c, double L) {
    return L >= c.white_cd_m2 ? 1.0LF : display_lut_drive(c, L);
})";

std::vector<double> lut_knots(const ChannelEncoding& ch) {
    std::vector<double> out;
    for (std::size_t j = 0; j < ch.lut.size(); ++j) {
        out.push_back(ch.lut[j].drive);
        out.push_back(ch.lut[j].cd_m2);
        out.push_back(pchip_slope(ch.lut, j));
    }
    return out;
}

void lut_check(const ChannelEncoding& ch, const ChannelCheck& at) {
    const auto& p = ch.lut;
    const std::string cn(at.channel);
    const std::string key = "lut";
    if (p.size() < 2)
        at.fail(key, fmt::format("the {} channel's LUT needs at least 2 entries, it has {}", cn, p.size()));
    if (p.size() > 65536)
        at.fail(key, fmt::format("the {} channel's LUT has {} entries; at most 65536 are allowed", cn, p.size()));
    for (std::size_t i = 0; i < p.size(); ++i) {
        const std::string entry = fmt::format("{}[{}]", key, i);
        if (!std::isfinite(p[i].drive) || p[i].drive < 0.0 || p[i].drive > 1.0)
            at.fail(entry + ".drive",
                    fmt::format("entry {} of the {} channel's LUT has drive {}, outside [0, 1]", i, cn, p[i].drive));
        if (!std::isfinite(p[i].cd_m2) || p[i].cd_m2 < 0.0)
            at.fail(entry + ".cd_m2", fmt::format("entry {} of the {} channel's LUT has luminance {} cd/m²; it "
                                                  "must be a finite number >= 0",
                                                  i, cn, p[i].cd_m2));
        if (i > 0 && !(p[i].drive > p[i - 1].drive))
            at.fail(entry + ".drive",
                    fmt::format("entry {} of the {} channel's LUT has drive {}, not above entry {}'s {}: drives "
                                "must increase strictly",
                                i, cn, p[i].drive, i - 1, p[i - 1].drive));
        if (i > 0 && p[i].cd_m2 < p[i - 1].cd_m2)
            at.fail(entry + ".cd_m2",
                    fmt::format("entry {} of the {} channel's LUT has {} cd/m², less than entry {}'s {} cd/m²: "
                                "luminance must not fall as the drive rises",
                                i, cn, p[i].cd_m2, i - 1, p[i - 1].cd_m2));
    }
    if (p.front().drive != 0.0)
        at.fail(key + "[0].drive", fmt::format("the {} channel's LUT must start at drive 0", cn));
    if (p.back().drive != 1.0)
        at.fail(fmt::format("{}[{}].drive", key, p.size() - 1),
                fmt::format("the {} channel's LUT must end at drive 1", cn));
    if (!(p.back().cd_m2 > p.front().cd_m2))
        at.fail(key, fmt::format("the {} channel's LUT does not rise from drive 0 to drive 1", cn));
}

}  // namespace

const DisplayEncoding& display_encoding_lut() {
    static const DisplayEncoding e{.name = "lut",
                                   .display_name = "LUT",
                                   .luminance_cd_m2 = lut_luminance,
                                   .drive_for = lut_drive,
                                   .glsl = kGlsl,
                                   .glsl_drive_function = "display_drive_lut",
                                   .knots_key = "lut",
                                   .check = lut_check,
                                   .gpu_knots = lut_knots};
    return e;
}

DisplayModel DisplayModel::lut(const std::array<std::vector<LutPoint>, 3>& channels, std::string name) {
    DisplayModel d;
    d.name = std::move(name);
    for (std::size_t c = 0; c < 3; ++c) {
        d.channels[c].encoding = &display_encoding_lut();
        d.channels[c].lut = channels[c];
    }
    // LUTs too short to evaluate are left for validate() to report.
    bool ok = true;
    for (const auto& ch : d.channels) ok = ok && ch.lut.size() >= 2;
    if (ok) d.sum_channels();
    return d;
}

}  // namespace atonlab::display
