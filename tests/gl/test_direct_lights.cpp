// The direct-light stage on the GPU, held to docs/architecture.md's "Physical invariants":
// energy (Σ L·Ω = I·T·P·B/d²), no flicker, and CPU/GPU agreement of the light model.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/quaternion.hpp>
#include <numbers>
#include <random>
#define GLM_ENABLE_EXPERIMENTAL
#include <glm/gtx/quaternion.hpp>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/atmosphere.h"
#include "atonlab/stimuli/footprint.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/light_model.h"
#include "gl_test_support.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

// A small display with a realistic focal length: 320×240 px, f = 0.9·320/0.1 = 2880 px
// (about 50 px per degree, like a 24" monitor at 90 cm).
Scene black_scene() {
    Scene s;
    s.display = {320, 240, 0.1, 0.9};
    s.camera.position_m = {0, 0, 0};
    s.environment.background = Background::uniform;
    s.environment.luminance_cd_m2 = 0.0;
    return s;
}

class DirectLights : public RendererTest {};

TEST_F(DirectLights, EnergyRuleHoldsFromOneMetreToThirtyKilometres) {
    // Radius 1 cm: a 29 px disc at 1 m, 1 px² near 51 m, 1e-3 px across at 30 km:
    // the sweep crosses the sub/supra-pixel transition.
    Scene scene = black_scene();
    Light light;
    light.radius_m = 0.01;
    light.intensity_cd = 100.0;
    scene.lights = {light};
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int n = 0;
    double worst = 0.0;
    for (double d = 1.0; d <= 30000.0; d *= 1.6) {
        // Somewhere in the field, up to 2.5° off-axis (the image is 6.4° × 4.8°).
        const double ax = u(rng) * 0.04, ay = u(rng) * 0.03;
        const glm::dvec3 dir = glm::normalize(glm::dvec3(std::tan(ax), std::tan(ay), -1.0));
        scene.lights[0].position_m = dir * d;
        renderer->render(scene, 0.0);
        const double expected = 100.0 / (d * d);  // I·T·P·B/d², T = P = B = 1
        const double got = image_illuminance_lux(renderer->read_hdr(), renderer->projection().focal_px);
        EXPECT_NEAR(got / expected, 1.0, 0.01) << "d = " << d << " m";
        worst = std::max(worst, std::abs(got / expected - 1.0));
        ++n;
    }
    EXPECT_GE(n, 20);
    std::printf("energy rule, 1 m .. 30 km: worst relative error %.3g over %d distances\n", worst, n);
}

TEST_F(DirectLights, EnergyRuleHoldsWithFogProfilesAndColour) {
    Scene scene = black_scene();
    scene.environment.extinction_per_m = extinction_per_m_from_visibility_m(5.0 * metres_per_nautical_mile);
    Light light;
    light.radius_m = 0.1;
    light.intensity_cd = 250.0;
    light.rgb_per_cd = *iala_colour_rgb("green");
    light.position_m = {3.0, 1.0, -1852.0};
    scene.lights = {light};
    renderer->render(scene, 0.0);
    const LightAtEye ref =
        evaluate_light(light, scene.profiles, scene.camera.position_m, 0.0, scene.environment.extinction_per_m);
    const double got = image_illuminance_lux(renderer->read_hdr(), renderer->projection().focal_px);
    EXPECT_NEAR(got / illuminance_lux(ref), 1.0, 0.01);
    // Bouguer (K2012 eq 4.14) really attenuated it: T(d) at V = 5 nmi is 0.05^(d/V).
    EXPECT_NEAR(ref.transmittance, std::pow(0.05, glm::length(light.position_m) / (5.0 * 1852.0)), 1e-12);
}

