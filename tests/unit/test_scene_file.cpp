// The scene file: a full scene parses to hand-derived values (unit conversions
// and defaults), the output tables are read, Al. characters expand into one
// light per colour, and chart sector bearings (from seaward) light the
// observers a chart says they light. Its errors: test_scene_file_errors.cpp;
// [eye] and [glare]: test_scene_file_glare.cpp; --set overrides and
// templates: test_scene_file_overrides.cpp.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/display/colour.h"
#include "atonlab/stimuli/profile.h"
#include "atonlab/stimuli/rhythm.h"
#include "atonlab/stimuli/scene_file.h"
#include "scene_file_test_support.h"

using atonlab::InputError;
using namespace atonlab::stimuli;
using namespace atonlab::display;
using namespace atonlab::stimuli::scene_file_test;  // NOLINT: the shared scenes and readers

namespace {

double luminance(glm::dvec3 rgb) {
    return 0.2126 * rgb.r + 0.7152 * rgb.g + 0.0722 * rgb.b;
}
// ---------------------------------------------------------------------------
// A valid scene.

TEST(SceneFile, FullSceneParsesToExpectedValues) {
    const Scene s = parse_scene(kFullScene, kFile);
    EXPECT_EQ(s.display.width_px, 1920);
    EXPECT_EQ(s.display.height_px, 1080);
    EXPECT_EQ(s.display.width_m, 0.598);
    EXPECT_EQ(s.display.viewing_distance_m, 0.9);

    EXPECT_EQ(s.camera.position_m, glm::dvec3(1.0, 4.0, -2.0));
    EXPECT_EQ(s.camera.yaw_deg, 45.0);  // an integer in the file is a number
    EXPECT_EQ(s.camera.pitch_deg, -2.5);
    EXPECT_EQ(s.camera.roll_deg, 1.0);
    ASSERT_TRUE(s.camera.fov_y_deg.has_value());
    EXPECT_EQ(*s.camera.fov_y_deg, 30.0);

    EXPECT_EQ(s.environment.background, Background::uniform);
    EXPECT_EQ(s.environment.luminance_cd_m2, 0.01);
    // 10 nmi = 18520 m; sigma = -ln(0.05) / V = ln 20 / 18520 m.
    EXPECT_NEAR(s.environment.extinction_per_m, 2.995732273553991 / 18520.0, 1e-15);
    EXPECT_EQ(s.environment.sea_reflectance_f0, 0.03);
    EXPECT_EQ(s.adaptation_cd_m2, 0.01);  // defaults to the environment's luminance

    // Profiles: uniform first; "lantern" used twice is stored once.
    ASSERT_EQ(s.profiles.vertical.size(), 3u);
    ASSERT_EQ(s.profiles.horizontal.size(), 2u);
    ASSERT_EQ(s.lights.size(), 3u);
    const Light& buoy = s.lights[0];
    const Light& second = s.lights[1];
    const Light& pier = s.lights[2];
    EXPECT_EQ(buoy.vertical_profile, 1);
    EXPECT_EQ(second.vertical_profile, 2);
    EXPECT_EQ(pier.vertical_profile, 1);
    EXPECT_EQ(buoy.horizontal_profile, 1);
    EXPECT_EQ(second.horizontal_profile, 0);
    EXPECT_EQ(pier.horizontal_profile, 0);
    // lantern: 1 at the horizon (p = 0.5), 0 straight up and down.
    EXPECT_NEAR(s.profiles.vertical[1].at_cos_theta(0.0), 1.0, 1e-2);
    EXPECT_NEAR(s.profiles.vertical[1].at_cos_theta(1.0), 0.0, 1e-6);
    // sabik-vp: 0.5 at 10° elevation (cos θ = sin 10°).
    EXPECT_NEAR(s.profiles.vertical[2].at_cos_theta(std::sin(10.0 * std::numbers::pi / 180.0)), 0.5, 1e-3);

    EXPECT_EQ(buoy.name, "buoy");
    EXPECT_EQ(buoy.position_m, glm::dvec3(0.0, 2.0, -1852.0));
    EXPECT_EQ(buoy.intensity_cd, 250.0);
    EXPECT_EQ(buoy.radius_m, 0.1);
    EXPECT_EQ(buoy.rgb_per_cd, *iala_colour_rgb("red"));
    EXPECT_GT(buoy.rgb_per_cd.r, buoy.rgb_per_cd.g);
    EXPECT_NEAR(luminance(buoy.rgb_per_cd), 1.0, 1e-3);  // the printed coefficients have 4 digits
    EXPECT_EQ(buoy.rhythm_period_s, 10.0);
    RhythmTiming timing;
    timing.ramp_s = 0.05;
    const Rhythm fl2 = parse_rhythm("Fl(2) 10s", timing);
    ASSERT_EQ(buoy.rhythm.size(), fl2.channels[0].knots.size());
    for (std::size_t i = 0; i < buoy.rhythm.size(); ++i) {
        EXPECT_EQ(buoy.rhythm[i].t_s, fl2.channels[0].knots[i].t_s);
        EXPECT_EQ(buoy.rhythm[i].level, fl2.channels[0].knots[i].level);
    }
    EXPECT_EQ(buoy.rhythm_phase_s, 0.0);
    // yaw 90: the light's north (-z) turns clockwise to east (+x).
    const glm::dvec3 north_of_light = buoy.orientation * glm::dvec3(0, 0, -1);
    EXPECT_NEAR(north_of_light.x, 1.0, 1e-12);
    EXPECT_NEAR(north_of_light.y, 0.0, 1e-12);
    EXPECT_NEAR(north_of_light.z, 0.0, 1e-12);

    EXPECT_EQ(second.name, "light1");  // default name: "light" + its 0-based index
    EXPECT_EQ(second.radius_m, 0.25);
    EXPECT_EQ(second.intensity_cd, 1000.0);
    EXPECT_EQ(second.rhythm_period_s, 0.0);
    ASSERT_EQ(second.rhythm.size(), 1u);
    EXPECT_EQ(second.rhythm[0].level, 1.0);
    EXPECT_EQ(second.rhythm_phase_s, 1.5);
    // D65's xy is (near enough) the Rec.709 white: RGB (1, 1, 1) at Y = 1.
    EXPECT_NEAR(second.rgb_per_cd.r, 1.0, 2e-3);
    EXPECT_NEAR(second.rgb_per_cd.g, 1.0, 2e-3);
    EXPECT_NEAR(second.rgb_per_cd.b, 1.0, 2e-3);
    EXPECT_EQ(second.orientation, glm::dquat(1, 0, 0, 0));

    EXPECT_EQ(pier.rgb_per_cd, normalised_rgb_from_spectrum(*named_spectrum("led-green")));
    EXPECT_GT(pier.rgb_per_cd.g, pier.rgb_per_cd.r);
    EXPECT_NEAR(luminance(pier.rgb_per_cd), 1.0, 1e-3);
}

TEST(SceneFile, DefaultsOfAMinimalScene) {
    const Scene s = parse_scene(kMinimal, kFile);
    EXPECT_EQ(s.display.width_px, 800);
    EXPECT_EQ(s.camera.position_m, glm::dvec3(0.0, 3.0, 0.0));
    EXPECT_EQ(s.camera.yaw_deg, 0.0);
    EXPECT_EQ(s.camera.pitch_deg, 0.0);
    EXPECT_EQ(s.camera.roll_deg, 0.0);
    EXPECT_FALSE(s.camera.fov_y_deg.has_value());  // the display's visual angle
    EXPECT_EQ(s.environment.background, Background::sky_sea);
    EXPECT_EQ(s.environment.luminance_cd_m2, 0.001);
    EXPECT_EQ(s.environment.extinction_per_m, 0.0);
    EXPECT_EQ(s.environment.sea_reflectance_f0, 0.02);
    EXPECT_EQ(s.adaptation_cd_m2, 0.001);
    EXPECT_TRUE(s.lights.empty());
    EXPECT_EQ(s.profiles.vertical.size(), 1u);
    EXPECT_EQ(s.profiles.horizontal.size(), 1u);
}

TEST(SceneFile, LightDefaults) {
    const Scene s = parse_scene(with_light("position_m = [0, 2, -100]\nintensity_cd = 10\n"), kFile);
    ASSERT_EQ(s.lights.size(), 1u);
    const Light& l = s.lights[0];
    EXPECT_EQ(l.name, "light0");
    EXPECT_EQ(l.radius_m, 0.1);
    EXPECT_EQ(l.rgb_per_cd, *iala_colour_rgb("white"));
    EXPECT_EQ(l.vertical_profile, 0);
    EXPECT_EQ(l.horizontal_profile, 0);
    EXPECT_EQ(l.rhythm_period_s, 0.0);
    EXPECT_EQ(l.rhythm_phase_s, 0.0);
    EXPECT_EQ(l.orientation, glm::dquat(1, 0, 0, 0));
}

TEST(SceneFile, ExtinctionPerKmAndDarkSkyAdaptation) {
    const Scene s =
        parse_scene(std::string(kMinimal) + "[environment]\nextinction_per_km = 0.5\nluminance_cd_m2 = 0\n", kFile);
    EXPECT_EQ(s.environment.extinction_per_m, 5e-4);
    EXPECT_EQ(s.environment.luminance_cd_m2, 0.0);
    EXPECT_EQ(s.adaptation_cd_m2, 0.001);  // a black sky cannot be the adaptation level
    const Scene t = parse_scene(std::string(kMinimal) + "[eye]\nadaptation_cd_m2 = 3\n", kFile);
    EXPECT_EQ(t.adaptation_cd_m2, 3.0);
}

TEST(SceneFile, LightOrientationConvention) {
    // pitch 90: the light's north (-z) points up; roll 90 (clockwise looking
    // forward): the light's up (+y) points to its right (+x).
    const Scene s =
        parse_scene(with_light("position_m = [0, 0, 0]\nintensity_cd = 1\npitch_deg = 90\n") +
                        "[[light]]\nposition_m = [0, 0, 0]\nintensity_cd = 1\nroll_deg = 90\n"
                        "[[light]]\nposition_m = [0, 0, 0]\nintensity_cd = 1\nyaw_deg = 90\npitch_deg = 30\n",
                    kFile);
    ASSERT_EQ(s.lights.size(), 3u);
    const glm::dvec3 forward = s.lights[0].orientation * glm::dvec3(0, 0, -1);
    EXPECT_NEAR(forward.y, 1.0, 1e-12);
    const glm::dvec3 up = s.lights[1].orientation * glm::dvec3(0, 1, 0);
    EXPECT_NEAR(up.x, 1.0, 1e-12);
    // Heading east, then 30° up: (cos 30°, sin 30°, 0).
    const glm::dvec3 f2 = s.lights[2].orientation * glm::dvec3(0, 0, -1);
    // The same convention as the camera's.
    Camera camera;
    camera.yaw_deg = 90;
    camera.pitch_deg = 30;
    EXPECT_EQ(s.lights[2].orientation, camera.orientation());
    EXPECT_NEAR(f2.x, std::sqrt(3.0) / 2.0, 1e-12);
    EXPECT_NEAR(f2.y, 0.5, 1e-12);
    EXPECT_NEAR(f2.z, 0.0, 1e-12);
}

TEST(SceneFile, LoadsFromAFileAndNamesIt) {
    std::random_device rd;
    const auto dir = std::filesystem::temp_directory_path() /
                     ("atonlab-scene-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
    std::filesystem::create_directories(dir);
    const auto good = dir / "good.toml";
    std::ofstream(good) << kFullScene;
    EXPECT_EQ(load_scene(good).lights.size(), 3u);
    EXPECT_EQ(load_scene(good, sets({"light.buoy.intensity_cd=7"})).lights[0].intensity_cd, 7.0);

    const auto bad = dir / "bad.toml";
    std::ofstream(bad) << kMinimal << "[camera]\nyaw_deg = \"north\"\n";
    try {
        load_scene(bad);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(bad.string() + ":7:"), std::string::npos) << e.what();
    }
    try {
        load_scene(dir / "missing.toml");
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find((dir / "missing.toml").string()), std::string::npos) << e.what();
    }
    std::filesystem::remove_all(dir);
}

