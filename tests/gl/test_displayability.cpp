// The displayability check (atonlab/runner/displayability.h; docs/running.md,
// "Displayability"):
//  - every example protocol (protocols/examples/*.toml) can produce a match at
//    1920×1080 px on 0.598 m, 3840×2160 px on 0.60 m and 1280×720 px on 0.30 m,
//    each at the protocol's viewing distance (issue 14 item 6);
//  - a light far too dim for its display (1e-7 cd at 500 m on 320 × 180 px:
//    3e-6 cd/m² over one pixel, 0.3 % of the 0.001 cd/m² background, less than
//    one 8-bit step at any code) changes no code of its frame, so it adds
//    exactly 0 lx over the lights-off frame of the same dither: R1 refuses it,
//    and the display's resolution there (one code step over the background's
//    codes, times the pixel's solid angle) is the sRGB decoding's, worked out
//    here independently;
//  - a white reference whose lowest level already puts more light into the eye
//    than the (white, same place) test is refused under R4, saying to lower
//    min_level; the level where the two are equal, interpolated between the
//    ends, lies near log10 of the test's intensity (the analytic match); with
//    the bound moved as said, the condition passes;
//  - a good condition passes, its interpolated equal level near the same;
//  - `atonlab run` refuses a protocol whose test light adds nothing, or whose
//    range does not straddle the test (exit 2, one sentence naming the
//    condition's line) before any trial, and creates no study file; with
//    --allow-undisplayable it runs and records the flag in the session
//    (sessions.displayability_json), and `atonlab analyze` says so;
//  - `atonlab check` prints the table and exits 0 or 2, writing nothing;
//  - a clipped, out-of-gamut light's shares reach `atonlab analyze`: summary.json's
//    largest shares equal those check computes for the same condition, judged by
//    the protocol's own display.max_out_of_gamut_loss, and the note gives the share.
// The binary's tests skip where it finds no GL 4.5 context (exit status 3).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <ostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "../store/store_test_support.h"
#include "../support/child_process.h"
#include "../support/skip.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/runner/displayability.h"
#include "atonlab/runner/session/run_session.h"
#include "atonlab/store/json.h"
#include "atonlab/store/store.h"
#include "gl_test_support.h"
#include "text_contains.h"

#ifndef ATONLAB_BINARY
#error "ATONLAB_BINARY (the atonlab executable) must be defined by the build"
#endif

