// What `atonlab analyze` says of the lights a study showed (issue 24 items 5
// and 7): each judged light's colour, rhythm and spectrum read from the scene
// stored in the study file with the trial's overrides (scene_lights.h); the
// difference between test and reference named "enhancement by glare" only
// where glare is all that differs; and trials.csv's tidy values (levels
// without the last-bit noise of summed decimal steps, block names, positions
// as numbers).
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "../../analysis/src/csv.h"
#include "atonlab/common/csv.h"
#include "../store/store_test_support.h"
#include "analysis_test_data.h"
#include "atonlab/analysis/dataset.h"
#include "atonlab/analysis/report.h"
#include "atonlab/analysis/scene_lights.h"
#include "atonlab/analysis/study_analysis.h"
#include "atonlab/store/json.h"
#include "atonlab/store/sha256.h"

namespace atonlab::analysis {
namespace {

namespace fs = std::filesystem;
using store::test_support::file_bytes;
using store::test_support::TempDir;
namespace td = test_data;
using Overrides = std::vector<SceneOverride>;  // as a trial stores them

// --- The scene reader ---------------------------------------------------------

constexpr const char* kScene = R"(
[[light]]
name = "buoy"
position_m = [0.0, 2.0, -1852.0]
intensity_cd = 250.0
colour = "red"
rhythm = "Fl(1) 4s"

[[light]]
position_m = [0.0, 2.0, -1852.0]
intensity_cd = 250.0
xy = [0.31, 0.33]

[[light]]
name = "lh"
position_m = [0.0, 2.0, -1852.0]
intensity_cd = 250.0
rhythm = "Al.WR 4s"

[[disc]]
name = "patch"
position_m = [0.0, 2.0, -1852.0]
diameter_deg = 0.5
luminance_cd_m2 = 1.0
spd = "led-white"
)";

SceneLights scene_lights(const char* text) {
    std::string why;
    auto s = SceneLights::parse(text, why);
    EXPECT_TRUE(s) << why;
    return s ? *s : *SceneLights::parse("", why);
}

TEST(AnalysisLights, TheSceneGivesEachLightsColourRhythmAndSpectrum) {
    const SceneLights s = scene_lights(kScene);
    EXPECT_EQ(s.look("buoy", {}), (LightLook{"red", "Fl(1) 4s", "iala-red"}));
    // A light without a name is "light1" (its index), as the scene loader names it; xy as written.
    EXPECT_EQ(s.look("light1", {}), (LightLook{"xy 0.31, 0.33", "F", "d65"}));
    // An alternating light: the whole, and one colour of it by its chart letter.
    EXPECT_EQ(s.look("lh", {}), (LightLook{"alternating (Al.WR 4s)", "Al.WR 4s", ""}));
    EXPECT_EQ(s.look("lh/R", {}), (LightLook{"red", "Al.WR 4s", "iala-red"}));
    // A light without spd takes its colour's representative spectrum, an xy light D65, an
    // alternating light none (each colour its own). A disc is steady; an spd is its spectrum.
    EXPECT_EQ(s.look("patch", {}), (LightLook{"spd led-white", "steady", "led-white"}));
    EXPECT_FALSE(s.look("nothing", {}));
    std::string why;
    EXPECT_FALSE(SceneLights::parse("[[light]\nname = ", why));
    EXPECT_FALSE(why.empty());
}

TEST(AnalysisLights, OverridesApplyInOrderByNameOrIndexAndColourKeysExcludeEachOther) {
    const SceneLights s = scene_lights(kScene);
    // By name; a later override wins; an spd replaces the colour (one of colour, xy, spd).
    EXPECT_EQ(s.look("buoy", Overrides{{"light.buoy.colour", "\"green\""}, {"light.buoy.spd", "\"led-white\""}}),
              (LightLook{"spd led-white", "Fl(1) 4s", "led-white"}));
    // By index; a value that is not TOML is a string, as for --set.
    EXPECT_EQ(s.look("buoy", Overrides{{"light[0].rhythm", "Oc 6s"}, {"light[0].colour", "'white'"}}),
              (LightLook{"white", "Oc 6s", "d65"}));
    // xy replaced by colour; overrides of other lights and other keys are not this light's.
    EXPECT_EQ(s.look("light1", Overrides{{"light[1].colour", "\"yellow\""},
                                         {"light.buoy.colour", "\"blue\""},
                                         {"light[1].intensity_cd", "3"},
                                         {"eye.glare", "\"none\""}}),
              (LightLook{"yellow", "F", "iala-yellow"}));
}

// --- The analysis of a study ----------------------------------------------------

/// A side-by-side 2AFC: `test_set` on the test light, the level on the
/// reference's log10 intensity, a staircase from -0.1 in steps of 0.2 (levels
/// -0.1 - 0.2 = -0.30000000000000004, ...), block "dusk".
std::string side_by_side(const std::string& test_set) {
    return R"(
[protocol]
name = "sim-side"
scene = "none.scene.toml"
seed = 3
[display]
width_px = 320
height_px = 180
width_m = 0.1
viewing_distance_m = 0.9
[defaults]
task = "2afc"
presentation = "side-by-side"
test_light = "test"
reference_light = "reference"
left_position_m = [-26.2, 3.0, -500.0]
right_position_m = [26.2, 3.0, -500.0]
test_set = [)" +
           test_set + R"(]
reference_set = ['light.reference.glare="none"']
level_key = "light.reference.intensity_cd"
level_scale = "log10"
choice = "chose-reference"
procedure = { kind = "staircase", start = [-0.1], step_sizes = [0.2], step_type = "lin", n_up = 1, n_down = 1, n_reversals = 30, max_trials = 24, min_level = -3.1, max_level = 2.9 }
[[block]]
name = "dusk"
set = ["eye.adaptation_cd_m2=0.1", "light.test.intensity_cd=1"]
[[block.condition]]
name = "side"
)";
}