// display.out_of_gamut (docs/tone-mapping.md "Out of gamut: colour or luminance"): keep-luminance
// by default; the one key sets the encoder's and the tone mapper's choice; a wrong name says which.
TEST(SceneFile, OutOfGamutIsReadForTheEncoderAndTheToneMapper) {
    const Scene plain = parse_scene(kMinimal, kFile);
    EXPECT_EQ(plain.output.encode.out_of_gamut, OutOfGamut::keep_luminance);
    EXPECT_EQ(plain.output.tonemap.out_of_gamut, OutOfGamut::keep_luminance);
    const Scene coloured = parse_scene(std::string(kMinimal) + "out_of_gamut = \"keep-signal-colour\"\n", kFile);
    EXPECT_EQ(coloured.output.encode.out_of_gamut, OutOfGamut::keep_signal_colour);
    EXPECT_EQ(coloured.output.tonemap.out_of_gamut, OutOfGamut::keep_signal_colour);
    expect_error_at(std::string(kMinimal) + "out_of_gamut = \"keep-colour\"\n", 6, "display.out_of_gamut",
                    "\"keep-luminance\", \"keep-signal-colour\", \"keep-chromaticity\", \"clip-channels\"");
}

TEST(SceneFileOutput, TonemapDisplayAndAdaptationAreRead) {
    const std::string text = std::string(kMinimal) +
                             "peak_cd_m2 = 250\nblack_cd_m2 = 0.2\nbits = 10\ndither = false\n"
                             "[eye]\nadaptation = \"dynamic\"\nadaptation_cd_m2 = 0.03\n"
                             "[tonemap]\noperator = \"perceptual\"\nblueshift = false\nhue_preservation = \"rgb\"\n"
                             "ldr_glare = true\n";
    const Scene scene = parse_scene(text, "out.toml");
    EXPECT_EQ(scene.output.adaptation.mode, AdaptationMode::dynamic);
    EXPECT_EQ(scene.adaptation_cd_m2, 0.03);
    EXPECT_EQ(scene.output.display.peak_cd_m2, 250.0);
    EXPECT_EQ(scene.output.display.black_cd_m2, 0.2);
    EXPECT_EQ(scene.output.tonemap.display_peak_cd_m2, 250.0);
    EXPECT_EQ(scene.output.encode.bits, 10);
    EXPECT_EQ(scene.output.encode.dither, Dither::none);
    EXPECT_EQ(scene.output.tonemap.tone_operator, ToneOperator::perceptual);
    EXPECT_FALSE(scene.output.tonemap.blueshift);
    EXPECT_EQ(scene.output.tonemap.hue_preservation, HuePreservation::rgb);
    EXPECT_TRUE(scene.output.ldr_glare);
    // A display whose black is not below its peak is refused where it is written.
    const std::string bad = std::string(kMinimal) + "peak_cd_m2 = 100\nblack_cd_m2 = 100\n";
    expect_error_at(bad, line_of(bad, "black_cd_m2"), "display.black_cd_m2", "below its peak");
    const std::string white = std::string(kMinimal) + "[tonemap]\nwhite_relative = -1\n";
    expect_error_at(white, line_of(white, "white_relative"), "tonemap.white_relative", "white_relative");
    // tonemap.mesopic: k2012 by default, cie191 read, anything else refused at its line.
    EXPECT_EQ(scene.output.tonemap.mesopic, MesopicModel::k2012);
    const Scene cie = parse_scene(std::string(kMinimal) + "[tonemap]\nmesopic = \"cie191\"\n", "out.toml");
    EXPECT_EQ(cie.output.tonemap.mesopic, MesopicModel::cie191);
    const std::string mes = std::string(kMinimal) + "[tonemap]\nmesopic = \"mes2\"\n";
    expect_error_at(mes, line_of(mes, "mesopic"), "tonemap.mesopic", "\"k2012\"");
}

