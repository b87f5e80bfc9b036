// The scene file's [[disc]] (scene.h Disc, docs/scene-file.md "[[disc]]"): a
// disc parses to its values, its colour keys are a light's, --set reaches it by
// name, and every bad input is an InputError naming the file, line and key.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/scene_file.h"

using atonlab::InputError;
using namespace atonlab::stimuli;
using namespace atonlab::display;

namespace {

constexpr const char* kFile = "suzuki.toml";

const std::string kScene = R"([display]
width_px = 800
height_px = 600
width_m = 0.4
viewing_distance_m = 0.6

[[light]]
name = "test"
position_m = [-1.0, 0.0, -10.0]
intensity_cd = 5.0

[[disc]]
name = "reference"
position_m = [1.0, 0.0, -10.0]
diameter_deg = 1.5
luminance_cd_m2 = 12.5
colour = "red"
)";

InputError error_of(const std::string& text, const std::vector<SceneOverride>& overrides = {}) {
    try {
        parse_scene(text, kFile, overrides);
    } catch (const InputError& e) {
        return e;
    }
    ADD_FAILURE() << "no InputError for:\n" << text;
    return InputError("(none)");
}

/// kScene with one of the disc's lines replaced.
std::string with(const std::string& from, const std::string& to) {
    std::string s = kScene;
    const auto pos = s.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    return s.replace(pos, from.size(), to);
}

void expect_error_at(const std::string& text, int line, const std::string& key, const std::string& words) {
    const InputError e = error_of(text);
    const std::string what = e.what();
    EXPECT_NE(what.find(std::string(kFile) + ":" + std::to_string(line) + ":"), std::string::npos) << what;
    EXPECT_NE(what.find("key '" + key + "'"), std::string::npos) << what;
    EXPECT_NE(what.find(words), std::string::npos) << "expected '" << words << "' in: " << what;
}

TEST(SceneDisc, ParsesToItsValues) {
    const Scene s = parse_scene(kScene, kFile);
    ASSERT_EQ(s.discs.size(), 1u);
    const Disc& d = s.discs[0];
    EXPECT_EQ(d.name, "reference");
    EXPECT_EQ(d.position_m, glm::dvec3(1.0, 0.0, -10.0));
    EXPECT_DOUBLE_EQ(d.diameter_deg, 1.5);
    EXPECT_DOUBLE_EQ(d.luminance_cd_m2, 12.5);
    EXPECT_EQ(d.rgb_per_cd_m2, *iala_colour_rgb("red"));
    EXPECT_NEAR(luminance_of_linear_rgb(d.rgb_per_cd_m2), 1.0, 1e-12);  // normalised to Y = 1
    ASSERT_EQ(s.lights.size(), 1u);  // a disc is not a light
}

TEST(SceneDisc, ColourByXyAndDefaultWhite) {
    const Scene xy = parse_scene(with("colour = \"red\"", "xy = [0.3127, 0.3290]"), kFile);
    EXPECT_NEAR(luminance_of_linear_rgb(xy.discs[0].rgb_per_cd_m2), 1.0, 1e-9);
    const Scene white = parse_scene(with("colour = \"red\"\n", ""), kFile);
    EXPECT_EQ(white.discs[0].rgb_per_cd_m2, *iala_colour_rgb("white"));
}

TEST(SceneDisc, OverridesReachADiscByNameAndIndex) {
    const Scene s = parse_scene(kScene, kFile,
                                {SceneOverride::parse("disc.reference.luminance_cd_m2=3.25"),
                                 SceneOverride::parse("disc[0].diameter_deg=0"),
                                 SceneOverride::parse("disc.reference.position_m=[0.5, 0.0, -10.0]"),
                                 SceneOverride::parse("disc.reference.xy=[0.3127, 0.3290]")});
    EXPECT_DOUBLE_EQ(s.discs[0].luminance_cd_m2, 3.25);
    EXPECT_DOUBLE_EQ(s.discs[0].diameter_deg, 0.0);
    EXPECT_EQ(s.discs[0].position_m, glm::dvec3(0.5, 0.0, -10.0));
    EXPECT_NE(s.discs[0].rgb_per_cd_m2, *iala_colour_rgb("red"));  // xy replaced colour
}

TEST(SceneDisc, BadOverridesNameTheKey) {
    const std::string unknown_name =
        error_of(kScene, {SceneOverride::parse("disc.nope.luminance_cd_m2=1")}).what();
    EXPECT_NE(unknown_name.find("no disc is named \"nope\"; the discs are \"reference\""), std::string::npos)
        << unknown_name;
    const std::string unknown_key = error_of(kScene, {SceneOverride::parse("disc.reference.intensity_cd=1")}).what();
    EXPECT_NE(unknown_key.find("unknown key 'intensity_cd' in [[disc]]"), std::string::npos) << unknown_key;
    const std::string negative = error_of(kScene, {SceneOverride::parse("disc.reference.diameter_deg=-2")}).what();
    EXPECT_NE(negative.find("--set: key 'disc.reference.diameter_deg'"), std::string::npos) << negative;
}

TEST(SceneDisc, NegativeDiameterIsRefusedAtItsLine) {
    expect_error_at(with("diameter_deg = 1.5", "diameter_deg = -1.5"), 15, "disc[0].diameter_deg",
                    "diameter_deg must be between 0 and 90, got -1.5");
}

TEST(SceneDisc, NonFiniteLuminanceIsRefusedAtItsLine) {
    expect_error_at(with("luminance_cd_m2 = 12.5", "luminance_cd_m2 = inf"), 16, "disc[0].luminance_cd_m2",
                    "luminance_cd_m2 must be a finite number, got inf");
    expect_error_at(with("luminance_cd_m2 = 12.5", "luminance_cd_m2 = nan"), 16, "disc[0].luminance_cd_m2",
                    "must be a finite number");
    expect_error_at(with("luminance_cd_m2 = 12.5", "luminance_cd_m2 = -1"), 16, "disc[0].luminance_cd_m2",
                    "luminance_cd_m2 must be at least 0, got -1");
}

TEST(SceneDisc, UnknownColourIsRefusedAtItsLine) {
    expect_error_at(with("colour = \"red\"", "colour = \"pink\""), 17, "disc[0].colour",
                    "in disc \"reference\", unknown colour \"pink\"");
}

TEST(SceneDisc, MissingKeysAndNameClashes) {
    expect_error_at(with("luminance_cd_m2 = 12.5\n", ""), 12, "disc[0].luminance_cd_m2", "has no 'luminance_cd_m2'");
    expect_error_at(with("name = \"reference\"", "name = \"test\""), 13, "disc[0].name",
                    "the name \"test\" is already used by light[0]");
    expect_error_at(with("colour = \"red\"", "brightness = 2"), 17, "disc[0].brightness", "unknown key 'brightness'");
}

}  // namespace
