#include "atonlab/stimuli/footprint.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "atonlab/display/solid_angle.h"

namespace atonlab::stimuli {
namespace {

// s(X) = sqrt(R² − X²) written as (R − X)(R + X) so it stays accurate near the rim.
double half_chord(double r, double x) { return std::sqrt(std::max(0.0, (r - x) * (r + x))); }

// ∫_p^q s(X) dX = ½[X s + R² asin(X/R)]_p^q, with the asin difference taken as
// one atan2 so that large discs do not lose the pixel-sized difference.
double chord_integral(double r, double p, double q) {
    const double sp = half_chord(r, p), sq = half_chord(r, q);
    const double dasin = std::atan2(q * sp - p * sq, sp * sq + p * q);
    return 0.5 * (q * sq - p * sp) + 0.5 * r * r * dasin;
}

// K(c) = ∫_a^b max(s(X) − c, 0) dX for c >= 0.
double excess(double r, double a, double b, double c) {
    if (c >= r) return 0.0;
    const double w = half_chord(r, c);
    const double p = std::max(a, -w), q = std::min(b, w);
    if (p >= q) return 0.0;
    return chord_integral(r, p, q) - c * (q - p);
}

// J(lo, hi) = ∫_a^b clamp(s(X), lo, hi) dX, where s = 0 outside the disc.
double clamped_chord(double r, double a, double b, double lo, double hi) {
    if (hi <= 0.0) return hi * (b - a);
    const double l = std::max(lo, 0.0);
    return l * (b - a) + excess(r, a, b, l) - excess(r, a, b, hi);
}

}  // namespace

double disc_pixel_coverage(double cx, double cy, double r, double x0, double y0) {
    if (!(r > 0.0)) return 0.0;
    const double a = x0 - cx, b = a + 1.0, lo = y0 - cy, hi = lo + 1.0;
    // Quick outs: the pixel entirely outside or inside the disc.
    const double nx = std::clamp(0.0, a, b), ny = std::clamp(0.0, lo, hi);
    if (nx * nx + ny * ny >= r * r) return 0.0;
    const double fx = std::max(std::abs(a), std::abs(b)), fy = std::max(std::abs(lo), std::abs(hi));
    if (fx * fx + fy * fy <= r * r) return 1.0;
    // Area between the lower and upper arcs, clipped to [lo, hi]:
    // ∫ [clamp(s, lo, hi) − clamp(−s, lo, hi)] dX = J(lo, hi) + J(−hi, −lo).
    const double area = clamped_chord(r, a, b, lo, hi) + clamped_chord(r, a, b, -hi, -lo);
    return std::clamp(area, 0.0, 1.0);
}

double box_pixel_coverage(double cx, double cy, double x0, double y0) {
    const double ox = std::max(0.0, std::min(cx + 0.5, x0 + 1.0) - std::max(cx - 0.5, x0));
    const double oy = std::max(0.0, std::min(cy + 0.5, y0 + 1.0) - std::max(cy - 0.5, y0));
    return ox * oy;
}

double sphere_solid_angle_sr(double radius_m, double distance_m) {
    if (distance_m <= radius_m) return 2.0 * std::numbers::pi;
    const double s = radius_m / distance_m;
    // 2π(1 − cos β) = 2π sin²β / (1 + cos β): no cancellation for small β.
    return 2.0 * std::numbers::pi * s * s / (1.0 + std::sqrt((1.0 - s) * (1.0 + s)));
}

double pixel_solid_angle_sr(double x0, double y0, double f) {
    return display::pixel_solid_angle_sr(x0, y0, f);  // one home: display/solid_angle.h
}

Footprint light_footprint(glm::dvec3 v, double radius_m, double focal_px, int width, int height) {
    Footprint fp;
    const double d = glm::length(v);
    // Only a sphere wholly in front of the camera's plane (depth > radius) has a bounded
    // image: nearer that plane the centre and the area (1/cos³α) overflow. Behind the
    // camera, beside it, or the eye inside the light (d <= radius): not visible.
    if (!(-v.z > radius_m) || !(d > radius_m)) return fp;
    const double depth = -v.z;
    fp.centre_px = {0.5 * width + focal_px * v.x / depth, 0.5 * height + focal_px * v.y / depth};
    const double cos_alpha = depth / d;
    // A small solid angle ω seen α off-axis covers ω f² / cos³α on the image plane.
    fp.area_px2 = sphere_solid_angle_sr(radius_m, d) * focal_px * focal_px / (cos_alpha * cos_alpha * cos_alpha);
    fp.disc = fp.area_px2 >= 1.0;
    fp.radius_px = std::sqrt(fp.area_px2 / std::numbers::pi);
    fp.visible = true;
    return fp;
}

}  // namespace atonlab::stimuli
