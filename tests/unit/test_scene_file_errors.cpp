// The scene file's errors: every bad input is an InputError naming the file,
// the line and the key, and every error of a file is reported at once, in
// file order.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/stimuli/scene_file.h"
#include "scene_file_test_support.h"

using atonlab::InputError;
using namespace atonlab::stimuli;
using namespace atonlab::display;
using namespace atonlab::stimuli::scene_file_test;  // NOLINT: the shared scenes and readers

namespace {

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

TEST(SceneFileErrors, UnknownSkySpectrumNamesTheKey) {
    const std::string text = std::string(kMinimal) + "\n[environment]\nluminance_cd_m2 = 0.01\nspd = \"sodium\"\n";
    expect_error_at(text, line_of(text, "spd"), "environment.spd", "unknown spectrum \"sodium\" for the sky");
    // The override names --set instead of a line.
    EXPECT_THROW(parse_scene(kMinimal, "harbour.toml", sets({"environment.spd=\"led-purple\""})), InputError);
}

TEST(SceneFileErrors, TheDisplaysOldKeyTransferIsReadAsEncodingWithANote) {
    const std::string old = std::string(kMinimal) + "peak_cd_m2 = 1000\ntransfer = \"pq\"\n";
    testing::internal::CaptureStderr();
    const Scene s = parse_scene(old, "harbour.toml");
    const std::string said = testing::internal::GetCapturedStderr();
    EXPECT_EQ(s.output.display.name, "PQ");
    EXPECT_EQ(s.output.display.peak_cd_m2, 1000.0);
    // The note is said once per process: here, or by an earlier test in the same process.
    if (!said.empty()) {
        EXPECT_EQ(said, "harbour.toml:" + std::to_string(line_of(old, "transfer")) +
                            ": note: [display] transfer is deprecated; write encoding\n");
    }
    EXPECT_EQ(atonlab::note_deprecated({}, "[display] transfer", "encoding"), "") << "the scene reader said no note";
    // The new key, and the two together.
    EXPECT_EQ(parse_scene(std::string(kMinimal) + "encoding = \"pq\"\n", "harbour.toml").output.display.name, "PQ");
    const std::string both = std::string(kMinimal) + "encoding = \"pq\"\ntransfer = \"pq\"\n";
    expect_error_at(both, line_of(both, "transfer"), "display.transfer", "give encoding alone");
    const std::string unknown = std::string(kMinimal) + "encoding = \"hlg\"\n";
    expect_error_at(unknown, line_of(unknown, "encoding"), "display.encoding", "unknown encoding \"hlg\"");
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

}  // namespace
