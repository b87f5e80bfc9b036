// The scene file's --set overrides: type-checked and located (at --set KEY,
// or at the line of the file that wrote them), by light name and index; and
// templates that make each scene afresh from one parse.
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

}  // namespace
