// DisplayGeometry (display/geometry.h): one type for the scene's display and a
// calibration's; analytic visual angles.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "atonlab/display/geometry.h"

namespace atonlab::display {
namespace {

TEST(DisplayGeometry, SquarePixelsUnlessTheHeightWasMeasured) {
    DisplayGeometry g{2000, 1000, 0.6, 0.9};
    EXPECT_DOUBLE_EQ(g.height_m(), 0.3);
    g.measured_height_m = 0.31;
    EXPECT_EQ(g.height_m(), 0.31);
    // The vertical visual angle follows the measured height: 2 atan(h / 2d).
    EXPECT_NEAR(g.fov_y_rad(), 2.0 * std::atan(0.155 / 0.9), 1e-15);
}

TEST(DisplayGeometry, PixelsPerDegreeExactAndSmallAngle) {
    // Pitch p = 0.5 mm at the distance where one pixel subtends 1/60 degree.
    const double pitch = 0.5 / 1000.0;
    const double d = pitch / (2.0 * std::tan(std::numbers::pi / 180.0 / 120.0));
    const DisplayGeometry g{1000, 500, 0.5, d};
    EXPECT_NEAR(g.pixels_per_degree(), 60.0, 1e-9);
    // focal_px · π/180 = d / p · π/180; it differs from the exact value by O(angle²) only.
    EXPECT_NEAR(g.pixels_per_degree_at_centre(), d / pitch * std::numbers::pi / 180.0, 1e-9);
    EXPECT_NEAR(g.pixels_per_degree_at_centre(), 60.0, 1e-4);
    EXPECT_NE(g.describe().find("1000 x 500 px"), std::string::npos);
}

}  // namespace
}  // namespace atonlab::display