struct Analysed {
    Dataset data;
    StudyResults results;
    std::string html, summary, fits, trials;
};

Analysed analyse(const TempDir& dir, const std::string& protocol, const std::string& scene) {
    td::run_simulated(dir / "s.db", protocol, td::sim("A", -0.5, 0.3), 7, true, 1u << 30, std::nullopt, scene);
    Analysed a;
    a.data = read_study(dir / "s.db");
    AnalysisOptions o;
    o.bootstrap = 20;
    a.results = analyze_study(a.data, o);
    const fs::path out = dir / "out";
    fs::create_directories(out);
    ReportContext ctx;
    ctx.data = &a.data;
    ctx.results = &a.results;
    ctx.software_version = "test";
    write_report(out, ctx);
    a.html = file_bytes(out / "report.html");
    a.summary = file_bytes(out / "summary.json");
    a.fits = file_bytes(out / "fits.csv");
    a.trials = file_bytes(out / "trials.csv");
    return a;
}

/// A CSV's column `name` as text, row by row (RFC 4180, read by common/csv.h's reader).
std::vector<std::string> column(const std::string& csv, const std::string& name) {
    CsvReader reader(csv, "trials.csv");
    const auto header = reader.next();
    EXPECT_TRUE(header);
    if (!header) return {};
    const std::vector<std::string> names = header->texts();
    const auto at = std::find(names.begin(), names.end(), name);
    EXPECT_NE(at, names.end()) << "no column " << name;
    const auto i = static_cast<std::size_t>(at - names.begin());
    std::vector<std::string> out;
    while (const auto rec = reader.next())
        out.push_back(i < rec->fields.size() ? rec->fields[i].text : std::string());
    return out;
}

TEST(AnalysisLights, ARedFlashingTestBesideAWhiteReferenceIsNamedAndNotCalledAnEnhancementByGlare) {
    TempDir dir;
    const Analysed a = analyse(
        dir,
        side_by_side(R"('light.test.glare="wave-optics"', 'light.test.colour="red"', 'light.test.rhythm="Fl(1) 4s"')"),
        td::kWhiteLightsScene);
    ASSERT_EQ(a.results.conditions.size(), 1u);
    const ConditionInfo& c = a.results.conditions[0];
    EXPECT_EQ(c.test_look, (LightLook{"red", "Fl(1) 4s", "iala-red"}));
    EXPECT_EQ(c.reference_look, (LightLook{"white", "F", "d65"}));
    EXPECT_EQ(c.differences, (std::vector<std::string>{"colour", "rhythm", "glare"}));
    EXPECT_EQ(c.difference_label(), "test − reference");
    for (const std::string* out : {&a.html, &a.summary, &a.fits})
        EXPECT_EQ(out->find("enhancement by glare"), std::string::npos);
    EXPECT_NE(a.html.find("red, rhythm Fl(1) 4s"), std::string::npos);
    EXPECT_NE(a.html.find("white, rhythm F"), std::string::npos);
    EXPECT_NE(a.html.find("test − reference"), std::string::npos);
    // summary.json names each side's light.
    const nlohmann::json j = store::parse_json(a.summary, "summary.json");
    EXPECT_EQ(store::string_at(j, "/conditions/0/test_light/colour"), "red");
    EXPECT_EQ(store::string_at(j, "/conditions/0/test_light/rhythm"), "Fl(1) 4s");
    EXPECT_EQ(store::string_at(j, "/conditions/0/test_light/glare"), "wave-optics");
    EXPECT_EQ(store::string_at(j, "/conditions/0/reference_light/colour"), "white");
    EXPECT_EQ(store::string_at(j, "/conditions/0/reference_light/glare"), "none");
    EXPECT_EQ(store::string_at(j, "/conditions/0/difference"), "test − reference");
    EXPECT_EQ(store::string_at(j, "/sessions/0/scene_sha256"), store::sha256_hex(td::kWhiteLightsScene));
    // fits.csv, on every row of the condition.
    for (const std::string& v : column(a.fits, "test_colour")) EXPECT_EQ(v, "red");
    for (const std::string& v : column(a.fits, "reference_colour")) EXPECT_EQ(v, "white");
    for (const std::string& v : column(a.fits, "test_rhythm")) EXPECT_EQ(v, "Fl(1) 4s");
}