// ---------------------------------------------------------------------------
// Alternating lights and sector bearings.

TEST(SceneFile, AlternatingCharacterExpandsIntoOneLightPerColour) {
    const Scene s = parse_scene(
        with_light("name = \"lh\"\nposition_m = [0, 20, -3000]\nintensity_cd = 5000\nrhythm = \"Al.WR 4s\"\n"), kFile);
    ASSERT_EQ(s.lights.size(), 2u);
    const Light& w = s.lights[0];
    const Light& r = s.lights[1];
    EXPECT_EQ(w.name, "lh/W");
    EXPECT_EQ(r.name, "lh/R");
    EXPECT_EQ(w.rgb_per_cd, *iala_colour_rgb("white"));
    EXPECT_EQ(r.rgb_per_cd, *iala_colour_rgb("red"));
    EXPECT_EQ(w.rhythm_period_s, 4.0);
    EXPECT_EQ(r.rhythm_period_s, 4.0);
    EXPECT_EQ(w.intensity_cd, 5000.0);
    EXPECT_EQ(r.position_m, glm::dvec3(0, 20, -3000));
    // Al.WR 4s: white for the first 2 s, red for the next 2 s.
    EXPECT_EQ(rhythm_level(w.rhythm, 4.0, 1.0), 1.0);
    EXPECT_EQ(rhythm_level(r.rhythm, 4.0, 1.0), 0.0);
    EXPECT_EQ(rhythm_level(w.rhythm, 4.0, 3.0), 0.0);
    EXPECT_EQ(rhythm_level(r.rhythm, 4.0, 3.0), 1.0);

    // An expanded name may not collide with another light's.
    const std::string clash =
        with_light("name = \"lh\"\nposition_m = [0, 0, 0]\nintensity_cd = 1\nrhythm = \"Al.WR 4s\"\n") +
        "[[light]]\nname = \"lh/R\"\nposition_m = [0, 0, 0]\nintensity_cd = 1\n";
    const InputError e = error_of(clash);
    EXPECT_NE(std::string(e.what()).find("\"lh/R\" is already used"), std::string::npos) << e.what();
}

