// The footprint math (footprint.h) against brute force and closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "atonlab/stimuli/footprint.h"

namespace atonlab::stimuli {
namespace {

// Brute force: fraction of an n×n grid of sample points of the pixel inside the disc.
double brute_coverage(double cx, double cy, double r, double x0, double y0, int n) {
    int inside = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double x = x0 + (i + 0.5) / n - cx, y = y0 + (j + 0.5) / n - cy;
            inside += x * x + y * y <= r * r ? 1 : 0;
        }
    return static_cast<double>(inside) / (static_cast<double>(n) * n);
}

TEST(Footprint, DiscCoverageMatchesBruteForce) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int t = 0; t < 300; ++t) {
        const double r = 0.2 + 4.0 * u(rng);
        const double cx = u(rng) * 3.0, cy = u(rng) * 3.0;
        const double x0 = std::floor(cx + (u(rng) - 0.5) * 2.0 * r), y0 = std::floor(cy + (u(rng) - 0.5) * 2.0 * r);
        // A 2000² grid resolves the area to ~1e-3 of a pixel (edge length / n).
        EXPECT_NEAR(disc_pixel_coverage(cx, cy, r, x0, y0), brute_coverage(cx, cy, r, x0, y0, 2000), 2e-3)
            << "r=" << r << " c=(" << cx << "," << cy << ") p=(" << x0 << "," << y0 << ")";
    }
}

TEST(Footprint, DiscCoverageSumsToTheDiscArea) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (double r : {0.5642, 0.8, 1.0, 2.5, 17.3, 300.0}) {
        for (int t = 0; t < 5; ++t) {
            const double cx = 1000.0 + u(rng), cy = 500.0 + u(rng);
            double sum = 0.0;
            for (double y = std::floor(cy - r) - 1; y <= cy + r + 1; ++y)
                for (double x = std::floor(cx - r) - 1; x <= cx + r + 1; ++x) sum += disc_pixel_coverage(cx, cy, r, x, y);
            EXPECT_NEAR(sum / (std::numbers::pi * r * r), 1.0, 1e-12) << "r=" << r;
        }
    }
}

TEST(Footprint, DiscInsideOnePixelCoversItsArea) {
    EXPECT_NEAR(disc_pixel_coverage(10.5, 20.5, 0.3, 10.0, 20.0), std::numbers::pi * 0.09, 1e-14);
    EXPECT_EQ(disc_pixel_coverage(10.5, 20.5, 0.3, 11.0, 20.0), 0.0);
    EXPECT_EQ(disc_pixel_coverage(10.5, 20.5, 5.0, 10.0, 20.0), 1.0);
}

TEST(Footprint, BoxCoverageIsBilinearAndSumsToOne) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int t = 0; t < 100; ++t) {
        const double cx = 50 + u(rng), cy = 60 + u(rng);
        double sum = 0;
        for (int y = 58; y < 63; ++y)
            for (int x = 48; x < 53; ++x) sum += box_pixel_coverage(cx, cy, x, y);
        EXPECT_NEAR(sum, 1.0, 1e-14);
    }
    // Centred on a pixel centre: all of it in that pixel.
    EXPECT_DOUBLE_EQ(box_pixel_coverage(7.5, 7.5, 7, 7), 1.0);
    // On a pixel corner: a quarter in each of four.
    EXPECT_DOUBLE_EQ(box_pixel_coverage(8.0, 8.0, 7, 7), 0.25);
}

TEST(Footprint, SphereSolidAngleIsAccurateFarAndNear) {
    // 2π(1 − cos β) evaluated naively in long double as the reference.
    for (double d : {0.2, 1.0, 10.0, 1e3, 3e4, 5e4}) {
        const long double s = 0.1L / d;
        const long double naive = 2.0L * std::numbers::pi_v<long double> * (1.0L - std::sqrt(1.0L - s * s));
        EXPECT_NEAR(sphere_solid_angle_sr(0.1, d) / static_cast<double>(naive), 1.0, 1e-6) << d;
    }
    // Far away it tends to π r²/d².
    EXPECT_NEAR(sphere_solid_angle_sr(0.1, 3e4) / (std::numbers::pi * 1e-2 / 9e8), 1.0, 1e-9);
    EXPECT_DOUBLE_EQ(sphere_solid_angle_sr(0.1, 0.05), 2.0 * std::numbers::pi);
}

TEST(Footprint, PixelSolidAnglesTileTheImage) {
    // The pixels of a W×H image tile the rectangle [-W/2, W/2]×[-H/2, H/2] on the
    // plane z = f; its solid angle is 4 atan(ab / (f sqrt(a² + b² + f²))).
    const double f = 500.0;
    const int W = 64, H = 48;
    double sum = 0;
    for (int y = -H / 2; y < H / 2; ++y)
        for (int x = -W / 2; x < W / 2; ++x) sum += pixel_solid_angle_sr(x, y, f);
    const double a = W / 2.0, b = H / 2.0;
    EXPECT_NEAR(sum, 4.0 * std::atan(a * b / (f * std::sqrt(a * a + b * b + f * f))), 1e-15);
    // At the centre one pixel subtends 1/f² sr.
    EXPECT_NEAR(pixel_solid_angle_sr(-0.5, -0.5, f) * f * f, 1.0, 1e-5);
}

TEST(Footprint, OffAxisFootprintGrowsAsOneOverCosCubed) {
    const double f = 1000.0;
    const Footprint on = light_footprint({0, 0, -100}, 0.5, f, 2000, 2000);
    const double a = 0.5;  // rad off-axis, same distance
    const Footprint off = light_footprint({100 * std::sin(a), 0, -100 * std::cos(a)}, 0.5, f, 2000, 2000);
    ASSERT_TRUE(on.visible && off.visible);
    EXPECT_NEAR(off.area_px2 / on.area_px2, 1.0 / std::pow(std::cos(a), 3), 1e-12);
    EXPECT_NEAR(off.centre_px.x - 1000.0, f * std::tan(a), 1e-9);
    EXPECT_FALSE(light_footprint({0, 0, 100}, 0.1, f, 100, 100).visible);    // behind
    EXPECT_FALSE(light_footprint({0, 0, -0.05}, 0.1, f, 100, 100).visible);  // eye inside the sphere
}

}  // namespace
}  // namespace atonlab::stimuli
