// Vertical and horizontal emission profiles, K2012 §4.1.1-4.1.2 and §5.1.
//
// The lookups (at_p, at_bearing_deg) are the CPU reference of the GLSL in
// shaders/light_model.glsl: keep the arithmetic step for step the same (index
// u, integer cell, fraction, mix(a, b, f) = a (1 - f) + b f) so that CPU and GPU
// agree to float rounding.
#include "atonlab/stimuli/profile.h"

#include <fmt/format.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

#include "atonlab/stimuli/error.h"

namespace atonlab::stimuli {
namespace {

constexpr double degrees_per_radian = 180.0 / std::numbers::pi;

/// GLSL mix(): exact at f = 0 (returns a) and, for finite a, b, at f = 1 (returns b).
double mix(double a, double b, double f) {
    return a * (1 - f) + b * f;
}

[[noreturn]] void fail(const std::string& what) {
    throw InputError(what);
}

/// Checks a (bearing or elevation, relative) table read from a user file.
void check_pairs(const char* what, std::span<const double> x, std::span<const double> rel, double lo, double hi) {
    if (x.size() != rel.size())
        fail(fmt::format("{} has {} angles but {} relative values", what, x.size(), rel.size()));
    if (x.empty()) fail(fmt::format("{} is empty", what));
    for (std::size_t i = 0; i < x.size(); ++i) {
        if (!(x[i] >= lo && x[i] <= hi)) fail(fmt::format("{} angle {}° is outside [{}, {}]°", what, x[i], lo, hi));
        if (!(rel[i] >= 0) || !std::isfinite(rel[i]))
            fail(fmt::format("{} value {} at {}° must be a finite number >= 0", what, rel[i], x[i]));
        if (i > 0 && !(x[i] > x[i - 1]))
            fail(fmt::format("{} angles must increase, but {}° follows {}°", what, x[i], x[i - 1]));
    }
}

/// Linear interpolation in a sorted table, flat beyond its ends.
double interpolate_clamped(std::span<const double> x, std::span<const double> y, double at) {
    if (at <= x.front()) return y.front();
    if (at >= x.back()) return y.back();
    const std::size_t i = static_cast<std::size_t>(std::upper_bound(x.begin(), x.end(), at) - x.begin());
    const double f = (at - x[i - 1]) / (x[i] - x[i - 1]);
    return mix(y[i - 1], y[i], f);
}

/// Bearing of table entry i of n: i * 360 / n degrees (K2012 eq 4.3).
double table_bearing_deg(int i, int n) {
    return i * 360.0 / n;
}

/// Relative level of one sector at bearing b (degrees in [0, 360)).
double sector_level(const Sector& s, double width_deg, double b) {
    double inside = std::fmod(b - s.from_deg, 360.0);  // clockwise offset from the "from" edge
    if (inside < 0) inside += 360.0;
    if (inside <= width_deg) return s.level;
    // Outside: angular distance to the nearer edge, then the linear fall-off.
    const double dist = std::min(inside - width_deg, 360.0 - inside);
    if (s.edge_deg > 0 && dist < s.edge_deg) return s.level * (1 - dist / s.edge_deg);
    return 0;
}

}  // namespace

// ---- Vertical ----------------------------------------------------------------

VerticalProfile VerticalProfile::uniform(int n) {
    assert(n >= 2);
    return VerticalProfile{std::vector<float>(static_cast<std::size_t>(std::max(n, 2)), 1.0f)};
}

VerticalProfile VerticalProfile::from_elevation_table(std::span<const double> elevation_deg,
                                                      std::span<const double> relative, int n) {
    check_pairs("the vertical profile", elevation_deg, relative, -90, 90);
    if (n < 2) fail(fmt::format("a vertical profile needs at least 2 table entries, not {}", n));
    VerticalProfile v;
    v.table.resize(static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j) {
        // K2012 eq 4.2: theta = acos(2p - 1) at p_j = j / (n - 1); elevation = 90° - theta.
        const double p = static_cast<double>(j) / (n - 1);
        const double theta_deg = std::acos(std::clamp(2 * p - 1, -1.0, 1.0)) * degrees_per_radian;
        v.table[static_cast<std::size_t>(j)] =
            static_cast<float>(interpolate_clamped(elevation_deg, relative, 90.0 - theta_deg));
    }
    return v;
}

double VerticalProfile::at_p(double p) const {
    const int n = static_cast<int>(table.size());
    assert(n >= 2);
    if (n < 2) return n == 1 ? table[0] : 1.0;
    if (!(p >= 0)) p = 0;  // also NaN
    if (p > 1) p = 1;
    const double u = p * (n - 1);
    const int j0 = std::min(static_cast<int>(std::floor(u)), n - 2);
    const double f = u - j0;
    return mix(table[static_cast<std::size_t>(j0)], table[static_cast<std::size_t>(j0 + 1)], f);
}

// ---- Horizontal --------------------------------------------------------------

HorizontalProfile HorizontalProfile::uniform(int n) {
    assert(n >= 1);
    return HorizontalProfile{std::vector<float>(static_cast<std::size_t>(std::max(n, 1)), 1.0f)};
}

HorizontalProfile HorizontalProfile::from_sectors(std::span<const Sector> sectors, int n) {
    if (n < 1) fail(fmt::format("a horizontal profile needs at least 1 table entry, not {}", n));
    std::vector<double> widths;
    for (const Sector& s : sectors) {
        if (!std::isfinite(s.from_deg) || !std::isfinite(s.to_deg))
            fail(fmt::format("sector limits must be finite numbers, not {}° to {}°", s.from_deg, s.to_deg));
        if (!(s.level >= 0) || !std::isfinite(s.level))
            fail(fmt::format("sector {}° to {}° has level {}, which must be a finite number >= 0", s.from_deg, s.to_deg,
                             s.level));
        if (!(s.edge_deg >= 0) || !std::isfinite(s.edge_deg))
            fail(fmt::format("sector {}° to {}° has edge {}°, which must be a finite number >= 0", s.from_deg, s.to_deg,
                             s.edge_deg));
        // Clockwise width: "to" may be below "from" (wraps through 0°); to = from + 360 is all round.
        double w = s.to_deg - s.from_deg;
        if (w == 0) fail(fmt::format("sector {}° to {}° is empty", s.from_deg, s.to_deg));
        if (w > 360 || w <= -360) fail(fmt::format("sector {}° to {}° spans more than 360°", s.from_deg, s.to_deg));
        if (w < 0) w += 360;
        widths.push_back(w);
    }
    HorizontalProfile h;
    h.table.assign(static_cast<std::size_t>(n), 0.0f);
    for (int i = 0; i < n; ++i) {
        const double b = table_bearing_deg(i, n);
        double level = 0;
        for (std::size_t k = 0; k < sectors.size(); ++k)
            level = std::max(level, sector_level(sectors[k], widths[k], b));  // overlap: the maximum
        h.table[static_cast<std::size_t>(i)] = static_cast<float>(level);
    }
    return h;
}

HorizontalProfile HorizontalProfile::from_bearing_table(std::span<const double> bearing_deg,
                                                        std::span<const double> relative, int n) {
    check_pairs("the horizontal profile", bearing_deg, relative, 0, 360);
    if (n < 1) fail(fmt::format("a horizontal profile needs at least 1 table entry, not {}", n));
    // 360° is 0° again: allowed as a closing entry only if it repeats the 0° value.
    std::vector<double> x(bearing_deg.begin(), bearing_deg.end());
    std::vector<double> y(relative.begin(), relative.end());
    if (x.back() == 360) {
        if (x.front() != 0 || y.front() != y.back())
            fail(fmt::format("the horizontal profile's value at 360° ({}) must repeat its value at 0°", y.back()));
        x.pop_back();
        y.pop_back();
    }
    // Close the period: the first entry again, one turn later.
    x.push_back(x.front() + 360);
    y.push_back(y.front());
    HorizontalProfile h;
    h.table.resize(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        double b = table_bearing_deg(i, n);
        if (b < x.front()) b += 360;
        h.table[static_cast<std::size_t>(i)] = static_cast<float>(interpolate_clamped(x, y, b));
    }
    return h;
}

double HorizontalProfile::at_bearing_deg(double bearing_deg) const {
    const int n = static_cast<int>(table.size());
    assert(n >= 1);
    if (n < 1) return 1.0;
    double b = std::isfinite(bearing_deg) ? bearing_deg : 0.0;
    b = b - 360.0 * std::floor(b / 360.0);  // wrap to [0, 360)
    if (b >= 360.0) b = 0;                  // -tiny + 360 rounds to 360
    const double u = b / 360.0 * n;         // K2012 eq 4.3, in table cells
    const double cell = std::floor(u);
    const int i0 = static_cast<int>(cell) % n;
    const double f = u - cell;
    return mix(table[static_cast<std::size_t>(i0)], table[static_cast<std::size_t>((i0 + 1) % n)], f);
}

double bearing_deg_of_direction(double x, double z) {
    if (x == 0 && z == 0) return 0;
    // Clockwise from -z (light-local north) towards +x (east); K2012 eq 4.4 rotated by 180°.
    double deg = std::atan2(x, -z) * degrees_per_radian;
    if (deg < 0) deg += 360;
    if (deg >= 360) deg = 0;
    return deg;
}

// ---- Builtin profiles ----------------------------------------------------------

double sabik_vp_relative_intensity(double elevation_deg) {
    // exp(-ln2 (|e|/10)^k): 0.5 at 10° for any k; 0.1 at 20° needs 2^k = ln10 / ln2.
    static const double k = std::log2(std::log2(10.0));
    return std::exp(-std::numbers::ln2 * std::pow(std::abs(elevation_deg) / 10.0, k));
}

VerticalProfile sabik_vp_vertical_profile(int n) {
    if (n < 2) fail(fmt::format("a vertical profile needs at least 2 table entries, not {}", n));
    VerticalProfile v;
    v.table.resize(static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j) {
        const double p = static_cast<double>(j) / (n - 1);  // K2012 eq 4.2
        const double theta_deg = std::acos(std::clamp(2 * p - 1, -1.0, 1.0)) * degrees_per_radian;
        v.table[static_cast<std::size_t>(j)] = static_cast<float>(sabik_vp_relative_intensity(90.0 - theta_deg));
    }
    return v;
}

}  // namespace atonlab::stimuli
