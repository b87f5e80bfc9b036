// Emission profiles (K2012 §4.1.1-4.1.2): table lookups, sector tables and the
// builtin Sabik VP vertical profile, against values worked out by hand.
#include <gtest/gtest.h>

#include "input_error.h"

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/profile.h"

namespace {

using atonlab::InputError;
using namespace atonlab::stimuli;

double rad(double deg) {
    return deg * std::numbers::pi / 180.0;
}
/// p of eq 4.1 for an elevation above the horizontal: cos(theta) = sin(elevation).
double p_of_elevation(double elevation_deg) {
    return 0.5 * std::sin(rad(elevation_deg)) + 0.5;
}

template <class F>
std::string error_of(F&& f) {
    return atonlab::test::input_error_of(f, "(accepted)");
}

// ---- Vertical ----------------------------------------------------------------

TEST(VerticalProfile, TablePointsReturnTableValuesExactly) {
    // n - 1 a power of two: p_j = j / 4 times 4 is exactly j.
    const VerticalProfile v{{0.1f, 0.7f, 0.3f, 0.9f, 0.2f}};
    for (int j = 0; j < 5; ++j)
        EXPECT_EQ(v.at_p(j / 4.0), static_cast<double>(v.table[static_cast<std::size_t>(j)])) << j;
    // Any n: j / (n - 1) * (n - 1) may miss j by an ulp; still the float table value.
    VerticalProfile w;
    for (int j = 0; j < 50; ++j) w.table.push_back(static_cast<float>(j * j % 7) / 7.0f);
    for (int j = 0; j < 50; ++j)
        EXPECT_EQ(static_cast<float>(w.at_p(j / 49.0)), w.table[static_cast<std::size_t>(j)]) << j;
}

TEST(VerticalProfile, LinearBetweenTablePoints) {
    const VerticalProfile v{{0.1f, 0.7f, 0.3f, 0.9f, 0.2f}};
    const double a = 0.1f, b = 0.7f, c = 0.3f;
    EXPECT_NEAR(v.at_p(0.125), 0.5 * (a + b), 1e-15);         // half way between p = 0 and 0.25
    EXPECT_NEAR(v.at_p(0.0625), 0.75 * a + 0.25 * b, 1e-15);  // a quarter of the way
    EXPECT_NEAR(v.at_p(0.3), 0.8 * b + 0.2 * c, 1e-15);       // u = 1.2
}

TEST(VerticalProfile, ClampedOutsideZeroToOne) {
    const VerticalProfile v{{0.1f, 0.7f, 0.3f, 0.9f, 0.2f}};
    EXPECT_EQ(v.at_p(-0.5), static_cast<double>(0.1f));
    EXPECT_EQ(v.at_p(1.5), static_cast<double>(0.2f));
    EXPECT_EQ(v.at_p(1.0), static_cast<double>(0.2f));
    EXPECT_EQ(v.at_p(std::nan("")), static_cast<double>(0.1f));
    EXPECT_EQ(v.at_cos_theta(0.0), static_cast<double>(0.3f));   // horizontal: p = 0.5
    EXPECT_EQ(v.at_cos_theta(1.0), static_cast<double>(0.2f));   // straight up: p = 1
    EXPECT_EQ(v.at_cos_theta(-1.0), static_cast<double>(0.1f));  // straight down: p = 0
}

TEST(VerticalProfile, UniformIsAllOnes) {
    const VerticalProfile v = VerticalProfile::uniform(3);
    for (double p : {0.0, 0.2, 0.5, 0.99, 1.0}) EXPECT_EQ(v.at_p(p), 1.0);
}

TEST(VerticalProfile, FromElevationTableInterpolatesInElevation) {
    // A triangle in elevation: 0 at -90°, 1 at 0°, 0 at +90°.
    const std::vector<double> e{-90, 0, 90}, r{0, 1, 0};
    const VerticalProfile v = VerticalProfile::from_elevation_table(e, r, 257);
    ASSERT_EQ(v.table.size(), 257u);
    EXPECT_NEAR(v.table[128], 1.0, 1e-6);  // p = 0.5: horizontal
    EXPECT_NEAR(v.table[0], 0.0, 1e-6);    // straight down
    EXPECT_NEAR(v.table[256], 0.0, 1e-6);  // straight up
    // 30° up: p = 0.75 is the table point j = 192; 1 - 30/90.
    EXPECT_NEAR(v.at_p(p_of_elevation(30)), 2.0 / 3.0, 1e-6);
    // 30° down: p = 0.25, j = 64.
    EXPECT_NEAR(v.at_p(p_of_elevation(-30)), 2.0 / 3.0, 1e-6);
}

TEST(VerticalProfile, FromElevationTableIsFlatBeyondItsEnds) {
    const std::vector<double> e{-10, 10}, r{0.2, 0.8};
    const VerticalProfile v = VerticalProfile::from_elevation_table(e, r, 65);
    EXPECT_NEAR(v.at_p(1.0), 0.8, 1e-7);
    EXPECT_NEAR(v.at_p(0.0), 0.2, 1e-7);
    EXPECT_NEAR(v.at_p(p_of_elevation(45)), 0.8, 1e-7);
    EXPECT_NEAR(v.table[32], 0.5, 1e-7);  // horizontal, half way between 0.2 and 0.8
}

TEST(VerticalProfile, BadElevationTablesAreRejected) {
    const std::vector<double> two{0, 10}, one{1}, unsorted{10, 0}, wide{-95, 10}, vals{1, 0.5}, neg{1, -0.5};
    EXPECT_NE(error_of([&] { VerticalProfile::from_elevation_table(two, one); }).find("2 angles but 1"),
              std::string::npos);
    EXPECT_NE(error_of([&] { VerticalProfile::from_elevation_table(unsorted, vals); }).find("0° follows 10°"),
              std::string::npos);
    EXPECT_NE(error_of([&] { VerticalProfile::from_elevation_table(wide, vals); }).find("-95°"), std::string::npos);
    EXPECT_NE(error_of([&] { VerticalProfile::from_elevation_table(two, neg); }).find("-0.5"), std::string::npos);
    EXPECT_NE(error_of([&] { VerticalProfile::from_elevation_table({}, {}); }).find("empty"), std::string::npos);
}

// ---- Horizontal --------------------------------------------------------------

TEST(HorizontalProfile, LookupIsPeriodicAndLinear) {
    const HorizontalProfile h{{1.0f, 2.0f, 3.0f, 4.0f}};  // at 0°, 90°, 180°, 270°
    EXPECT_EQ(h.at_bearing_deg(0), 1.0);
    EXPECT_EQ(h.at_bearing_deg(90), 2.0);
    EXPECT_EQ(h.at_bearing_deg(270), 4.0);
    EXPECT_NEAR(h.at_bearing_deg(45), 1.5, 1e-15);
    EXPECT_NEAR(h.at_bearing_deg(315), 2.5, 1e-15);  // between the last (4) and the first (1)
    // 359.95°: f = 89.95 / 90 of the way from 4 to 1.
    EXPECT_NEAR(h.at_bearing_deg(359.95), 4.0 - 3.0 * 89.95 / 90.0, 1e-12);
    EXPECT_EQ(h.at_bearing_deg(-90), 4.0);
    EXPECT_EQ(h.at_bearing_deg(720 + 90), 2.0);
    EXPECT_NEAR(h.at_bearing_deg(-45), 2.5, 1e-15);
    EXPECT_EQ(h.at_bearing_deg(-1e-20), 1.0);  // wraps to 360 - tiny, which rounds to 0
    EXPECT_EQ(h.at_bearing_deg(std::nan("")), 1.0);
}

TEST(HorizontalProfile, UniformIsAllOnes) {
    const HorizontalProfile h = HorizontalProfile::uniform();
    for (double b : {0.0, 12.3, 359.99, -500.0}) EXPECT_EQ(h.at_bearing_deg(b), 1.0);
}

TEST(HorizontalProfile, SectorThroughNorthWraps) {
    const std::vector<Sector> s{{350, 10, 1.0, 0}};
    const HorizontalProfile h = HorizontalProfile::from_sectors(s);  // 0.1° table
    // Near-exact: b / 360 * 3600 may land an ulp beside a table point.
    for (double b : {350.0, 355.0, 359.9, 0.0, 5.0, 10.0}) EXPECT_NEAR(h.at_bearing_deg(b), 1.0, 1e-9) << b;
    for (double b : {10.1, 90.0, 180.0, 349.9}) EXPECT_NEAR(h.at_bearing_deg(b), 0.0, 1e-9) << b;
    EXPECT_NEAR(h.at_bearing_deg(10.05), 0.5, 1e-9);  // between the last lit and first dark table points
}

TEST(HorizontalProfile, SectorEdgesFallLinearlyOverEdgeDeg) {
    const std::vector<Sector> s{{90, 180, 0.8, 2.0}};
    const HorizontalProfile h = HorizontalProfile::from_sectors(s);
    EXPECT_NEAR(h.at_bearing_deg(135), 0.8, 1e-7);
    EXPECT_NEAR(h.at_bearing_deg(180), 0.8, 1e-7);
    EXPECT_NEAR(h.at_bearing_deg(181), 0.4, 1e-7);  // edge_deg / 2 outside: level / 2
    EXPECT_NEAR(h.at_bearing_deg(89), 0.4, 1e-7);
    EXPECT_NEAR(h.at_bearing_deg(180.5), 0.6, 1e-7);  // a quarter of the edge: 3/4 level
    EXPECT_NEAR(h.at_bearing_deg(182), 0.0, 1e-7);
    EXPECT_NEAR(h.at_bearing_deg(88), 0.0, 1e-7);
    EXPECT_NEAR(h.at_bearing_deg(270), 0.0, 1e-7);
}

TEST(HorizontalProfile, OverlappingSectorsTakeTheMaximum) {
    const std::vector<Sector> s{{0, 100, 0.5, 0}, {50, 150, 1.0, 0}, {200, 200 + 360, 0.1, 0}};
    const HorizontalProfile h = HorizontalProfile::from_sectors(s, 360);
    EXPECT_NEAR(h.at_bearing_deg(25), 0.5, 1e-7);
    EXPECT_NEAR(h.at_bearing_deg(75), 1.0, 1e-7);
    EXPECT_NEAR(h.at_bearing_deg(125), 1.0, 1e-7);
    EXPECT_NEAR(h.at_bearing_deg(250), 0.1, 1e-7);  // the all-round sector (to = from + 360)
}

TEST(HorizontalProfile, AllRoundSector) {
    const std::vector<Sector> s{{30, 390, 0.7, 0}};
    const HorizontalProfile h = HorizontalProfile::from_sectors(s, 36);
    for (float v : h.table) EXPECT_EQ(v, 0.7f);
}

TEST(HorizontalProfile, BadSectorsAreRejected) {
    const std::vector<Sector> empty{{30, 30, 1, 0}}, wide{{0, 400, 1, 0}}, neg{{0, 90, -1, 0}},
        nan_edge{{0, 90, 1, std::nan("")}};
    EXPECT_NE(error_of([&] { HorizontalProfile::from_sectors(empty); }).find("30° to 30° is empty"), std::string::npos);
    EXPECT_NE(error_of([&] { HorizontalProfile::from_sectors(wide); }).find("more than 360°"), std::string::npos);
    EXPECT_NE(error_of([&] { HorizontalProfile::from_sectors(neg); }).find("level -1"), std::string::npos);
    EXPECT_NE(error_of([&] { HorizontalProfile::from_sectors(nan_edge); }).find("edge nan"), std::string::npos);
}

TEST(HorizontalProfile, FromBearingTableIsPeriodic) {
    const std::vector<double> b{0, 90, 180, 270}, r{1, 0, 1, 0};
    const HorizontalProfile h = HorizontalProfile::from_bearing_table(b, r, 360);
    EXPECT_NEAR(h.at_bearing_deg(45), 0.5, 1e-7);
    EXPECT_NEAR(h.at_bearing_deg(315), 0.5, 1e-7);  // 270 -> 360 (= 0)
    EXPECT_NEAR(h.at_bearing_deg(300), 1.0 / 3.0, 1e-7);

    // Not starting at 0: the wrap segment runs 350° -> 370° (= 10°).
    const std::vector<double> b2{10, 350}, r2{1, 0};
    const HorizontalProfile h2 = HorizontalProfile::from_bearing_table(b2, r2, 3600);
    EXPECT_NEAR(h2.at_bearing_deg(0), 0.5, 1e-7);
    EXPECT_NEAR(h2.at_bearing_deg(355), 0.25, 1e-7);
    EXPECT_NEAR(h2.at_bearing_deg(180), 0.5, 1e-7);  // 10 -> 350: half way

    // A closing 360° entry must repeat 0°.
    const std::vector<double> b3{0, 180, 360}, r3{1, 0, 0.5};
    EXPECT_NE(error_of([&] { HorizontalProfile::from_bearing_table(b3, r3); }).find("360°"), std::string::npos);
    const std::vector<double> r4{1, 0, 1};
    EXPECT_NEAR(HorizontalProfile::from_bearing_table(b3, r4).at_bearing_deg(90), 0.5, 1e-7);
}

TEST(Bearing, AxesOfLightSpace) {
    EXPECT_NEAR(bearing_deg_of_direction(0, -1), 0, 1e-12);    // -z: light-local north
    EXPECT_NEAR(bearing_deg_of_direction(1, 0), 90, 1e-12);    // +x: east
    EXPECT_NEAR(bearing_deg_of_direction(0, 1), 180, 1e-12);   // +z: south
    EXPECT_NEAR(bearing_deg_of_direction(-1, 0), 270, 1e-12);  // -x: west
    EXPECT_NEAR(bearing_deg_of_direction(1, -1), 45, 1e-12);
    EXPECT_NEAR(bearing_deg_of_direction(-1, -1), 315, 1e-12);
    EXPECT_NEAR(bearing_deg_of_direction(-0.0, 1), 180, 1e-12);
    EXPECT_EQ(bearing_deg_of_direction(0, 0), 0.0);
    const double tiny = bearing_deg_of_direction(-1e-300, -1);  // just west of north
    EXPECT_GE(tiny, 0.0);
    EXPECT_LT(tiny, 360.0);
}

// ---- Sabik VP ------------------------------------------------------------------

TEST(SabikVp, FitPassesThroughTheDataSheetPoints) {
    // K2012 §2.3: 50% of peak at ±10°, 10% at ±20°.
    EXPECT_NEAR(sabik_vp_relative_intensity(0), 1.0, 1e-15);
    EXPECT_NEAR(sabik_vp_relative_intensity(10), 0.5, 1e-12);
    EXPECT_NEAR(sabik_vp_relative_intensity(-10), 0.5, 1e-12);
    EXPECT_NEAR(sabik_vp_relative_intensity(20), 0.1, 1e-12);
    EXPECT_NEAR(sabik_vp_relative_intensity(-20), 0.1, 1e-12);
}

TEST(SabikVp, TableMatchesTheFitWithinTheDocumentedTolerance) {
    const VerticalProfile v = sabik_vp_vertical_profile();
    ASSERT_EQ(v.table.size(), 256u);
    for (double e : {-20.0, -10.0, 10.0, 20.0}) {
        const double want = std::abs(e) == 10 ? 0.5 : 0.1;
        EXPECT_NEAR(v.at_p(p_of_elevation(e)), want, 1e-4) << e;
    }
    double prev = 2;
    for (int k = 0; k <= 900; ++k) {
        const double e = k * 0.1;
        EXPECT_NEAR(v.at_p(p_of_elevation(e)), sabik_vp_relative_intensity(e), 1e-3) << e;
        EXPECT_NEAR(v.at_p(p_of_elevation(-e)), v.at_p(p_of_elevation(e)), 1e-6) << e;  // symmetric
        EXPECT_LE(v.at_p(p_of_elevation(e)), prev) << e;  // falls away from the horizontal
        prev = v.at_p(p_of_elevation(e));
    }
}

}  // namespace
