// The scene file: a full scene parses to hand-derived values (unit conversions
// and defaults), every bad input is an InputError naming the file, line and
// key, --set overrides are type-checked and located, Al. characters expand into
// one light per colour, and chart sector bearings (from seaward) light the
// observers a chart says they light.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "atonlab/display/colour.h"
#include "atonlab/common/input_error.h"
#include "atonlab/stimuli/profile.h"
#include "atonlab/stimuli/rhythm.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/scene_file.h"

using atonlab::InputError;
using namespace atonlab::stimuli;
using namespace atonlab::display;

namespace {

constexpr const char* kFile = "harbour.toml";

const char* const kFullScene = R"(# a harbour entrance at night
[display]
width_px = 1920
height_px = 1080
width_m = 0.598
viewing_distance_m = 0.9

[camera]
position_m = [1.0, 4.0, -2.0]
yaw_deg = 45
pitch_deg = -2.5
roll_deg = 1
fov_deg = 30

[environment]
background = "uniform"
luminance_cd_m2 = 0.01
visibility_nmi = 10
sea_reflectance = 0.03

[eye]
adaptation = "fixed"
glare = "none"

[profiles.vertical.lantern]
elevation_deg = [-90, 0, 90]
relative = [0, 1, 0]

[profiles.horizontal.harbour]
sectors = [{ from_deg = 90, to_deg = 180 }, { from_deg = 180, to_deg = 270, level = 0.5, edge_deg = 2 }]

[[light]]
name = "buoy"
position_m = [0.0, 2.0, -1852.0]
intensity_cd = 250
colour = "red"
rhythm = "Fl(2) 10s"
ramp_s = 0.05
vertical_profile = "lantern"
horizontal_profile = "harbour"
yaw_deg = 90

[[light]]
position_m = [100, 5, -1000]
intensity_cd = 1000.0
xy = [0.3127, 0.3290]
vertical_profile = "sabik-vp"
radius_m = 0.25
rhythm_phase_s = 1.5

[[light]]
name = "pier"
position_m = [0, 3, -500]
intensity_cd = 50
spd = "led-green"
vertical_profile = "lantern"
)";

const char* const kMinimal = R"([display]
width_px = 800
height_px = 600
width_m = 0.4
viewing_distance_m = 0.6
)";

/// 1-based line of the first occurrence of needle (so tests name lines by content).
int line_of(const std::string& text, const std::string& needle) {
    const auto pos = text.find(needle);
    EXPECT_NE(pos, std::string::npos) << needle;
    return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(pos), '\n'));
}

/// The InputError that parsing throws, or a failure.
InputError error_of(const std::string& text, const std::vector<SceneOverride>& overrides = {}) {
    try {
        parse_scene(text, kFile, overrides);
    } catch (const InputError& e) {
        return e;
    }
    ADD_FAILURE() << "no InputError for:\n" << text;
    return InputError("(none)");
}

/// Expects an error at FILE:LINE for KEY whose message contains `words`.
void expect_error_at(const std::string& text, int line, const std::string& key, const std::string& words) {
    const InputError e = error_of(text);
    const std::string what = e.what();
    EXPECT_NE(what.find(std::string(kFile) + ":" + std::to_string(line) + ":"), std::string::npos)
        << "expected line " << line << " in: " << what;
    EXPECT_NE(what.find("key '" + key + "'"), std::string::npos) << "expected key " << key << " in: " << what;
    EXPECT_NE(what.find(words), std::string::npos) << "expected '" << words << "' in: " << what;
    ASSERT_TRUE(e.where().has_value());
    EXPECT_EQ(e.where()->line, line);
    EXPECT_EQ(e.where()->key, key);
}

/// kMinimal plus a light section.
std::string with_light(const std::string& light) {
    return std::string(kMinimal) + "\n[[light]]\n" + light;
}

std::vector<SceneOverride> sets(std::initializer_list<const char*> texts) {
    std::vector<SceneOverride> out;
    for (const char* t : texts) out.push_back(SceneOverride::parse(t));
    return out;
}

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

// ---------------------------------------------------------------------------
// Errors: file, line, key.