/// Light-space bearing of the direction from a light to an observer at world
/// offset (dx, dz) from it.
double bearing_to_observer(const Light& light, double dx, double dz) {
    const glm::dvec3 d = glm::inverse(light.orientation) * glm::dvec3(dx, 0.0, dz);
    return bearing_deg_of_direction(d.x, d.z);
}

TEST(SceneFile, SectorBearingsAreFromSeaward) {
    // A chart's "W 090°-180°": an observer who sees the light on a bearing
    // between 090 and 180 (the light lies E to S of them) sees it, so the lit
    // observers are W to N of the light. North is -z, east +x.
    const Scene s = parse_scene(with_light("position_m = [0, 0, 0]\nintensity_cd = 1\n"
                                           "sectors = [{ from_deg = 90, to_deg = 180 }]\n") +
                                    "[[light]]\nposition_m = [0, 0, 0]\nintensity_cd = 1\nyaw_deg = 90\n"
                                    "sectors = [{ from_deg = 90, to_deg = 180 }]\n",
                                kFile);
    const Light& l = s.lights[0];
    const HorizontalProfile& h = s.profiles.horizontal[static_cast<std::size_t>(l.horizontal_profile)];
    // Observer NW of the light sees it bearing 135: lit.
    EXPECT_EQ(h.at_bearing_deg(bearing_to_observer(l, -1, -1)), 1.0);
    // Observer W by N (sees the light on 100) and N by W (on 170): lit.
    EXPECT_EQ(h.at_bearing_deg(bearing_to_observer(l, -std::cos(0.1745), -std::sin(0.1745))), 1.0);
    EXPECT_EQ(h.at_bearing_deg(bearing_to_observer(l, -std::sin(0.1745), -std::cos(0.1745))), 1.0);
    // Observer SE (sees it on 315), W by S (on 080) and N by E (on 190): dark.
    EXPECT_EQ(h.at_bearing_deg(bearing_to_observer(l, 1, 1)), 0.0);
    EXPECT_EQ(h.at_bearing_deg(bearing_to_observer(l, -std::cos(0.1745), std::sin(0.1745))), 0.0);
    EXPECT_EQ(h.at_bearing_deg(bearing_to_observer(l, std::sin(0.1745), -std::cos(0.1745))), 0.0);

    // The light's yaw turns the whole pattern clockwise: with yaw 90 the lit
    // observers are N to E of the light.
    const Light& turned = s.lights[1];
    EXPECT_EQ(turned.horizontal_profile, l.horizontal_profile);             // same table, shared
    EXPECT_EQ(h.at_bearing_deg(bearing_to_observer(turned, 1, -1)), 1.0);   // NE
    EXPECT_EQ(h.at_bearing_deg(bearing_to_observer(turned, -1, -1)), 0.0);  // NW
}

