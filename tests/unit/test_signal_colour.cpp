// The navigation-light colour check's geometry (signal_colour.h) against the
// corner coordinates of COLREGs 1972 Annex I §7 worked by hand, and u′v′
// against the published value of D65.
#include <gtest/gtest.h>

#include <stdexcept>

#include "atonlab/display/colour.h"
#include "atonlab/display/display_model.h"
#include "atonlab/stimuli/signal_colour.h"

namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

std::vector<glm::dvec2> area(const char* name) {
    return *signal_colour_area(name);
}

TEST(SignalColour, AreasHoldTheColoursTheyName) {
    // atonlab's IALA green (K2012 table 4.1) and D65 white lie in their areas.
    EXPECT_TRUE(inside_polygon(*iala_colour_xy("green"), area("green")));
    EXPECT_TRUE(inside_polygon(d65_white_xy(), area("white")));
    // The Rec.709 red primary (x = 0.64) is short of the red area (x >= 0.66),
    // and the gamut's yellow (on its red-green edge) short of the yellow area.
    EXPECT_FALSE(inside_polygon(*iala_colour_xy("red"), area("red")));
    EXPECT_FALSE(inside_polygon(*iala_colour_xy("yellow"), area("yellow")));
    // Corners are inside (on the edge).
    EXPECT_TRUE(inside_polygon({0.525, 0.382}, area("white")));
    EXPECT_FALSE(signal_colour_area("blue").has_value());
}

// The white area is not convex: its boundary turns back at (0.443, 0.382). A
// point below y = 0.382 right of that corner is outside, although the convex
// hull (the chord from (0.310, 0.283) to (0.525, 0.382), y = 0.3705 at x = 0.5)
// would hold it.
TEST(SignalColour, TheWhiteAreasNotchIsOutside) {
    EXPECT_FALSE(inside_polygon({0.5, 0.375}, area("white")));
    EXPECT_TRUE(inside_polygon({0.5, 0.39}, area("white")));
}

// Worked by hand: every red corner has x >= 0.66 > 0.64, the gamut's largest
// x; every yellow corner lies above the gamut's red-green edge
// (y = 0.33 - 0.794 (x - 0.64): 0.352 at x = 0.612, 0.382 at x = 0.575).
TEST(SignalColour, WhichAreasMeetTheRec709Gamut) {
    EXPECT_TRUE(polygons_overlap(area("white"), rec709_gamut_xy()));
    EXPECT_TRUE(polygons_overlap(area("green"), rec709_gamut_xy()));
    EXPECT_FALSE(polygons_overlap(area("red"), rec709_gamut_xy()));
    EXPECT_FALSE(polygons_overlap(area("yellow"), rec709_gamut_xy()));
    // One polygon wholly inside another overlaps it.
    const std::vector<glm::dvec2> small = {{0.30, 0.32}, {0.32, 0.32}, {0.31, 0.33}};
    EXPECT_TRUE(polygons_overlap(small, rec709_gamut_xy()));
    EXPECT_TRUE(polygons_overlap(rec709_gamut_xy(), small));
}

// D65 (X, Y, Z) = (95.047, 100, 108.883): u′ = 0.1978, v′ = 0.4683 (CIE 15:2004 table).
TEST(SignalColour, UvPrimeOfD65) {
    const glm::dvec2 uv = uv_prime({95.047, 100.0, 108.883});
    EXPECT_NEAR(uv.x, 0.1978, 1e-4);
    EXPECT_NEAR(uv.y, 0.4683, 1e-4);
    EXPECT_EQ(uv_prime({0, 0, 0}), glm::dvec2(0.0));
}

// Full white on an sRGB display of 100 cd/m² peak: Y = 100 cd/m² and D65's xy.
TEST(SignalColour, DisplayedXyzOfFullWhite) {
    const DisplayModel display = DisplayModel::srgb(100.0, 0.1);
    const glm::dvec3 xyz = displayed_xyz(display, {255, 255, 255}, 8);
    EXPECT_NEAR(xyz.y, displayed_luminance_cd_m2(display, {255, 255, 255}, 8), 1e-9);
    EXPECT_NEAR(xyz.y, 100.0, 0.2);
    const double sum = xyz.x + xyz.y + xyz.z;
    EXPECT_NEAR(xyz.x / sum, 0.3127, 1e-4);
    EXPECT_NEAR(xyz.y / sum, 0.3290, 1e-4);
}

TEST(SignalColour, CheckPassesOnlyWithinToleranceAndArea) {
    const glm::dvec3 green = xyY_to_xyz({0.28, 0.52, 1.0});
    SignalColourCheck c = check_signal_colour("green", green, green);
    EXPECT_EQ(c.delta_uv, 0.0);
    EXPECT_TRUE(c.area_meets_gamut);
    EXPECT_TRUE(c.inside_area);
    EXPECT_TRUE(c.passes());
    // Blue-shifted half way to (0.3, 0.3): outside the green area and far in u′v′.
    c = check_signal_colour("green", xyY_to_xyz({0.29, 0.41, 1.0}), green);
    EXPECT_GT(c.delta_uv, 0.01);
    EXPECT_FALSE(c.inside_area);
    EXPECT_FALSE(c.passes());
    // Red: its area does not meet the gamut, so only Δu′v′ counts.
    const glm::dvec3 red = xyY_to_xyz({0.64, 0.33, 1.0});
    c = check_signal_colour("red", red, red);
    EXPECT_FALSE(c.area_meets_gamut);
    EXPECT_FALSE(c.inside_area);
    EXPECT_TRUE(c.passes());
    EXPECT_THROW(check_signal_colour("blue", red, red), std::invalid_argument);
}

}  // namespace