TEST_F(DirectLights, NoFlickerWhenASubPixelLightMovesInSubPixelSteps) {
    Scene scene = black_scene();
    Light light;
    light.intensity_cd = 100.0;
    scene.lights = {light};
    // 5 km: a 0.003 px² box; 60 m: a 72 px² disc (r = 0.1 m).
    for (double d : {5000.0, 60.0}) {
        double first = -1.0, worst = 0.0;
        for (int step = 0; step < 40; ++step) {
            // 0.07 px per step across about three pixels, horizontally and a little vertically.
            const double px = 0.07 * step;
            const double f = 2880.0;
            scene.lights[0].position_m = glm::dvec3(px / f * d, 0.3 * px / f * d, -d);
            renderer->render(scene, 0.0);
            const double e = image_illuminance_lux(renderer->read_hdr(), renderer->projection().focal_px);
            if (first < 0) first = e;
            worst = std::max(worst, std::abs(e / first - 1.0));
        }
        EXPECT_LT(worst, 1e-3) << "d = " << d;
        std::printf("moving light at %g m: worst frame-to-frame energy change %.3g\n", d, worst);
    }
}

TEST_F(DirectLights, LightsBehindTheCameraOrHiddenBySeaEmitNothing) {
    Scene scene = black_scene();
    Light behind;
    behind.position_m = {0, 0, 100};
    Light below_sea;  // under the flat sea, seen from 3 m above it
    below_sea.position_m = {0, -5, -200};
    scene.lights = {behind, below_sea};
    scene.camera.position_m = {0, 3, 0};
    scene.environment.background = Background::sky_sea;
    scene.environment.luminance_cd_m2 = 0.0;
    renderer->render(scene, 0.0);
    EXPECT_EQ(image_illuminance_lux(renderer->read_hdr(), renderer->projection().focal_px), 0.0);
    EXPECT_EQ(renderer->stats().drawn, 0);
}

TEST_F(DirectLights, BackgroundIsTheConfiguredLuminance) {
    Scene scene = black_scene();
    scene.environment.luminance_cd_m2 = 0.03;
    renderer->render(scene, 0.0);
    const ImageRGBA32F img = renderer->read_hdr();
    for (int i : {0, 1000, 76799}) {
        const float* p = &img.rgba[static_cast<std::size_t>(i) * 4];
        EXPECT_FLOAT_EQ(p[0], 0.03f);
        EXPECT_FLOAT_EQ(p[1], 0.03f);
        EXPECT_FLOAT_EQ(p[2], 0.03f);
    }
}

TEST_F(DirectLights, SeaReflectsTheSkyWithSchlickFresnel) {
    Scene scene = black_scene();
    scene.environment.background = Background::sky_sea;
    scene.environment.luminance_cd_m2 = 1.0;
    scene.camera.position_m = {0, 10, 0};
    scene.camera.pitch_deg = -2.0;  // the horizon in the upper part of the image
    renderer->render(scene, 0.0);
    const ImageRGBA32F img = renderer->read_hdr();
    // Bottom-centre pixel: its ray leaves the eye at elevation -2° - atan((119.5 - 0) / f) ...
    const double f = renderer->projection().focal_px;
    const double elev = -2.0 * std::numbers::pi / 180.0 - std::atan(119.5 / f);
    const double cos_i = std::sin(-elev);
    const double fresnel = 0.02 + 0.98 * std::pow(1.0 - cos_i, 5.0);  // K2012 eq 3.17
    EXPECT_NEAR(img.pixel(160, 239)[1], fresnel, 2e-3 * fresnel);
    EXPECT_FLOAT_EQ(img.pixel(160, 0)[1], 1.0f);  // sky at the top
}

