#include "atonlab/display/geometry.h"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "atonlab/display/solid_angle.h"

namespace atonlab::display {

double DisplayGeometry::fov_x_rad() const {
    return 2.0 * std::atan(0.5 * width_m / viewing_distance_m);
}
double DisplayGeometry::fov_y_rad() const {
    return 2.0 * std::atan(0.5 * height_m() / viewing_distance_m);
}
double DisplayGeometry::pixels_per_degree_at_centre() const {
    return focal_px() * std::numbers::pi / 180.0;
}

double DisplayGeometry::pixels_per_degree() const {
    const double pitch_m = width_m / width_px;
    const double pixel_deg = 2.0 * std::atan(pitch_m / (2.0 * viewing_distance_m)) * 180.0 / std::numbers::pi;
    return 1.0 / pixel_deg;
}

std::string DisplayGeometry::describe() const {
    return fmt::format("{} x {} px, {:.4g} x {:.4g} m at {:.4g} m: {:.1f} px/deg at the centre", width_px, height_px,
                       width_m, height_m(), viewing_distance_m, pixels_per_degree());
}

double pixel_solid_angle_sr(double x0, double y0, double focal_px) {
    const double f = focal_px;
    auto corner = [f](double x, double y) { return std::atan(x * y / (f * std::sqrt(x * x + y * y + f * f))); };
    const double x1 = x0 + 1.0, y1 = y0 + 1.0;
    return corner(x1, y1) - corner(x0, y1) - corner(x1, y0) + corner(x0, y0);
}

}  // namespace atonlab::display