TEST(SceneFileErrors, SyntaxErrorGivesTheParserLine) {
    const std::string text = std::string(kMinimal) + "[camera]\nyaw_deg = = 4\n";
    const InputError e = error_of(text);
    EXPECT_EQ(e.where()->line, 7);
    EXPECT_NE(std::string(e.what()).find("harbour.toml:7:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("syntax error"), std::string::npos) << e.what();
}

TEST(SceneFileErrors, MissingRequiredKeyNamesItsTableAndLine) {
    const std::string text = "# display\n\n[display]\nwidth_px = 800\nheight_px = 600\nviewing_distance_m = 0.6\n";
    expect_error_at(text, 3, "display.width_m", "the [display] table (line 3) has no 'width_m'");
    const std::string light = with_light("name = \"buoy\"\nposition_m = [0, 2, -100]\n");
    expect_error_at(light, line_of(light, "[[light]]"), "light[0].intensity_cd",
                    "[[light]] \"buoy\" (light[0]) (line 7) has no 'intensity_cd'");
    const InputError e = error_of("[camera]\nyaw_deg = 3\n");
    EXPECT_NE(std::string(e.what()).find("no [display] table"), std::string::npos) << e.what();
}

TEST(SceneFileErrors, WrongType) {
    std::string text = kMinimal;
    text.replace(text.find("0.4"), 3, "\"wide\"");
    expect_error_at(text, 4, "display.width_m", "expected a number, got a string");
    std::string px = kMinimal;
    px.replace(px.find("800"), 3, "800.5");
    expect_error_at(px, 2, "display.width_px", "expected an integer, got a floating-point number");
    const std::string pos = with_light("position_m = [0, \"two\", 3]\nintensity_cd = 1\n");
    expect_error_at(pos, line_of(pos, "position_m"), "light[0].position_m[1]", "expected a number, got a string");
    const std::string short_pos = with_light("position_m = [0, 2]\nintensity_cd = 1\n");
    expect_error_at(short_pos, line_of(short_pos, "position_m"), "light[0].position_m", "got 2 elements");
}

TEST(SceneFileErrors, UnknownKeyAndUnknownSection) {
    const std::string text = with_light("name = \"buoy\"\nposition_m = [0, 2, -100]\nintensity_cdd = 250\n");
    expect_error_at(text, line_of(text, "intensity_cdd"), "light[0].intensity_cdd", "Did you mean 'intensity_cd'?");
    const std::string section = std::string(kMinimal) + "\n[enviroment]\nluminance_cd_m2 = 1\n";
    expect_error_at(section, line_of(section, "[enviroment]"), "enviroment",
                    "unknown table 'enviroment'. Did you mean 'environment'?");
    const std::string tonemap = std::string(kMinimal) + "\n[tonemap]\noperator = \"sepia\"\n";
    expect_error_at(tonemap, line_of(tonemap, "operator"), "tonemap.operator", "unknown tone-mapping operator");
    const std::string cam = std::string(kMinimal) + "[camera]\nyaw = 4\n";
    expect_error_at(cam, 7, "camera.yaw", "Did you mean 'yaw_deg'?");
}

TEST(SceneFileErrors, UnknownColourName) {
    const std::string text =
        with_light("name = \"buoy\"\nposition_m = [0, 2, -100]\nintensity_cd = 1\ncolour = \"pink\"\n");
    expect_error_at(text, line_of(text, "colour"), "light[0].colour", "unknown colour \"pink\"");
    const std::string spd = with_light("position_m = [0, 2, -100]\nintensity_cd = 1\nspd = \"sodium\"\n");
    expect_error_at(spd, line_of(spd, "spd"), "light[0].spd", "unknown spectrum \"sodium\"");
    const std::string xy = with_light("position_m = [0, 2, -100]\nintensity_cd = 1\nxy = [0.7, 0.5]\n");
    expect_error_at(xy, line_of(xy, "xy"), "light[0].xy", "not a chromaticity");
}

TEST(SceneFileErrors, NegativeNaNAndInfiniteValues) {
    const std::string neg = with_light("name = \"buoy\"\nposition_m = [0, 2, -100]\nintensity_cd = -5\n");
    expect_error_at(neg, line_of(neg, "intensity_cd"), "light[0].intensity_cd",
                    "in light \"buoy\", intensity_cd must be at least 0, got -5");
    const std::string nan = with_light("name = \"buoy\"\nposition_m = [0, 2, -100]\nintensity_cd = nan\n");
    expect_error_at(nan, line_of(nan, "intensity_cd"), "light[0].intensity_cd", "must be a finite number, got nan");
    const std::string inf = with_light("position_m = [0, 2, -100]\nintensity_cd = 1\nradius_m = inf\n");
    expect_error_at(inf, line_of(inf, "radius_m"), "light[0].radius_m", "finite");
    const std::string zero = with_light("position_m = [0, 2, -100]\nintensity_cd = 1\nradius_m = 0\n");
    expect_error_at(zero, line_of(zero, "radius_m"), "light[0].radius_m", "greater than 0");
    const std::string fov = std::string(kMinimal) + "[camera]\nfov_deg = 180\n";
    expect_error_at(fov, 7, "camera.fov_deg", "less than 180");
}

TEST(SceneFileErrors, UnknownRhythm) {
    const std::string text =
        with_light("name = \"buoy\"\nposition_m = [0, 2, -100]\nintensity_cd = 1\nrhythm = \"Blink 3s\"\n");
    expect_error_at(text, line_of(text, "rhythm"), "light[0].rhythm", "invalid rhythm \"Blink 3s\"");
}

TEST(SceneFileErrors, BothColourAndXy) {
    const std::string text =
        with_light("position_m = [0, 2, -100]\nintensity_cd = 1\ncolour = \"red\"\nxy = [0.3, 0.3]\n");
    expect_error_at(text, line_of(text, "xy"), "light[0].xy", "give only one of colour, xy and spd");
}

TEST(SceneFileErrors, DuplicateLightNames) {
    const std::string first = with_light("name = \"buoy\"\nposition_m = [0, 2, -100]\nintensity_cd = 1\n");
    const std::string text = first + "\n[[light]]\nname = \"buoy\"\nposition_m = [5, 2, -100]\nintensity_cd = 1\n";
    const int second_name = line_of(first, "intensity_cd") + 3;  // then a blank line, [[light]], name
    expect_error_at(text, second_name, "light[1].name", "already used by light[0]");
}

TEST(SceneFileErrors, UnknownChoicesSaySo) {
    const std::string adaptation = std::string(kMinimal) + "[eye]\nadaptation = \"sticky\"\n";
    expect_error_at(adaptation, 7, "eye.adaptation", "\"fixed\" or \"dynamic\"");
    const std::string bogus = std::string(kMinimal) + "[eye]\nglare = \"sparkle\"\n";
    expect_error_at(bogus, 7, "eye.glare", "unknown glare model");
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

TEST(SceneFileGlare, ModelsPupilAndTableAreRead) {
    const std::string text = std::string(kMinimal) +
                             "[eye]\nglare = \"spencer\"\npupil_mm = 5.5\n[glare]\nwindow = \"epanechnikov\"\n"
                             "psf_size = 256\nradius_deg = 2.5\nspencer_vision = \"mesopic\"\nclear_pupil = true\nseed = 7\n";
    const Scene scene = parse_scene(text, "glare.toml");
    EXPECT_EQ(scene.glare.model, GlareModel::spencer);
    EXPECT_EQ(scene.glare.pupil_mm, 5.5);
    EXPECT_EQ(scene.glare.window, GlareWindow::epanechnikov);
    EXPECT_EQ(scene.glare.psf_size, 256);
    EXPECT_EQ(scene.glare.radius_deg, 2.5);
    EXPECT_EQ(spencer_vision_for(scene), SpencerVision::mesopic);
    EXPECT_EQ(scene.glare.placement, ComputePlacement::automatic);  // not given
    for (auto [name, want] : {std::pair{"gpu", ComputePlacement::gpu}, std::pair{"cpu", ComputePlacement::cpu},
                              std::pair{"automatic", ComputePlacement::automatic}})
        EXPECT_EQ(parse_scene(std::string(kMinimal) + "[glare]\nplacement = \"" + name + "\"\n", "p.toml").glare.placement,
                  want)
            << name;
    EXPECT_FALSE(scene.glare.eye.gratings.enabled);
    EXPECT_FALSE(scene.glare.eye.halo_radius_deg.has_value());
    EXPECT_EQ(scene.glare.eye.seed, 7u);
    // Every model name round-trips; --set switches glare off.
    for (const char* m : {"none", "wave-optics", "gaussian-bloom", "spencer", "aperture", "cie"})
        EXPECT_EQ(glare_model_name(*glare_model_from_name(m)), m);
}

TEST(SceneFileGlare, EachLightMayGiveItsOwnModel) {
    // Issue 14: [[light]] glare overrides [eye] glare for that light; --set reaches it.
    const std::string text = std::string(kMinimal) +
                             "[eye]\nglare = \"wave-optics\"\n"
                             "[[light]]\nname = \"test\"\nposition_m = [0, 2, -500]\nintensity_cd = 1\n"
                             "[[light]]\nname = \"reference\"\nposition_m = [0, 2, -500]\nintensity_cd = 1\n"
                             "glare = \"none\"\n";
    const Scene s = parse_scene(text, kFile);
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_FALSE(s.lights[0].glare.has_value());
    EXPECT_EQ(light_glare_model(s, s.lights[0]), GlareModel::wave_optics);  // the eye's
    EXPECT_EQ(light_glare_model(s, s.lights[1]), GlareModel::none);         // its own
    EXPECT_TRUE(any_light_glare(s));
    EXPECT_EQ(glare_models_used(s), (std::vector<GlareModel>{GlareModel::wave_optics, GlareModel::none}));
    const Scene set = parse_scene(text, kFile, sets({"light.test.glare=\"cie\"", "light.reference.glare=\"spencer\"",
                                                     "eye.glare=\"none\""}));
    EXPECT_EQ(light_glare_model(set, set.lights[0]), GlareModel::cie);
    EXPECT_EQ(light_glare_model(set, set.lights[1]), GlareModel::spencer);
    EXPECT_EQ(set.glare.model, GlareModel::none);
    EXPECT_EQ(glare_path(GlareModel::none), GlarePath::direct);
    EXPECT_EQ(glare_path(GlareModel::cie), GlarePath::veil);
    EXPECT_EQ(glare_path(GlareModel::spencer), GlarePath::billboard);
    // An unknown model names the light's key and line.
    const std::string bad = with_light("position_m = [0, 2, -100]\nintensity_cd = 1\nglare = \"sparkle\"\n");
    expect_error_at(bad, line_of(bad, "glare = \"sparkle\""), "light[0].glare", "unknown glare model \"sparkle\"");
    // The billboard's width limit holds for a light's own model too (the eye has none).
    // (45° at 126 px per degree: over 11 000 px.)
    const std::string narrow = "[display]\nwidth_px = 800\nheight_px = 600\nwidth_m = 0.1\nviewing_distance_m = 0.9\n"
                               "[glare]\nradius_deg = 45\n";
    const std::string wide =
        narrow + "[[light]]\nposition_m = [0, 2, -100]\nintensity_cd = 1\nglare = \"gaussian-bloom\"\n";
    EXPECT_NE(std::string(error_of(wide).what()).find("the glare billboard is"), std::string::npos);
    EXPECT_NO_THROW(parse_scene(narrow, kFile));
}

TEST(SceneFileGlare, CieModelAndObserverAreRead) {
    const std::string text =
        std::string(kMinimal) + "[eye]\nglare = \"cie\"\ncie_age_years = 62\ncie_pigmentation = 1.0\n";
    const Scene scene = parse_scene(text, "cie.toml");
    EXPECT_EQ(scene.glare.model, GlareModel::cie);
    EXPECT_EQ(cie_observer(scene.glare).age_years, 62.0);
    EXPECT_EQ(cie_observer(scene.glare).pigmentation, 1.0);
    // Defaults: the CIE's 25-year-old, brown eyes (p = 0.5); and --set reaches both keys.
    const Scene plain = parse_scene(std::string(kMinimal), "cie.toml");
    EXPECT_EQ(cie_observer(plain.glare).age_years, 25.0);
    EXPECT_EQ(cie_observer(plain.glare).pigmentation, 0.5);
    const Scene set = parse_scene(text, "cie.toml", sets({"eye.cie_age_years=40", "eye.glare=\"cie\""}));
    EXPECT_EQ(cie_observer(set.glare).age_years, 40.0);
}

TEST(SceneFileGlare, SpectralPathIsRead) {
    EXPECT_EQ(parse_scene(std::string(kMinimal), "s.toml").glare.spectral_path, SpectralPath::anchored);
    const Scene s =
        parse_scene(std::string(kMinimal) + "[glare]\nspectral_path = \"exact\"\nspectral_anchors = 9\n", "s.toml");
    EXPECT_EQ(s.glare.spectral_path, SpectralPath::exact);
    EXPECT_EQ(s.glare.spectral_anchors, 9);
    for (const char* p : {"anchored", "rescaled", "exact"})
        EXPECT_EQ(spectral_path_name(*spectral_path_from_name(p)), p);
    const std::string glare = std::string(kMinimal) + "[glare]\n";
    expect_error_at(glare + "spectral_path = \"fast\"\n", 7, "glare.spectral_path", "unknown spectral path");
    expect_error_at(glare + "spectral_anchors = 0\n", 7, "glare.spectral_anchors", "between");
}

TEST(SceneFileGlare, BadCieObserverNamesFileLineAndKey) {
    const std::string eye = std::string(kMinimal) + "[eye]\nglare = \"cie\"\n";
    expect_error_at(eye + "cie_age_years = -3\n", 8, "eye.cie_age_years", "between 0 and 100");
    expect_error_at(eye + "cie_pigmentation = 2\n", 8, "eye.cie_pigmentation", "between 0 and 1.2");
    // Each within range, together beyond what a positive GSF can conserve.
    expect_error_at(eye + "cie_age_years = 100\ncie_pigmentation = 1.2\n", 8, "eye.cie_age_years",
                    "more than all of it");
    const InputError e = error_of(std::string(kMinimal), sets({"eye.cie_age_years=-1"}));
    EXPECT_EQ(e.where()->option, "--set");
    EXPECT_EQ(e.where()->key, "eye.cie_age_years");
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

TEST(SceneFileGlare, BadGlareInputNamesTheKey) {
    const std::string eye = std::string(kMinimal) + "[eye]\n";
    expect_error_at(eye + "pupil_mm = 0\n", 7, "eye.pupil_mm", "greater than 0");
    expect_error_at(eye + "pupil_mm = -3\n", 7, "eye.pupil_mm", "greater than 0");
    const std::string glare = std::string(kMinimal) + "[glare]\n";
    expect_error_at(glare + "psf_size = 300\n", 7, "glare.psf_size", "power of two");
    expect_error_at(glare + "window = \"box\"\n", 7, "glare.window", "unknown glare window");
    expect_error_at(glare + "placement = \"tpu\"\n", 7, "glare.placement", "\"automatic\", \"gpu\" or \"cpu\"");
    expect_error_at(glare + "spencer_vision = \"owl\"\n", 7, "glare.spencer_vision", "unknown vision");
    expect_error_at(glare + "aperture_image = \"no-such-lashes.png\"\n", 7, "glare.aperture_image", "does not exist");
    expect_error_at(glare + "grating_count = -1\n", 7, "glare.grating_count", "between");
    // The old key names the new one; a defocus the grid cannot sample says why, at its line.
    expect_error_at(glare + "fresnel_distance_mm = 24\n", 7, "glare.fresnel_distance_mm", "defocus_diopters");
    expect_error_at(glare + "defocus_diopters = -30\n", 7, "glare.defocus_diopters", "more than π between texels");
    expect_error_at(glare + "eye_preset = \"k2013\"\n", 7, "glare.eye_preset", "unknown eye preset");
    // The limit is the scene's pupil's: λ0 N / (p W) = 2.04 D at 8 mm and N = 512, 4.09 D at 4 mm.
    const std::string three_d = "[glare]\ndefocus_diopters = 3\n";
    expect_error_at(std::string(kMinimal) + "[eye]\npupil_mm = 8\n" + three_d, 9, "glare.defocus_diopters",
                    "at most ±2.04 D");
    EXPECT_DOUBLE_EQ(parse_scene(std::string(kMinimal) + "[eye]\npupil_mm = 4\n" + three_d, kFile)
                         .glare.eye.defocus_diopters,
                     3.0);
    const Scene k2012 = parse_scene(glare + "eye_preset = \"k2012\"\nseed = 7\n", kFile);
    EXPECT_EQ(k2012.glare.eye.scale, EyeScale::k2012_single);
    EXPECT_DOUBLE_EQ(k2012.glare.eye.defocus_diopters, 0.2);
    EXPECT_EQ(k2012.glare.eye.seed, 7u);  // the preset first, then the keys
    expect_error_at(glare + "sparkle = 1\n", 7, "glare.sparkle", "unknown key");
}

TEST(SceneFileErrors, ConflictsAndShapes) {
    const std::string fog = std::string(kMinimal) + "[environment]\nvisibility_nmi = 5\nextinction_per_km = 1\n";
    expect_error_at(fog, 8, "environment.extinction_per_km", "not both");
    const std::string single = std::string(kMinimal) + "[light]\nposition_m = [0, 0, 0]\n";
    expect_error_at(single, 6, "light", "write [[light]], not [light]");
    const std::string al =
        with_light("position_m = [0, 2, -100]\nintensity_cd = 1\ncolour = \"red\"\nrhythm = \"Al.WR 4s\"\n");
    expect_error_at(al, line_of(al, "colour"), "light[0].colour", "gives the colours itself");
    const std::string profile =
        with_light("position_m = [0, 2, -100]\nintensity_cd = 1\nvertical_profile = \"nope\"\n");
    expect_error_at(profile, line_of(profile, "vertical_profile"), "light[0].vertical_profile",
                    "unknown vertical profile \"nope\"");
    const std::string unsorted =
        std::string(kMinimal) + "[profiles.vertical.x]\nelevation_deg = [0, -10, 20]\nrelative = [1, 1, 1]\n";
    expect_error_at(unsorted, 7, "profiles.vertical.x.elevation_deg[1]", "sorted in increasing order");
    const std::string lengths =
        std::string(kMinimal) + "[profiles.vertical.x]\nelevation_deg = [0, 10]\nrelative = [1, 1, 1]\n";
    expect_error_at(lengths, 8, "profiles.vertical.x.relative", "same length");
    const std::string builtin = std::string(kMinimal) + "[profiles.vertical.uniform]\nelevation_deg = [0, 10]\n";
    expect_error_at(builtin, 6, "profiles.vertical.uniform", "builtin");
    const std::string sector = with_light(
        "position_m = [0, 2, -100]\nintensity_cd = 1\n"
        "sectors = [{ from_deg = 10, to_deg = 20 }, { from_deg = 400, to_deg = 20 }]\n");
    expect_error_at(sector, line_of(sector, "sectors"), "light[0].sectors[1].from_deg", "between 0 and 360");
    const std::string both = with_light(
        "position_m = [0, 2, -100]\nintensity_cd = 1\nhorizontal_profile = \"uniform\"\n"
        "sectors = [{ from_deg = 10, to_deg = 20 }]\n");
    expect_error_at(both, line_of(both, "sectors"), "light[0].sectors", "not both");
}

// ---------------------------------------------------------------------------
// Overrides.

TEST(SceneOverrides, ParseSplitsAtTheFirstEquals) {
    const SceneOverride o = SceneOverride::parse("light.buoy.rhythm=Fl(2) 10s");
    EXPECT_EQ(o.key, "light.buoy.rhythm");
    EXPECT_EQ(o.value, "Fl(2) 10s");
    const SceneOverride p = SceneOverride::parse("a.b==c");
    EXPECT_EQ(p.key, "a.b");
    EXPECT_EQ(p.value, "=c");
    EXPECT_THROW(SceneOverride::parse("camera.yaw_deg"), InputError);
    EXPECT_THROW(SceneOverride::parse("=4"), InputError);
}

TEST(SceneOverrides, ChangeValues) {
    const Scene s = parse_scene(kFullScene, kFile,
                                sets({"camera.yaw_deg=90", "display.width_px=800", "camera.position_m=[0, 10, 5]",
                                      "environment.background=\"sky-sea\"", "eye.adaptation_cd_m2=0.5"}));
    EXPECT_EQ(s.camera.yaw_deg, 90.0);
    EXPECT_EQ(s.display.width_px, 800);
    EXPECT_EQ(s.camera.position_m, glm::dvec3(0, 10, 5));
    EXPECT_EQ(s.environment.background, Background::sky_sea);
    EXPECT_EQ(s.adaptation_cd_m2, 0.5);
    // Later overrides win; a float may replace an integer and vice versa.
    const Scene t =
        parse_scene(kFullScene, kFile, sets({"camera.yaw_deg=10", "camera.yaw_deg=12.5", "camera.pitch_deg=3"}));
    EXPECT_EQ(t.camera.yaw_deg, 12.5);
    EXPECT_EQ(t.camera.pitch_deg, 3.0);
}

TEST(SceneOverrides, AddKeysAndTablesTheFileLeavesOut) {
    const Scene s = parse_scene(kMinimal, kFile, sets({"environment.visibility_nmi=10", "camera.fov_deg=20"}));
    EXPECT_NEAR(s.environment.extinction_per_m, 2.995732273553991 / 18520.0, 1e-15);
    EXPECT_EQ(*s.camera.fov_y_deg, 20.0);
}

TEST(SceneOverrides, WrongTypeIsRejected) {
    const InputError e = error_of(kFullScene, sets({"camera.yaw_deg=\"north\""}));
    ASSERT_TRUE(e.where().has_value());
    EXPECT_EQ(e.where()->option, "--set");
    EXPECT_EQ(e.where()->key, "camera.yaw_deg");
    const std::string what = e.what();
    EXPECT_NE(what.find("expected a number like the value it replaces (harbour.toml:10), got a string"),
              std::string::npos)
        << what;
    // A bare word is read as a string, and the message says so.
    const InputError bare = error_of(kFullScene, sets({"display.width_px=wide"}));
    EXPECT_NE(std::string(bare.what()).find("not valid TOML"), std::string::npos) << bare.what();
}

TEST(SceneOverrides, ByLightNameAndIndex) {
    const Scene s = parse_scene(kFullScene, kFile,
                                sets({"light.buoy.intensity_cd=500", "light[1].intensity_cd=7",
                                      "light.light1.radius_m=0.5", "light.pier.colour=green"}));
    EXPECT_EQ(s.lights[0].intensity_cd, 500.0);
    EXPECT_EQ(s.lights[1].intensity_cd, 7.0);
    EXPECT_EQ(s.lights[1].radius_m, 0.5);
    // colour replaces the file's spd (they exclude each other), and a bare word is a string.
    EXPECT_EQ(s.lights[2].rgb_per_cd, *iala_colour_rgb("green"));
    // A name with dots is found whole.
    const Scene d = parse_scene(with_light("name = \"a.b\"\nposition_m = [0, 0, 0]\nintensity_cd = 1\n"), kFile,
                                sets({"light.a.b.intensity_cd=3"}));
    EXPECT_EQ(d.lights[0].intensity_cd, 3.0);
}

TEST(SceneOverrides, UnknownKeysAreRejectedNamingSet) {
    for (const char* bad : {"camera.yaw=4", "foo.bar=1", "light.buoy.colr=\"red\"", "light.nobody.intensity_cd=1",
                            "light[9].intensity_cd=1", "profiles.vertical.lantern.relativ=[1, 1]", "camera=4"}) {
        const InputError e = error_of(kFullScene, sets({bad}));
        ASSERT_TRUE(e.where().has_value()) << bad;
        EXPECT_EQ(e.where()->option, "--set") << bad;
        EXPECT_TRUE(std::string(e.what()).starts_with("--set: key '")) << e.what();
    }
    const InputError e = error_of(kFullScene, sets({"camera.yaw=4"}));
    EXPECT_NE(std::string(e.what()).find("Did you mean 'yaw_deg'?"), std::string::npos) << e.what();
}

TEST(SceneOverrides, ValidationErrorsPointAtTheOverride) {
    const InputError e = error_of(kFullScene, sets({"light.buoy.intensity_cd=-1"}));
    EXPECT_EQ(std::string(e.what()),
              "--set: key 'light.buoy.intensity_cd': in light \"buoy\", intensity_cd must be at least 0, got -1.");
    const InputError s =
        error_of(kFullScene, sets({"light.buoy.horizontal_profile=\"uniform\"",
                                   "light.buoy.sectors=[{from_deg = 10, to_deg = 20}, {from_deg = 1}]"}));
    EXPECT_EQ(s.where()->option, "--set");
    EXPECT_EQ(s.where()->key, "light.buoy.sectors[1].to_deg") << s.what();
    const InputError r = error_of(kFullScene, sets({"light[2].rhythm=Blink"}));
    EXPECT_EQ(r.where()->key, "light[2].rhythm");
    EXPECT_NE(std::string(r.what()).find("invalid rhythm \"Blink\""), std::string::npos) << r.what();
}

TEST(SceneOverrides, SetsProfileTables) {
    const Scene s = parse_scene(kFullScene, kFile, sets({"profiles.vertical.lantern.relative=[1, 1, 1]"}));
    EXPECT_NEAR(s.profiles.vertical[s.lights[0].vertical_profile].at_cos_theta(1.0), 1.0, 1e-6);
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

// ---------------------------------------------------------------------------
// Every error at once.

TEST(SceneFileErrors, ErrorsInSeveralTablesAreAllReportedInFileOrder) {
    const std::string text = std::string(kMinimal) + R"(
[camera]
fov_dge = 30

[environment]
luminance_cd_m2 = "dark"

[[light]]
name = "a"
position_m = [0.0, 0.0, -500.0]
intensity_cd = -1

[[light]]
name = "b"
position_m = [0.0, 0.0]
intensity_cd = 10
)";
    const InputError e = error_of(text);
    ASSERT_TRUE(e.where().has_value());
    EXPECT_EQ(e.where()->line, line_of(text, "fov_dge"));
    EXPECT_EQ(e.where()->key, "camera.fov_dge");
    ASSERT_EQ(e.further().size(), 3u) << e.what();
    const std::vector<std::string> at = {":" + std::to_string(line_of(text, "luminance_cd_m2 = \"dark\"")) + ":",
                                         ":" + std::to_string(line_of(text, "intensity_cd = -1")) + ":",
                                         ":" + std::to_string(line_of(text, "position_m = [0.0, 0.0]")) + ":"};
    for (std::size_t i = 0; i < at.size(); ++i)
        EXPECT_NE(e.further()[i].find(std::string(kFile) + at[i]), std::string::npos) << e.further()[i];
    // what() is every line: the first, then the others.
    const std::string all = e.what();
    EXPECT_EQ(std::count(all.begin(), all.end(), '\n'), 3) << all;
}

// A template makes each scene afresh: overrides never leak into the next
// instantiation, and errors keep the template's own lines.
TEST(SceneTemplate, EachInstantiationStartsFromTheFileAndKeepsItsLines) {
    const SceneTemplate t = SceneTemplate::parse(kFullScene, kFile);
    const Scene brighter = t.instantiate({SceneOverride::parse("light.buoy.intensity_cd=400")});
    EXPECT_EQ(brighter.lights[0].intensity_cd, 400.0);
    const Scene plain = t.instantiate();
    EXPECT_EQ(plain.lights[0].intensity_cd, 250.0);  // the file's value, as written
    EXPECT_EQ(plain.lights[1].intensity_cd, 1000.0);

    // An override that makes a value of the file wrong elsewhere: the error
    // names the file's line, which the copy kept.
    const std::string bad = std::string(kMinimal) + "\n[eye]\npupil_mm = -1\n";
    const SceneTemplate tb = SceneTemplate::parse(bad, kFile);
    try {
        (void)tb.instantiate({SceneOverride::parse("camera.yaw_deg=10")});
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        ASSERT_TRUE(e.where());
        EXPECT_EQ(e.where()->file, kFile);
        EXPECT_EQ(e.where()->line, line_of(bad, "pupil_mm = -1")) << e.what();
        EXPECT_EQ(e.where()->key, "eye.pupil_mm") << e.what();
    }
}

// The template is parsed once and every scene is made from its one tree: the
// overrides' changes (a value replaced, a key of an exclusive group erased, a
// table made) are undone after each scene, made or refused, and the restored
// values keep the file's lines.
TEST(SceneTemplate, OverridesAreUndoneAndTheRestoredValuesKeepTheirLines) {
    const SceneTemplate t = SceneTemplate::parse(kFullScene, kFile);
    const Scene fresh = parse_scene(kFullScene, kFile);  // a second, independent parse

    const Scene changed = t.instantiate(sets({"light.buoy.xy=[0.3, 0.3]",  // erases colour
                                              "light[1].colour=\"green\"",  // erases xy
                                              "profiles.vertical.extra.elevation_deg=[-90, 90]",  // new tables
                                              "profiles.vertical.extra.relative=[1, 1]",
                                              "light.buoy.vertical_profile=\"extra\"", "eye.pupil_mm=3"}));
    EXPECT_NE(changed.lights[0].rgb_per_cd, fresh.lights[0].rgb_per_cd);
    EXPECT_NE(changed.lights[1].rgb_per_cd, fresh.lights[1].rgb_per_cd);
    EXPECT_EQ(changed.glare.pupil_mm, 3.0);

    const Scene plain = t.instantiate();
    ASSERT_EQ(plain.lights.size(), fresh.lights.size());
    for (std::size_t i = 0; i < fresh.lights.size(); ++i) {
        EXPECT_EQ(plain.lights[i].rgb_per_cd, fresh.lights[i].rgb_per_cd) << i;
        EXPECT_EQ(plain.lights[i].vertical_profile, fresh.lights[i].vertical_profile) << i;
    }
    EXPECT_EQ(plain.profiles.vertical.size(), fresh.profiles.vertical.size());
    EXPECT_FALSE(plain.glare.pupil_mm.has_value());

    // The erased and restored values are the file's nodes, with their lines.
    const auto replaced_at = [&](const char* set, const char* written) {
        try {
            (void)t.instantiate(sets({set}));
            ADD_FAILURE() << "no InputError for " << set;
        } catch (const InputError& e) {
            const std::string at = std::string(kFile) + ":" + std::to_string(line_of(kFullScene, written));
            EXPECT_NE(std::string(e.what()).find("like the value it replaces (" + at + ")"), std::string::npos)
                << e.what();
        }
    };
    replaced_at("light.buoy.colour=5", "colour = \"red\"");
    replaced_at("light[1].xy=\"white\"", "xy = [0.3127, 0.3290]");

    // A refused override list leaves the tree as the file has it too.
    EXPECT_THROW((void)t.instantiate(sets({"profiles.vertical.more.relative=[1]",
                                           "light.buoy.vertical_profile=\"more\"", "camera.nope=1"})),
                 InputError);
    const Scene after_error = t.instantiate();
    EXPECT_EQ(after_error.profiles.vertical.size(), fresh.profiles.vertical.size());
    EXPECT_EQ(after_error.lights[0].vertical_profile, fresh.lights[0].vertical_profile);
}

// An override carries where it was written: a value a protocol's line gave is
// named at that line, whether the override itself is refused or the value it
// gave is refused later by the schema. The command line's is "--set KEY".
TEST(SceneOverrides, AnOverrideWrittenInAFileIsNamedAtItsLine) {
    const atonlab::SourceLocation study{"study.toml", 12, 7, "block[0].condition[0].set[0]"};
    const auto at_study = [&](const char* key, const char* value) { return SceneOverride{key, value, study}; };
    for (const SceneOverride& o : {at_study("eye.glaer", "\"none\""), at_study("camera.fov_deg", "-5"),
                                   at_study("camera.fov_deg", "\"wide\"")}) {
        const InputError e = error_of(kMinimal, {o});
        ASSERT_TRUE(e.where()) << e.what();
        EXPECT_EQ(e.where()->file, "study.toml") << e.what();
        EXPECT_EQ(e.where()->line, 12) << e.what();
        EXPECT_EQ(e.where()->column, 7) << e.what();
        EXPECT_EQ(e.where()->key, o.key) << e.what();
        EXPECT_FALSE(e.where()->from_command_line()) << e.what();
        EXPECT_EQ(std::string(e.what()).rfind("study.toml:12: key '" + o.key + "'", 0), 0u) << e.what();
    }
    const InputError cli = error_of(kMinimal, sets({"camera.fov_deg=-5"}));
    ASSERT_TRUE(cli.where());
    EXPECT_EQ(cli.where()->option, "--set");
    EXPECT_EQ(cli.where()->key, "camera.fov_deg");
}

// Every unknown key of one table is reported in one run, not only the first.
TEST(SceneFileErrors, EveryUnknownKeyOfATableIsReported) {
    const std::string text = std::string(kMinimal) + "brightness = 1\ncontrast = 2\n";
    try {
        (void)parse_scene(text, kFile);
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        ASSERT_TRUE(e.where());
        EXPECT_EQ(e.where()->key, "display.brightness") << e.what();
        ASSERT_EQ(e.further().size(), 1u) << e.what();
        EXPECT_NE(e.further()[0].find("key 'display.contrast'"), std::string::npos) << e.what();
        EXPECT_NE(e.further()[0].find(":" + std::to_string(line_of(text, "contrast")) + ":"), std::string::npos)
            << e.what();
    }
}