// The GPU light model against the CPU reference, for random lights, orientations,
// sectored profiles with soft edges, rhythms and viewing directions.
TEST_F(DirectLights, GpuLightModelMatchesCpuReference) {
    std::mt19937 rng(1234);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Scene scene = black_scene();
    scene.display = {64, 64, 0.1, 0.9};
    scene.camera.position_m = {10.0, 3.0, -20.0};
    scene.environment.extinction_per_m = 1e-4;
    const std::vector<Sector> sectors = {{20, 110, 1.0, 3.0}, {200, 260, 0.6, 1.0}, {330, 30, 0.8, 5.0}};
    scene.profiles.horizontal.push_back(HorizontalProfile::from_sectors(sectors));
    const std::vector<double> elev = {-90, -20, -10, 0, 10, 20, 90}, rel = {0, 0.1, 0.5, 1, 0.5, 0.1, 0};
    scene.profiles.vertical.push_back(VerticalProfile::from_elevation_table(elev, rel));
    const Rhythm rhythm = parse_rhythm("Fl(2) 10s");
    for (int i = 0; i < 2000; ++i) {
        Light L;
        const double dist = std::exp(std::log(5.0) + u(rng) * std::log(2e4));
        const glm::dvec3 dir = glm::normalize(glm::dvec3(u(rng) - 0.5, 0.3 * (u(rng) - 0.5), u(rng) - 0.5));
        L.position_m = scene.camera.position_m + dir * dist;
        L.orientation = glm::normalize(glm::dquat(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5));
        L.intensity_cd = 1.0 + 1e4 * u(rng);
        L.rgb_per_cd = {u(rng) * 3, u(rng) * 2, u(rng) * 5};
        L.horizontal_profile = 1;
        L.vertical_profile = 1;
        L.rhythm = rhythm.channels[0].knots;
        L.rhythm_period_s = rhythm.period_s;
        L.rhythm_phase_s = 10.0 * u(rng);
        scene.lights.push_back(L);
    }
    // Every fifth light looks at the eye from exactly on a sector edge: its
    // light-space bearing to the eye is an edge (from_deg - edge/2 etc.).
    for (std::size_t i = 0; i < scene.lights.size(); i += 5) {
        Light& L = scene.lights[i];
        const double edge_bearing = std::vector<double>{20, 18.5, 110, 111.5, 200, 260, 330, 30, 32.5}[i / 5 % 9];
        const glm::dvec3 to_eye = scene.camera.position_m - L.position_m;
        const double dist = glm::length(to_eye);
        const double b = edge_bearing * std::numbers::pi / 180.0;
        // Light-space direction with that bearing, 5° elevation; choose the orientation that maps it to to_eye.
        const glm::dvec3 e_light = glm::normalize(glm::dvec3(std::sin(b), 0.0875, -std::cos(b)));
        L.orientation = glm::rotation(e_light, to_eye / dist);
    }
    const double time_s = 3.7;
    renderer->render(scene, time_s);
    const auto draws = renderer->read_light_draws();
    // The GPU sees eye-relative positions rounded to fp32: give the CPU the same inputs.
    const GpuLightTables packed = pack_lights(scene, scene.camera.position_m);
    double worst = 0.0, worst_edge = 0.0;
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        Light L = scene.lights[i];
        const float* rec = &packed.lights[i * 24];
        L.position_m = glm::dvec3(rec[0], rec[1], rec[2]);
        L.orientation = glm::dquat(rec[7], rec[4], rec[5], rec[6]);
        L.rhythm_phase_s = rec[11];
        for (auto& k : L.rhythm) k = {static_cast<float>(k.t_s), static_cast<float>(k.level)};
        const LightAtEye ref = evaluate_light(L, scene.profiles, glm::dvec3(0.0), time_s,
                                              static_cast<float>(scene.environment.extinction_per_m));
        const glm::dvec3 cpu = ref.illuminance_rgb_lux;
        const glm::dvec3 gpu = draws[i].illuminance_rgb_lux;
        // Relative to the light's unshielded peak at that distance (I·rgb·T/d²), so
        // that values near zero on a steep edge are judged by the slope's scale.
        const double peak = L.intensity_cd * ref.transmittance / (ref.distance_m * ref.distance_m) *
                            std::max({L.rgb_per_cd.r, L.rgb_per_cd.g, L.rgb_per_cd.b});
        for (int c = 0; c < 3; ++c) {
            const double err = std::abs(gpu[c] - cpu[c]) / peak;
            worst = std::max(worst, err);
            if (i % 5 == 0) worst_edge = std::max(worst_edge, err);
        }
        ASSERT_NEAR(draws[i].horizontal, ref.horizontal, 1e-5) << "light " << i;
        ASSERT_NEAR(draws[i].vertical, ref.vertical, 1e-5) << "light " << i;
        ASSERT_NEAR(draws[i].rhythm, ref.rhythm, 1e-5) << "light " << i;
    }
    std::printf("GPU vs CPU light model: worst relative error %.3g (sector edges %.3g)\n", worst, worst_edge);
    EXPECT_LT(worst, 1e-5);
}

}  // namespace
}  // namespace atonlab::test