TEST(SceneFile, SectorThroughNorthAndBearingTable) {
    // From seaward 300..060 wraps through north: observers S of the light
    // (seeing it on 000) are lit; observers N of it (seeing it on 180) are not.
    const Scene s =
        parse_scene(std::string(kMinimal) +
                        "[profiles.horizontal.wrap]\nsectors = [{ from_deg = 300, to_deg = 60 }]\n"
                        "[profiles.horizontal.table]\nbearing_deg = [0, 90, 180, 270]\nrelative = [1, 0.5, 0, 0.25]\n"
                        "[[light]]\nposition_m = [0, 0, 0]\nintensity_cd = 1\nhorizontal_profile = \"wrap\"\n"
                        "[[light]]\nposition_m = [0, 0, 0]\nintensity_cd = 1\nhorizontal_profile = \"table\"\n",
                    kFile);
    const HorizontalProfile& wrap = s.profiles.horizontal[static_cast<std::size_t>(s.lights[0].horizontal_profile)];
    EXPECT_EQ(wrap.at_bearing_deg(bearing_to_observer(s.lights[0], 0, 1)), 1.0);   // observer S
    EXPECT_EQ(wrap.at_bearing_deg(bearing_to_observer(s.lights[0], 0, -1)), 0.0);  // observer N
    // Bearing table from seaward: 1 for the observer who sees the light on 000
    // (south of it), 0.5 on 090 (west of it), 0 on 180 (north), 0.25 on 270 (east).
    const HorizontalProfile& table = s.profiles.horizontal[static_cast<std::size_t>(s.lights[1].horizontal_profile)];
    EXPECT_NEAR(table.at_bearing_deg(bearing_to_observer(s.lights[1], 0, 1)), 1.0, 1e-6);
    EXPECT_NEAR(table.at_bearing_deg(bearing_to_observer(s.lights[1], -1, 0)), 0.5, 1e-6);
    EXPECT_NEAR(table.at_bearing_deg(bearing_to_observer(s.lights[1], 0, -1)), 0.0, 1e-6);
    EXPECT_NEAR(table.at_bearing_deg(bearing_to_observer(s.lights[1], 1, 0)), 0.25, 1e-6);
}

}  // namespace