namespace atonlab {
namespace {

namespace fs = std::filesystem;
namespace p = atonlab::protocols;
using runner::Displayability;
using store::test_support::file_bytes;
using store::test_support::TempDir;

const fs::path kSource(ATONLAB_SOURCE_DIR);
const fs::path kUndisplayable = kSource / "tests/data/run/undisplayable_2afc.toml";

std::vector<fs::path> example_protocols() {
    std::vector<fs::path> out;
    for (const auto& e : fs::directory_iterator(kSource / "protocols/examples")) {
        const std::string name = e.path().filename().string();
        if (e.path().extension() == ".toml" && name.find(".scene.") == std::string::npos) out.push_back(e.path());
    }
    std::sort(out.begin(), out.end());
    return out;
}

Displayability check(const fs::path& file, int width_px, int height_px, double width_m) {
    p::Protocol protocol = p::load_protocol(file.string());
    protocol.display.width_px = width_px;
    protocol.display.height_px = height_px;
    protocol.display.width_m = width_m;
    const p::ModelObserverParams params{};
    runner::StimulusRenderer renderer(
        stimuli::SceneTemplate::parse(file_bytes(protocol.scene), protocol.scene.string()), params.window_radius_deg,
        protocol.timing.stimulus_s);
    return runner::check_displayability(renderer, protocol);
}

/// A copy of `from` in `dir` named `name`, each `replace` pair's first text
/// (which must be there) replaced by its second, and its scene named by its
/// absolute path (the copy is not beside the scene).
fs::path variant(const fs::path& dir, const std::string& name, const fs::path& from,
                 const std::vector<std::pair<std::string, std::string>>& replace) {
    std::string text = file_bytes(from);
    const std::string scene = "scene = \"small.scene.toml\"";
    std::vector<std::pair<std::string, std::string>> all = replace;
    all.emplace_back(scene, "scene = \"" + (kSource / "tests/data/run/small.scene.toml").string() + "\"");
    for (const auto& [a, b] : all) {
        const std::size_t at = text.find(a);
        if (at == std::string::npos) throw std::runtime_error("variant: no \"" + a + "\" in " + from.string());
        text.replace(at, a.size(), b);
    }
    const fs::path out = dir / name;
    std::FILE* f = std::fopen(out.c_str(), "wb");
    if (!f) throw std::runtime_error("cannot write " + out.string());
    std::fwrite(text.data(), 1, text.size(), f);
    std::fclose(f);
    return out;
}

/// Protocol-file values the tests below change in undisplayable_2afc.toml.
const std::string kTestIntensity = "light.test.intensity_cd=1e-7";
const std::string kMinLevel = "min_level = -4.0";

struct DisplayCase {
    const char* name;
    int width_px, height_px;
    double width_m;
};

// Issue 14 item 6: the three displays every example must suit.
const DisplayCase kDisplays[] = {{"hd", 1920, 1080, 0.598}, {"uhd", 3840, 2160, 0.60}, {"small", 1280, 720, 0.30}};

/// One example at one display, its own CTest (GL.Displayability/Examples.Check/NAME_DISPLAY), so
/// that they run in parallel and a 4K one does not hold up the rest.
struct ExampleAtDisplay {
    fs::path protocol;
    DisplayCase display;
};

/// What CTest's name shows after "# GetParam() = " (gtest_discover_tests appends it).
void PrintTo(const ExampleAtDisplay& e, std::ostream* os) {
    *os << e.protocol.filename().string() << " at " << e.display.width_px << "x" << e.display.height_px;
}

std::vector<ExampleAtDisplay> examples_at_displays() {
    std::vector<ExampleAtDisplay> out;
    for (const fs::path& f : example_protocols())
        for (const DisplayCase& d : kDisplays) out.push_back({f, d});
    return out;
}

class Examples : public ::testing::TestWithParam<ExampleAtDisplay> {};

TEST(Displayability, ThereAreExamples) {
    EXPECT_GE(example_protocols().size(), 4u);
}

// The long form (docs/running.md, "Displayability"): every example at three
// displays renders hundreds of full frames, 1–13 min per case on llvmpipe, so
// the suite runs it only with ATONLAB_LONG_TESTS=1. The short form in the
// suite: `atonlab run` checks every example at its own display before the
// first trial (GL.ExampleConvergence.*, the main job), and the README's quick
// start runs `atonlab check`.
TEST_P(Examples, Check) {
    if (const char* on = std::getenv("ATONLAB_LONG_TESTS"); on == nullptr || std::string(on) != "1")
        ATONLAB_SKIP_NOT_APPLICABLE() << "long form: set ATONLAB_LONG_TESTS=1 to check every example at three displays";
    if (!test::gl_context()) ATONLAB_SKIP_NO_GPU() << test::gl_unavailable_reason();
    const fs::path& file = GetParam().protocol;
    const DisplayCase& d = GetParam().display;
    const Displayability r = check(file, d.width_px, d.height_px, d.width_m);
    std::printf("%s at %dx%d px, %.3g m:\n%s", file.filename().string().c_str(), d.width_px, d.height_px, d.width_m,
                runner::displayability_table(r).c_str());
    EXPECT_TRUE(r.displayable()) << runner::displayability_refusal(r, file.string());
    for (const runner::ConditionDisplayability& c : r.conditions) {
        // Both ends rendered, with every judged light of the stimulus.
        EXPECT_FALSE(c.low.lights.empty()) << c.name;
        EXPECT_EQ(c.low.lights.size(), c.high.lights.size()) << c.name;
        EXPECT_LT(c.low.level, c.high.level) << c.name;
    }
}

INSTANTIATE_TEST_SUITE_P(Displayability, Examples, ::testing::ValuesIn(examples_at_displays()),
                         [](const ::testing::TestParamInfo<ExampleAtDisplay>& param_info) {
                             const ExampleAtDisplay& e = param_info.param;
                             std::string name = e.protocol.stem().string() + "_" + e.display.name;
                             for (char& ch : name)
                                 if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                             return name;
                         });

using Result = test::Captured;
using test::atonlab;

using ::atonlab::test::contains;

/// IEC 61966-2-1 (sRGB) decoding of a drive level V in [0, 1]: the scene's
/// default display (docs/scene-file.md: encoding "srgb", peak 100 cd/m², black
/// 0.1 cd/m², each channel its Rec.709 share), in double precision.
double srgb_decode(double v) {
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

/// What the default display emits for 8-bit codes (R, G, B), cd/m².
double default_display_cd_m2(const glm::ivec3& code) {
    const double share[3] = {0.2126, 0.7152, 0.0722};
    double l = 0.0;
    for (int c = 0; c < 3; ++c) l += share[c] * (0.1 + (100.0 - 0.1) * srgb_decode(code[c] / 255.0));
    return l;
}

/// The solid angle (sr) of a pixel at the centre of a display width_px wide
/// over width_m, seen from distance_m.
double pixel_sr(int width_px, double width_m, double distance_m) {
    const double pitch_rad = 2.0 * std::atan(0.5 * width_m / width_px / distance_m);
    return pitch_rad * pitch_rad;
}

// A test light far too dim to change any code (the file's header): it adds
// exactly nothing over the lights-off frame of the same dither, so R1 refuses
// it; what the check calls the display's resolution there is one code step of
// all three channels (the light raises none) over the background's codes.
TEST(Displayability, TooDimTestLightAddsNothingAndIsRefused) {
    if (!test::gl_context()) ATONLAB_SKIP_NO_GPU() << test::gl_unavailable_reason();
    const Displayability d = check(kUndisplayable, 320, 180, 0.1);
    ASSERT_EQ(d.conditions.size(), 1u);
    const runner::ConditionDisplayability& c = d.conditions[0];
    EXPECT_FALSE(c.displayable());
    ASSERT_EQ(c.high.lights.size(), 2u);
    const runner::ShownLight& test = c.high.lights[0];
    ASSERT_EQ(test.role, p::Role::Test);
    // Not a hair of dither noise: the same frame index in both renders.
    EXPECT_EQ(test.added_lux, 0.0);
    // The 0.001 cd/m² sky is shown above the display's black: its codes are
    // what the screen shows (not 0), and their luminance is the display's.
    EXPECT_GT(test.background_code.r + test.background_code.g + test.background_code.b, 0);
    EXPECT_NEAR(test.background_cd_m2, default_display_cd_m2(test.background_code), 1e-6)
        << "background decoded through the display model";
    const double step_cd_m2 =
        default_display_cd_m2(test.background_code + glm::ivec3(1)) - default_display_cd_m2(test.background_code);
    // 0.5 %: the check's pixel is the camera's at the screen's centre (its own
    // pinhole), this one the display's pitch over the distance; they agree to ~1e-6.
    EXPECT_NEAR(test.resolution_lux, step_cd_m2 * pixel_sr(320, 0.1, 0.9), 5e-3 * test.resolution_lux);
    ASSERT_FALSE(c.problems.empty());
    EXPECT_TRUE(contains(c.problems[0], "the test light \"test\" adds no light")) << c.problems[0];
    // The reference, which the level raises, is seen at the top of its range.
    EXPECT_GT(c.high.lights[1].added_lux, c.high.lights[1].resolution_lux);
}

// A white reference whose lowest level already puts more light into the eye
// than the white test at the same place: the range does not straddle the
// test, and the refusal says to lower min_level, to about where. Both lights
// are the same pixel of the same colour, so they are equal exactly where
// their intensities are (the analytic match): level log10(1e-4 cd) = −4.
TEST(Displayability, ReferenceBrighterAtItsLowestLevelIsRefusedWithTheBoundToMove) {
    if (!test::gl_context()) ATONLAB_SKIP_NO_GPU() << test::gl_unavailable_reason();
    TempDir dir;
    const fs::path too_bright = variant(dir.path(), "too-bright.toml", kUndisplayable,
                                        {{kTestIntensity, "light.test.intensity_cd=1e-4"},
                                         {kMinLevel, "min_level = -3.6"},
                                         {"max_level = -2.0", "max_level = -3.0"}});
    const Displayability d = check(too_bright, 320, 180, 0.1);
    ASSERT_EQ(d.conditions.size(), 1u);
    const runner::ConditionDisplayability& c = d.conditions[0];
    std::printf("%s", runner::displayability_table(d).c_str());
    EXPECT_FALSE(c.displayable());
    ASSERT_EQ(c.problems.size(), 1u);
    const std::string& why = c.problems[0];
    EXPECT_TRUE(contains(why, "does not reach below the test light \"test\"")) << why;
    EXPECT_TRUE(contains(why, "at min_level (-3.6)")) << why;
    // The reference at its lowest level against the test.
    ASSERT_EQ(c.low.lights[1].role, p::Role::Reference);
    EXPECT_GE(c.low.lights[1].added_lux, c.low.lights[0].added_lux);
    ASSERT_TRUE(c.equal_level.has_value());
    // 0.25 log10: the level is extrapolated 0.4 below the range, along the
    // slope the tone curve gives between its ends (it compresses: the estimate
    // falls below the match, on the side that leaves the procedure room).
    EXPECT_NEAR(*c.equal_level, -4.0, 0.25) << why;
    const std::string say = "lower min_level to about ";
    const std::size_t at = why.find(say);
    ASSERT_NE(at, std::string::npos) << why;
    const double suggested = std::stod(why.substr(at + say.size()));
    EXPECT_LT(suggested, *c.equal_level);
    // With min_level moved as said, the condition can produce a match.
    const fs::path moved = variant(dir.path(), "moved.toml", kUndisplayable,
                                   {{kTestIntensity, "light.test.intensity_cd=1e-4"},
                                    {kMinLevel, fmt::format("min_level = {}", suggested)},
                                    {"max_level = -2.0", "max_level = -3.0"}});
    const Displayability after = check(moved, 320, 180, 0.1);
    EXPECT_TRUE(after.displayable()) << runner::displayability_refusal(after, moved.string());
}

// A condition whose test is well shown and whose range brackets it passes, its
// equal level near the analytic match (log10 of the test's intensity).
TEST(Displayability, GoodConditionPasses) {
    if (!test::gl_context()) ATONLAB_SKIP_NO_GPU() << test::gl_unavailable_reason();
    TempDir dir;
    const fs::path good =
        variant(dir.path(), "good.toml", kUndisplayable, {{kTestIntensity, "light.test.intensity_cd=1e-3"}});
    const Displayability d = check(good, 320, 180, 0.1);
    std::printf("%s", runner::displayability_table(d).c_str());
    ASSERT_EQ(d.conditions.size(), 1u);
    const runner::ConditionDisplayability& c = d.conditions[0];
    EXPECT_TRUE(c.displayable()) << runner::displayability_refusal(d, good.string());
    const runner::ShownLight& test = c.high.lights[0];
    EXPECT_GT(test.added_lux, 10.0 * test.resolution_lux);
    // The reference below the test at the bottom of its range, above it at the top.
    EXPECT_LT(c.low.lights[1].added_lux, c.low.lights[0].added_lux);
    EXPECT_GT(c.high.lights[1].added_lux, c.high.lights[0].added_lux);
    ASSERT_TRUE(c.equal_level.has_value());
    // 0.5 log10: interpolated across the range's two decades, along which the
    // tone curve compresses (a straight line in log through two points).
    EXPECT_NEAR(*c.equal_level, -3.0, 0.5);
}

TEST(Displayability, RunRefusesBeforeAnyTrialAndAllowRecordsTheFlag) {
    TempDir dir;
    const fs::path db = dir / "study.db";
    const Result refused = atonlab(
        {"run", kUndisplayable.string(), "--db", db.string(), "--headless", "--model-observer"}, dir.path(), "refused");
    if (refused.code == 3) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << refused.err;
    EXPECT_EQ(refused.code, 2) << refused.err;
    EXPECT_FALSE(fs::exists(db)) << "a refused session must not create the study file";
    // One sentence for the condition, naming the file and its line, what is not displayable and what to change.
    EXPECT_TRUE(contains(refused.err, kUndisplayable.string() + ":52: condition \"too-dim\" cannot produce a match"))
        << refused.err;
    EXPECT_TRUE(contains(refused.err, "test light \"test\" adds no light")) << refused.err;
    EXPECT_TRUE(contains(refused.err, "it cannot be seen; raise its intensity_cd")) << refused.err;
    EXPECT_TRUE(contains(refused.err, "--allow-undisplayable")) << refused.err;
    // The header's table was printed before the refusal.
    EXPECT_TRUE(contains(refused.out, "displayability on 320×180 px")) << refused.out;

    const Result allowed = atonlab({"run", kUndisplayable.string(), "--db", db.string(), "--headless",
                                    "--model-observer", "--no-true-pse", "--allow-undisplayable"},
                                   dir.path(), "allowed");
    ASSERT_EQ(allowed.code, 0) << allowed.err;
    EXPECT_TRUE(contains(allowed.err, "running anyway")) << allowed.err;
    {
        const store::Store study = store::Store::open_read_only(db);
        const std::vector<store::SessionRecord> sessions = study.sessions();
        ASSERT_EQ(sessions.size(), 1u);
        ASSERT_TRUE(sessions[0].displayability_json.has_value());
        const nlohmann::json j = store::parse_json(*sessions[0].displayability_json);
        EXPECT_EQ(store::boolean_at(j, "/displayable"), false);
        EXPECT_EQ(store::boolean_at(j, "/allowed_undisplayable"), true);
        EXPECT_EQ(store::string_at(j, "/conditions/0/name"), "too-dim");
        EXPECT_EQ(store::number_at(j, "/display/width_px"), 320.0);
        EXPECT_EQ(store::number_at(j, "/display/white_code"), 255.0);
        EXPECT_EQ(store::string_at(j, "/display/out_of_gamut"), "keep-luminance");  // the scene's default
        // The test light is the first of a 2AFC stimulus; at 1e-7 cd it adds nothing.
        EXPECT_EQ(store::string_at(j, "/conditions/0/ends/1/lights/0/role"), "test");
        EXPECT_EQ(store::number_at(j, "/conditions/0/ends/1/lights/0/added_lux").value_or(99.0), 0.0);
        EXPECT_GT(store::number_at(j, "/conditions/0/ends/1/lights/0/resolution_lux").value_or(0.0), 0.0);
        EXPECT_EQ(store::number_at(j, "/window_radius_deg"), 0.5);
    }
    const Result analyzed =
        atonlab({"analyze", db.string(), "--out", (dir / "report").string(), "--bootstrap", "20"}, dir.path(), "an");
    EXPECT_TRUE(analyzed.code == 0 || analyzed.code == 5) << analyzed.err;
    EXPECT_TRUE(contains(analyzed.out, "ran with --allow-undisplayable: too-dim")) << analyzed.out;
    const nlohmann::json summary = store::parse_json(file_bytes(dir / "report/summary.json"), "summary.json");
    EXPECT_EQ(store::boolean_at(summary, "/sessions/0/allowed_undisplayable"), true);
}

// R4 refuses a session the same way: exit 2 before the study file exists.
TEST(Displayability, RunRefusesARangeThatDoesNotStraddleTheTest) {
    TempDir dir;
    const fs::path too_bright = variant(dir.path(), "too-bright.toml", kUndisplayable,
                                        {{kTestIntensity, "light.test.intensity_cd=1e-4"},
                                         {kMinLevel, "min_level = -3.6"},
                                         {"max_level = -2.0", "max_level = -3.0"}});
    const fs::path db = dir / "study.db";
    const Result refused = atonlab({"run", too_bright.string(), "--db", db.string(), "--headless", "--model-observer"},
                                   dir.path(), "refused");
    if (refused.code == 3) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << refused.err;
    EXPECT_EQ(refused.code, 2) << refused.err;
    EXPECT_FALSE(fs::exists(db)) << "a refused session must not create the study file";
    EXPECT_TRUE(contains(refused.err, too_bright.string() + ":52: condition \"too-dim\" cannot produce a match"))
        << refused.err;
    EXPECT_TRUE(contains(refused.err, "lower min_level to about")) << refused.err;
    EXPECT_TRUE(contains(refused.out, "lx")) << refused.out;
}

TEST(Displayability, CheckCommandExitsTwoOrZeroAndWritesNothing) {
    TempDir dir;
    const Result bad = atonlab({"check", kUndisplayable.string()}, dir.path(), "bad");
    if (bad.code == 3) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << bad.err;
    EXPECT_EQ(bad.code, 2) << bad.err;
    EXPECT_TRUE(contains(bad.out, "NOT DISPLAYABLE")) << bad.out;
    EXPECT_TRUE(contains(bad.err, "condition \"too-dim\" cannot produce a match on this 320×180 display")) << bad.err;
    // The same light ten thousand times brighter rises well above the background.
    const fs::path brighter = dir / "brighter.toml";
    {
        std::string text = file_bytes(kUndisplayable);
        const std::string from = "light.test.intensity_cd=1e-7";
        text.replace(text.find(from), from.size(), "light.test.intensity_cd=1e-3");
        text.replace(text.find("scene = \"small.scene.toml\""), 26,
                     "scene = \"" + (kSource / "tests/data/run/small.scene.toml").string() + "\"");
        std::FILE* f = std::fopen(brighter.c_str(), "wb");
        ASSERT_TRUE(f);
        std::fwrite(text.data(), 1, text.size(), f);
        std::fclose(f);
    }
    const Result good = atonlab({"check", brighter.string()}, dir.path(), "good");
    EXPECT_EQ(good.code, 0) << good.out << good.err;
    EXPECT_TRUE(contains(good.out, "every condition can produce a match")) << good.out;
    // Another display on the command line: --set display.*.
    const Result other =
        atonlab({"check", brighter.string(), "--set", "display.width_px=640", "--set", "display.height_px=360"},
                dir.path(), "other");
    EXPECT_TRUE(contains(other.out, "displayability on 640×360 px")) << other.out;
    const Result wrong = atonlab({"check", brighter.string(), "--set", "eye.glare=none"}, dir.path(), "wrong");
    EXPECT_EQ(wrong.code, 2);
    EXPECT_TRUE(contains(wrong.err, "check sets only the display")) << wrong.err;
    // Nothing written next to the protocol: only this test's own files are in the folder.
    for (const auto& e : fs::directory_iterator(dir.path()))
        EXPECT_TRUE(e.path().extension() == ".out" || e.path().extension() == ".err" || e.path() == brighter)
            << e.path();
}

// Issue 44 §5 and issue 43 §3: a red 0.3 cd test light at 500 m over 0.001 cd/m² (320 × 180 px):
// its core asks the tone mapper for about twice the display's white (empirical operator, white
// 2: lr = key · L / L_wa ≈ 5), so keep-luminance shows it at white and loses about half of its
// light there. `check` warns of it with the share lost and refuses it under --strict. With
// display.out_of_gamut = "keep-signal-colour" the core is shown in red at 0.2126 of white: it
// gives up most of the luminance left, more than display.max_out_of_gamut_loss (5 %), and a
// brightness-matching condition is refused (R5) unless the protocol allows that share.
TEST(Displayability, AClippedOrOutOfGamutLightIsWarnedOfAndRefusedAsStated) {
    TempDir dir;
    const std::vector<std::pair<std::string, std::string>> red = {
        {"max_level = -2.0", "max_level = 0.0"},
        {kMinLevel, "min_level = -2.0"},
        {"start = -3.0", "start = -1.0"},
        {"\"light.test.intensity_cd=1e-7\"]", "\"light.test.intensity_cd=0.3\", 'light.test.colour=\"red\"']"}};
    const fs::path clipped = variant(dir.path(), "clipped.toml", kUndisplayable, red);
    const Result loose = atonlab({"check", clipped.string()}, dir.path(), "loose");
    if (loose.code == 3) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << loose.err;
    EXPECT_EQ(loose.code, 0) << loose.out << loose.err;
    EXPECT_TRUE(contains(loose.err, "atonlab: warning: " + clipped.string())) << loose.err;
    EXPECT_TRUE(contains(loose.err, "the test light \"test\" is clipped at the display's white (code 255) and shows"))
        << loose.err;
    EXPECT_TRUE(contains(loose.out, "% at white")) << loose.out;
    const Result strict = atonlab({"check", clipped.string(), "--strict"}, dir.path(), "strict");
    EXPECT_EQ(strict.code, 2) << strict.err;
    EXPECT_TRUE(contains(strict.err, "--strict")) << strict.err;
    if (!test::gl_context()) ATONLAB_SKIP_NO_GPU() << test::gl_unavailable_reason();

    // The share lost, from the API: about half of the test light's window light (Y ≈ 2 at its core).
    const Displayability d = check(clipped, 320, 180, 0.1);
    ASSERT_EQ(d.conditions.size(), 1u);
    const runner::ShownLight& test = d.conditions[0].high.lights[0];
    std::printf("red 0.3 cd: adds %.3g lx, %.1f %% lost at white, %.1f %% to the gamut choice\n", test.added_lux,
                100.0 * test.white_loss_share, 100.0 * test.gamut_loss_share);
    EXPECT_GT(test.white_loss_share, 0.2);
    EXPECT_LT(test.white_loss_share, 0.8);
    EXPECT_LT(test.gamut_loss_share, 1e-9);  // keep-luminance takes nothing beyond the white
    EXPECT_EQ(d.out_of_gamut, "keep-luminance");

    // keep-signal-colour: the red core keeps its colour and gives up luminance; R5 refuses.
    std::vector<std::pair<std::string, std::string>> signal = red;
    signal.emplace_back("set = ['tonemap.operator=\"empirical\"']",
                        "set = ['tonemap.operator=\"empirical\"', 'display.out_of_gamut=\"keep-signal-colour\"']");
    const fs::path coloured = variant(dir.path(), "coloured.toml", kUndisplayable, signal);
    const Displayability k = check(coloured, 320, 180, 0.1);
    ASSERT_EQ(k.conditions.size(), 1u);
    const runner::ShownLight& kt = k.conditions[0].high.lights[0];
    std::printf("keep-signal-colour: %.1f %% lost at white, %.1f %% to the gamut choice\n",
                100.0 * kt.white_loss_share, 100.0 * kt.gamut_loss_share);
    EXPECT_GT(kt.gamut_loss_share, 0.05);
    EXPECT_EQ(k.conditions[0].high.out_of_gamut, "keep-signal-colour");
    EXPECT_FALSE(k.conditions[0].displayable());
    bool named = false;
    for (const std::string& problem : k.conditions[0].problems)
        named = named || contains(problem, "display.out_of_gamut = \"keep-signal-colour\"");
    EXPECT_TRUE(named) << runner::displayability_refusal(k, coloured.string());
    // A protocol that allows the share: no R5.
    signal.emplace_back("viewing_distance_m = 0.9", "viewing_distance_m = 0.9\nmax_out_of_gamut_loss = 1.0");
    const fs::path allowed_file = variant(dir.path(), "allowed.toml", kUndisplayable, signal);
    const Displayability allowed = check(allowed_file, 320, 180, 0.1);
    for (const std::string& problem : allowed.conditions.at(0).problems)
        EXPECT_FALSE(contains(problem, "display.out_of_gamut")) << problem;
    // The study file stores the choice, and the report names it.
    const fs::path db = dir / "study.db";
    const Result ran = atonlab({"run", allowed_file.string(), "--db", db.string(), "--headless", "--model-observer",
                                "--no-true-pse", "--allow-undisplayable"},
                               dir.path(), "ran");
    ASSERT_EQ(ran.code, 0) << ran.err;
    {
        const store::Store study = store::Store::open_read_only(db);
        const nlohmann::json j = store::parse_json(*study.sessions().at(0).displayability_json);
        EXPECT_EQ(store::string_at(j, "/conditions/0/ends/1/out_of_gamut"), "keep-signal-colour");
        EXPECT_GT(store::number_at(j, "/conditions/0/ends/1/lights/0/gamut_loss_share").value_or(0.0), 0.05);
    }
    const Result analyzed =
        atonlab({"analyze", db.string(), "--out", (dir / "report").string(), "--bootstrap", "20"}, dir.path(), "an");
    EXPECT_TRUE(analyzed.code == 0 || analyzed.code == 5) << analyzed.err;
    // The report's notes (HTML-escaped quotes).
    const std::string html = file_bytes(dir / "report/report.html");
    EXPECT_TRUE(contains(html, "display.out_of_gamut = &quot;keep-signal-colour&quot;, not keep-luminance"))
        << analyzed.out;
    // analyze reads the shares back: summary.json's largest shares are those `check` computes for the
    // same condition on the same display, judged by the limits the session ran under (the protocol's 1.0).
    double white = 0.0, gamut = 0.0;
    for (const runner::LevelEnd* end : {&allowed.conditions[0].low, &allowed.conditions[0].high})
        for (const runner::ShownLight& s : end->lights) {
            white = std::max(white, s.white_loss_share);
            gamut = std::max(gamut, s.gamut_loss_share);
        }
    const nlohmann::json summary = store::parse_json(file_bytes(dir / "report/summary.json"), "summary.json");
    const nlohmann::json& losses = summary.at("sessions").at(0).at("display_losses").at(0);
    EXPECT_NEAR(store::number_at(losses, "/white_loss/share").value_or(-1.0), white, 1e-3) << losses.dump();
    EXPECT_NEAR(store::number_at(losses, "/gamut_loss/share").value_or(-1.0), gamut, 1e-3) << losses.dump();
    EXPECT_EQ(store::number_at(summary, "/sessions/0/display_thresholds/max_out_of_gamut_loss"), 1.0);
    EXPECT_EQ(store::number_at(summary, "/sessions/0/display_thresholds/white_loss_warning_share"),
              runner::kWhiteLossWarningShare);
    EXPECT_EQ(store::boolean_at(losses, "/gamut_loss_over_limit"), false);
    EXPECT_EQ(store::boolean_at(losses, "/white_loss_over_warning"), white > runner::kWhiteLossWarningShare);
    // Clipped at white by more than 1 %: one line on the console and one note, with the share.
    if (white > runner::kWhiteLossWarningShare) {
        const std::string said = fmt::format("loses {:.1f} % of its light at the display's white", 100.0 * white);
        EXPECT_TRUE(contains(analyzed.out, said)) << said << "\n" << analyzed.out;
        const std::string escaped =
            fmt::format("loses {:.1f} % of its light at the display&#39;s white", 100.0 * white);
        EXPECT_TRUE(contains(html, escaped)) << escaped;
    }
}

}  // namespace
}  // namespace atonlab