TEST(AnalysisLights, GlareAloneIsStillABrightnessEnhancementByGlare) {
    TempDir dir;
    const Analysed a = analyse(dir, side_by_side(R"('light.test.glare="wave-optics"')"), td::kWhiteLightsScene);
    const ConditionInfo& c = a.results.conditions.at(0);
    EXPECT_EQ(c.test_look, c.reference_look);
    EXPECT_EQ(c.differences, std::vector<std::string>{"glare"});
    EXPECT_TRUE(c.glare_only_difference());
    EXPECT_NE(a.html.find("enhancement by glare"), std::string::npos);
    EXPECT_NE(a.fits.find("enhancement by glare"), std::string::npos);
}

TEST(AnalysisLights, AStudyWithoutItsSceneSaysSoAndDoesNotClaimAnEnhancement) {
    TempDir dir;
    const Analysed a = analyse(dir, side_by_side(R"('light.test.glare="wave-optics"')"), "");
    const ConditionInfo& c = a.results.conditions.at(0);
    EXPECT_FALSE(c.lights_known());
    EXPECT_EQ(c.difference_label(), "test − reference");
    EXPECT_EQ(a.html.find("enhancement by glare"), std::string::npos);
    EXPECT_NE(a.html.find("does not hold the scene"), std::string::npos);
    EXPECT_TRUE(std::any_of(a.results.warnings.begin(), a.results.warnings.end(), [](const std::string& w) {
        return w.find("does not hold the scene") != std::string::npos;
    }));
}

// --- Tidy values in trials.csv ----------------------------------------------------

double parsed(const std::string& text) {
    double x = std::nan("");
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), x);
    EXPECT_TRUE(ec == std::errc() && ptr == text.data() + text.size()) << "'" << text << "' is not a number";
    return x;
}

TEST(AnalysisLights, TrialsCsvWritesLevelsWithoutNoiseBlockNamesAndPositionsAsNumbers) {
    TempDir dir;
    const Analysed a = analyse(dir, side_by_side(R"('light.test.glare="wave-optics"')"), td::kWhiteLightsScene);
    const std::vector<std::string> levels = column(a.trials, "level");
    ASSERT_EQ(levels.size(), a.data.trials.size());
    store::Store db = store::Store::open_read_only(dir / "s.db");
    const std::vector<store::TrialRecord> records = db.trials(db.sessions().at(0).id);
    ASSERT_EQ(records.size(), levels.size());
    bool noisy = false;
    for (std::size_t i = 0; i < levels.size(); ++i) {
        SCOPED_TRACE(levels[i]);
        const double stored = records[i].level;  // as the study file keeps it, bit for bit
        // The staircase's levels are -0.1 + 0.2 k: the decimal (2k - 1) / 10,
        // whose nearest double is the integer division (IEEE 754 rounds it).
        const long k = std::lround((stored + 0.1) / 0.2);
        const double decimal = static_cast<double>(2 * k - 1) / 10.0;
        noisy = noisy || stored != decimal;
        EXPECT_LE(std::abs(stored - decimal), 1e-15);      // noise, not a different level
        EXPECT_EQ(parsed(levels[i]), decimal);             // the decimal, exactly
        EXPECT_EQ(levels[i], fmt::format("{}", decimal));  // in its shortest text ("-0.3")
        EXPECT_LE(levels[i].size(), 4u);                   // never "-0.30000000000000004"
    }
    EXPECT_TRUE(noisy) << "no stored level carries the noise this test is about";
    for (const std::string& b : column(a.trials, "block")) EXPECT_EQ(b, "dusk");
    for (const std::string& b : column(a.trials, "block_index")) EXPECT_EQ(b, "0");
    // Positions: one number per element; the test's x is one of the two sides.
    const std::vector<std::string> x = column(a.trials, "light.test.position_m[0]");
    const std::vector<std::string> z = column(a.trials, "light.test.position_m[2]");
    ASSERT_EQ(x.size(), levels.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
        EXPECT_EQ(std::abs(parsed(x[i])), 26.2) << x[i];
        EXPECT_EQ(parsed(z[i]), -500.0) << z[i];
    }
    EXPECT_EQ(a.trials.find("\"["), std::string::npos) << "a quoted TOML array";
    // Read back, the positions are one setting again, and the levels the decimals.
    const Dataset back = read_trials_csv(dir / "out" / "trials.csv");
    ASSERT_EQ(back.trials.size(), a.data.trials.size());
    for (std::size_t i = 0; i < back.trials.size(); ++i) {
        const SettingValue p = setting_value(back.trials[i].settings.at("light.test.position_m"));
        ASSERT_TRUE(p.numbers);
        EXPECT_EQ(*p.numbers, *setting_value(a.data.trials[i].settings.at("light.test.position_m")).numbers);
        EXPECT_EQ(back.trials[i].block_name, "dusk");
        EXPECT_EQ(back.trials[i].test_look, a.data.trials[i].test_look);
    }
}

}  // namespace
}  // namespace atonlab::analysis
