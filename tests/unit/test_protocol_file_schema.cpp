// The protocol file's schema: inline protocols' details (side-by-side
// positions, inheritance), conflicting overrides, and every malformed file as
// one sentence naming the file, the line and the key, all errors of a file at
// once in file order.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/protocols/protocol_file.h"
#include "protocol_file_test_support.h"

namespace {

using namespace atonlab::protocols;                      // NOLINT: the test exercises the whole namespace
using namespace atonlab::protocols::protocol_file_test;  // NOLINT: the shared examples and readers
namespace fs = std::filesystem;

TEST(ProtocolSchema, SideBySideSwapsThePositionsWithTheForcedChoice) {
    const Protocol p = parse(R"(
[[block]]
[[block.condition]]
name = "colour"
task = "2afc"
presentation = "side-by-side"
test_light = "red"
reference_light = "white"
left_position_m = [-10.0, 3.0, -500.0]
right_position_m = [10.0, 3.0, -500.0]
level_key = "light.white.intensity_cd"
procedure = { kind = "weighted-staircase", start = 2.0, target = 0.75, step_sizes = 0.05, step_type = "lin", n_trials = 30 }
)");
    EXPECT_EQ(p.scene, fs::path("scene.toml"));
    EXPECT_EQ(p.blocks[0].name, "block0");
    const Condition& c = p.blocks[0].conditions[0];
    Proposal prop;
    prop.level = 1.0;
    prop.test_on_left = true;
    Stimulus s = make_stimulus(p, c, prop);
    ASSERT_EQ(s.frames.size(), 1u);
    EXPECT_FALSE(s.frames[0].role.has_value());
    const auto& o = s.frames[0].override_texts();
    EXPECT_NE(std::find(o.begin(), o.end(), "light.red.position_m=[-10, 3, -500]"), o.end());
    EXPECT_NE(std::find(o.begin(), o.end(), "light.white.position_m=[10, 3, -500]"), o.end());
    EXPECT_NE(std::find(o.begin(), o.end(), "light.white.intensity_cd=10"), o.end());
    EXPECT_EQ(s.views[0].light, "red");
    EXPECT_EQ(s.views[1].light, "white");
    prop.test_on_left = false;
    s = make_stimulus(p, c, prop);
    const std::vector<std::string> swapped = s.frames[0].override_texts();
    EXPECT_NE(std::find(swapped.begin(), swapped.end(), "light.red.position_m=[10, 3, -500]"), swapped.end());
    EXPECT_EQ(s.views[0].light, "white");
    EXPECT_EQ(make_track(c, 0, 1)->kind(), "2afc");
}

TEST(ProtocolSchema, ConditionsInheritAndAProcedureOfAnotherKindStartsAfresh) {
    const Protocol p = parse(R"(
[defaults]
task = "yes-no"
level_key = "light.l.intensity_cd"
set = ["eye.glare=\"none\""]
procedure = { kind = "quest", t_guess = 0.0, n_trials = 20 }

[[block]]
name = "b"
set = ["eye.adaptation_cd_m2=0.01"]
procedure = { n_trials = 25 }

[[block.condition]]
name = "inherits"

[[block.condition]]
name = "staircase"
level_scale = "linear"
set = "light.l.rhythm=\"Fl 2s\""
[block.condition.procedure]
kind = "staircase"
start = 5.0
step_type = "lin"
step_sizes = [1.0]
n_trials = 10
)");
    const Condition& a = p.blocks[0].conditions[0];
    EXPECT_EQ(a.task, Task::YesNo);
    EXPECT_EQ(a.presentation, Presentation::Single);
    EXPECT_EQ(a.level_on, Role::Test);
    EXPECT_EQ(a.set.size(), 2u);
    EXPECT_EQ(std::get<QuestParams>(a.procedure.params).n_trials, 25);
    const Condition& b = p.blocks[0].conditions[1];
    EXPECT_EQ(b.set.size(), 3u);
    EXPECT_EQ(b.set[2].text(), "light.l.rhythm=\"Fl 2s\"");
    ASSERT_EQ(b.procedure.kind, ProcedureKind::Staircase);
    EXPECT_EQ(std::get<StaircaseParams>(b.procedure.params).n_trials, 10);
    EXPECT_EQ(b.scene_value(5.0), 5.0);
    EXPECT_EQ(a.scene_value(1.0), 10.0);
}

TEST(ProtocolSchema, EachErrorIsOneSentenceAtItsLine) {
    // Line numbers count the 9-line header.
    EXPECT_EQ(error_of(R"(
[[block]]
[[block.condition]]
task = "2afc"
level_key = "light.r.intensity_cd"
procedure = { kind = "staircase", start = 1.0, step_type = "lin", n_reversals = 4 }
[[block.condition]]
name = "block0-c0"
)"),
              "inline.toml:17: key 'block[0].condition[1].name': a condition called \"block0-c0\" already exists "
              "(line 12); condition names are unique in the protocol.");
    EXPECT_EQ(error_of(R"(
[[block]]
[[block.condition]]
task = "adjust"
level_key = "light.r.intensity_cd"
procedure = { kind = "staircase", start = 1.0, step_type = "lin", n_reversals = 4 }
)"),
              "inline.toml:15: key 'block[0].condition[0].procedure.kind': in condition \"block0-c0\", task = "
              "\"adjust\" needs kind = \"adjustment\", not \"staircase\".");
    EXPECT_EQ(error_of(R"(
[[block]]
[[block.condition]]
task = "yes-no"
level_key = "light.r.intensity_cd"
level_scale = "linear"
procedure = { kind = "quest", t_guess = 1.0, n_trials = 4 }
)"),
              "inline.toml:15: key 'block[0].condition[0].level_scale': in condition \"block0-c0\", QUEST works in "
              "log10 units (its Weibull is a function of log intensity): level_scale must be \"log10\".");
    EXPECT_EQ(error_of(R"(
[[block]]
[[block.condition]]
task = "2afc"
presentation = "side-by-side"
level_key = "light.r.intensity_cd"
procedure = { kind = "staircase", start = 1.0, step_type = "lin", n_reversals = 4 }
)"),
              "inline.toml:12: key 'block[0].condition[0].test_light': condition \"block0-c0\" (line 12) has no "
              "'test_light', which is required (side-by-side needs both lights and both positions); give it in "
              "the condition, its [[block]] or [defaults].");
}

// ---- Conflicting overrides (docs/protocol-file.md "When two overrides set one key") ----

/// A two-interval or side-by-side 2AFC block with the given condition keys.
std::string conflict_case(const std::string& presentation, const std::string& defaults, const std::string& block,
                          const std::string& condition) {
    return "[defaults]\ntask = \"2afc\"\npresentation = \"" + presentation +
           "\"\ntest_light = \"t\"\nreference_light = \"r\"\n" +
           (presentation == "side-by-side"
                ? "left_position_m = [-10.0, 3.0, -500.0]\nright_position_m = [10.0, 3.0, -500.0]\n"
                : "\n\n") +  // (the same line numbers either way)
           std::string("level_key = \"light.r.intensity_cd\"\n"
           "procedure = { kind = \"staircase\", start = 1.0, step_type = \"lin\", n_reversals = 4 }\n") +
           defaults + "\n[[block]]\n" + block + "\n[[block.condition]]\nname = \"c\"\n" + condition + "\n";
}

std::string conflict_error(const std::string& text) {
    try {
        (void)parse(text);
    } catch (const atonlab::InputError& e) {
        return e.what();
    }
    return "";
}

TEST(ProtocolConflicts, SideBySideTestAndReferenceSetsMustAgree) {
    // The issue's case: the eye is one for both lights of the frame.
    const std::string e = conflict_error(conflict_case(
        "side-by-side", "test_set = ['eye.glare=\"wave-optics\"']\nreference_set = ['eye.glare=\"none\"']", "", ""));
    EXPECT_NE(e.find("inline.toml:20: key 'defaults.reference_set[0]'"), std::string::npos) << e;
    EXPECT_NE(e.find("eye.glare is set to \"none\" here and to \"wave-optics\" by defaults.test_set[0] (line 19)"),
              std::string::npos)
        << e;
    // The same lists in a two-interval design switch the eye per interval: fine.
    EXPECT_EQ(conflict_error(conflict_case("two-interval",
                                           "test_set = ['eye.glare=\"wave-optics\"']\nreference_set = "
                                           "['eye.glare=\"none\"']",
                                           "", "")),
              "");
    // Each light its own model: different keys, one frame.
    const Protocol p = parse(conflict_case(
        "side-by-side", "test_set = ['light.t.glare=\"wave-optics\"']\nreference_set = ['light.r.glare=\"none\"']", "",
        ""));
    const Condition& c = p.blocks[0].conditions[0];
    Proposal prop;
    prop.level = 0.5;
    prop.test_on_left = true;
    const Stimulus stimulus = make_stimulus(p, c, prop);
    const auto& o = stimulus.frames[0].override_texts();
    EXPECT_NE(std::find(o.begin(), o.end(), "light.t.glare=\"wave-optics\""), o.end());
    EXPECT_NE(std::find(o.begin(), o.end(), "light.r.glare=\"none\""), o.end());
    // Equal values are not a conflict (numbers compare as numbers).
    EXPECT_EQ(conflict_error(conflict_case("side-by-side", "test_set = ['eye.pupil_mm=4']\nreference_set = "
                                                           "['eye.pupil_mm=4.0']",
                                           "", "")),
              "");
}

TEST(ProtocolConflicts, ABlockAndItsConditionMustAgree) {
    const std::string e = conflict_error(
        conflict_case("two-interval", "", "set = ['tonemap.operator=\"empirical\"']", "set = ['tonemap.operator=\"perceptual\"']"));
    EXPECT_NE(e.find("key 'block[0].condition[0].set[0]'"), std::string::npos) << e;
    EXPECT_NE(e.find("tonemap.operator is set to \"perceptual\" here and to \"empirical\" by block[0].set[0]"),
              std::string::npos)
        << e;
    EXPECT_NE(e.find("a condition and its block"), std::string::npos) << e;
    // One list twice.
    EXPECT_NE(conflict_error(conflict_case("two-interval", "", "set = ['eye.pupil_mm=3', 'eye.pupil_mm=5']", ""))
                  .find("one list sets it twice"),
              std::string::npos);
}

TEST(ProtocolConflicts, DefaultsAndRoleListsReplaceByDesign) {
    // A block replaces a default, in any presentation; the default is dropped.
    for (const std::string presentation : {"two-interval", "side-by-side"}) {
        SCOPED_TRACE(presentation);
        const Protocol p = parse(conflict_case(presentation, "test_set = ['eye.pupil_mm=3']", "set = ['eye.pupil_mm=5']", ""));
        const Condition& c = p.blocks[0].conditions[0];
        Proposal prop;
        prop.level = 0.5;
        prop.test_on_left = true;
        const Stimulus s = make_stimulus(p, c, prop);
        // The test's frame (the only frame side by side): the last pupil_mm is the block's in side-by-side; in a
        // two-interval test frame the role's list replaces `set` (the default's 3).
        std::string last;
        for (const std::string& o : s.frames[0].override_texts())
            if (o.starts_with("eye.pupil_mm=")) last = o;
        if (presentation == "side-by-side") {
            EXPECT_EQ(last, "eye.pupil_mm=5");
        } else if (s.frames[0].role == Role::Test) {
            EXPECT_EQ(last, "eye.pupil_mm=3");
        }
    }
    // Two-interval: a block's set and the defaults' role list (the glare examples'
    // light.test.intensity_cd) are fine; side by side a block's set and a
    // block's reference_set on one key are not.
    EXPECT_EQ(conflict_error(conflict_case("two-interval", "reference_set = ['light.t.intensity_cd=0']",
                                           "set = ['light.t.intensity_cd=0.002']", "")),
              "");
    EXPECT_NE(conflict_error(conflict_case("side-by-side", "", "set = ['light.t.intensity_cd=0.002']",
                                           "reference_set = ['light.t.intensity_cd=0']"))
                  .find("a side-by-side frame holds both lights, and set and reference_set both apply"),
              std::string::npos);
}

TEST(ProtocolConflicts, TheLevelAndTheSideBySidePositionsAreNotOverridden) {
    const std::string level = conflict_error(conflict_case("two-interval", "", "reference_set = ['light.r.intensity_cd=5']", ""));
    EXPECT_NE(level.find("light.r.intensity_cd is set to 5 here, but it is the level_key (defaults.level_key)"),
              std::string::npos)
        << level;
    // In the frame the level is not on, the key is free.
    EXPECT_EQ(conflict_error(conflict_case("two-interval", "test_set = ['light.r.intensity_cd=0']", "", "")), "");
    EXPECT_NE(conflict_error(conflict_case("side-by-side", "test_set = ['light.r.intensity_cd=0']", "", ""))
                  .find("it is the level_key"),
              std::string::npos);
    EXPECT_NE(conflict_error(conflict_case("side-by-side", "set = ['light.t.position_m=[0, 3, -500]']", "", ""))
                  .find("a side-by-side frame places its lights at left_position_m and right_position_m"),
              std::string::npos);
}

// ---- Malformed files -------------------------------------------------------------

struct Bad {
    std::string file;
    int line;
    std::string key;
    std::string says;  ///< a phrase the message must contain
};

TEST(ProtocolErrors, EveryMalformedFileNamesFileLineAndKey) {
    const std::vector<Bad> cases = {
        {"syntax-error.toml", 14, "", "TOML syntax error"},
        {"unknown-key.toml", 13, "timing.stimulus",
         "unknown key 'stimulus' in the [timing] table. Did you mean 'stimulus_s'?"},
        {"unknown-procedure-key.toml", 23, "block[0].condition[0].procedure.step_size",
         "unknown key 'step_size' in a staircase procedure. Did you mean 'step_sizes'?"},
        {"wrong-type.toml", 14, "block[0].repetitions", "expected an integer, got a string."},
        {"wrong-type-procedure.toml", 21, "defaults.procedure.n_reversals",
         "expected an integer, got a floating-point number."},
        {"negative-duration.toml", 13, "timing.inter_trial_s", "inter_trial_s must be at least 0, got -1."},
        {"negative-adaptation.toml", 14, "block[0].adaptation_s", "adaptation_s must be at least 0, got -30."},
        {"min-above-max.toml", 25, "block[0].condition[0].procedure.min_level",
         "min_level (3) is greater than max_level (1)."},
        {"p-threshold-below-gamma.toml", 24, "block[0].condition[0].procedure.p_threshold", "p_threshold"},
        {"bad-step-type.toml", 23, "block[0].condition[0].procedure.step_type",
         "step_type must be \"db\", \"log\" or \"lin\", not \"log2\"."},
        {"staircase-without-stop-rule.toml", 20, "block[0].condition[0].procedure",
         "the staircase procedure has no stop rule: give n_reversals, n_trials or max_trials."},
        {"quest-without-stop-rule.toml", 16, "defaults.procedure",
         "the quest procedure has no stop rule: give n_trials"},
        {"unquoted-override.toml", 18, "block[0].condition[0].set[1]",
         "the value of 'eye.glare' is not one TOML value (a string needs quotes, as in 'eye.glare=\"wave-optics\"')"},
        {"missing-level-key.toml", 15, "block[0].condition[0].level_key",
         "condition \"c\" (line 15) has no 'level_key', which is required"},
        {"key-conflict.toml", 14, "responses.keys.right",
         "the key \"x\" is bound to both 'left' and 'right', which are used together."},
        {"unknown-key-name.toml", 13, "responses.keys.yes", "\"enterr\" is not a key name. Did you mean 'enter'?"},
        {"missing-scene.toml", 3, "protocol.scene", "the scene file \"no-such-scene.toml\" does not exist"},
        {"negative-seed.toml", 4, "protocol.seed", "seed must be at least 0, got -3."},
        {"no-blocks.toml", 0, "block", "the protocol file has no [[block]], which is required"},
        // Extreme values: each refused where it is read, none reaching an internal error.
        {"duration-two-to-the-31.toml", 13, "timing.stimulus_s",
         "stimulus_s must be at most 86400 s (a day; durations are counted in whole refreshes), got 2147483648."},
        {"duration-1e9.toml", 13, "timing.inter_stimulus_s",
         "inter_stimulus_s must be at most 86400 s (a day; durations are counted in whole refreshes), got 1000000000."},
        {"block-adaptation-1e9.toml", 14, "block[0].adaptation_s", "adaptation_s must be at most 86400 s"},
        {"display-too-wide.toml", 7, "display.width_px", "width_px must be between 1 and 16384, got 16385."},
        {"yes-no-two-interval.toml", 19, "block[0].condition[0].presentation",
         "a yes-no task shows one stimulus: presentation must be \"single\", got \"two-interval\"."},
    };
    const fs::path dir = source_dir() / "tests" / "data" / "protocols";
    std::set<std::string> covered;
    for (const Bad& b : cases) {
        SCOPED_TRACE(b.file);
        covered.insert(b.file);
        const fs::path path = dir / b.file;
        try {
            (void)load_protocol(path);
            ADD_FAILURE() << "no InputError";
        } catch (const atonlab::InputError& e) {
            const std::string what = e.what();
            EXPECT_EQ(e.where()->file, path.string());
            EXPECT_EQ(e.where()->line, b.line) << what;
            EXPECT_EQ(e.where()->key, b.key) << what;
            EXPECT_NE(what.find(b.says), std::string::npos) << what;
            // One sentence: "FILE:LINE: key 'KEY': MESSAGE." on one line, one final period.
            std::string prefix = path.string();
            if (b.line > 0) prefix += ":" + std::to_string(b.line);
            prefix += ": ";
            if (!b.key.empty()) prefix += "key '" + b.key + "': ";
            EXPECT_EQ(what.rfind(prefix, 0), 0u) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
            EXPECT_EQ(what.back(), '.') << what;
        }
    }
    // Every file in the folder is checked here.
    for (const auto& entry : fs::directory_iterator(dir))
        EXPECT_TRUE(covered.count(entry.path().filename().string())) << entry.path() << " has no expectation";
}

TEST(ProtocolErrors, AnUnreadableFileIsOneSentence) {
    try {
        (void)load_protocol("/nonexistent/protocol.toml");
        ADD_FAILURE();
    } catch (const atonlab::InputError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "/nonexistent/protocol.toml: cannot read the protocol file: No such file or directory.");
    }
}

}  // namespace

// ---- Every error at once ------------------------------------------------------------

TEST(ProtocolErrors, FiveErrorsInDifferentPlacesAreAllReportedInFileOrder) {
    // Five mistakes in four tables; the loader reads on past each one. Line
    // numbers count the 9-line header of error_of's protocols.
    const std::string what = error_of(R"(
[timing]
stimulus = 0.5

[defaults]
task = "2afc"
levels = [1.0, 2.0]

[[block]]
name = "b"
repetitions = "two"

[[block.condition]]
name = "c1"
level_key = "light.r.intensity_cd"
procedure = { kind = "staircase", start = 1.0, step_type = "lin", n_reversals = 4, step_size = 0.1 }

[[block.condition]]
name = "c2"
level_key = "light.r.intensity_cd"
procedure = { kind = "constant-stimuli", levels = [50.0, 100.0, 200.0], repetitions = 4 }
)");
    std::vector<std::string> lines;
    for (std::size_t at = 0; at <= what.size();) {
        const std::size_t end = std::min(what.find('\n', at), what.size());
        lines.push_back(what.substr(at, end - at));
        at = end + 1;
    }
    ASSERT_EQ(lines.size(), 5u) << what;
    const std::vector<std::pair<std::string, std::string>> expected = {
        {"inline.toml:12: key 'timing.stimulus'",
         "unknown key 'stimulus' in the [timing] table. Did you mean 'stimulus_s'?"},
        {"inline.toml:16: key 'defaults.levels'", "'levels' belongs in [defaults.procedure]"},
        {"inline.toml:20: key 'block[0].repetitions'", "expected an integer, got a string."},
        {"inline.toml:25: key 'block[0].condition[0].procedure.step_size'", "Did you mean 'step_sizes'?"},
        {"inline.toml:30: key 'block[0].condition[1].procedure.levels'", "These look like linear values"},
    };
    for (std::size_t i = 0; i < expected.size(); ++i) {
        SCOPED_TRACE(i);
        EXPECT_EQ(lines[i].rfind(expected[i].first, 0), 0u) << lines[i];
        EXPECT_NE(lines[i].find(expected[i].second), std::string::npos) << lines[i];
    }
}

TEST(ProtocolErrors, TheFirstErrorKeepsItsFieldsAndTheOthersFollow) {
    try {
        (void)parse(R"(
[timing]
stimulus = 0.5
inter_trial = 1.0

[[block]]
[[block.condition]]
task = "2afc"
level_key = "light.r.intensity_cd"
level_scale = "linear"
procedure = { kind = "staircase", start = -2.0, step_type = "lin", n_reversals = 4 }
)");
        ADD_FAILURE() << "no InputError";
    } catch (const atonlab::InputError& e) {
        EXPECT_EQ(e.where()->line, 12);
        EXPECT_EQ(e.where()->key, "timing.stimulus");
        ASSERT_EQ(e.further().size(), 2u) << e.what();
        EXPECT_EQ(e.further()[0].rfind("inline.toml:13: key 'timing.inter_trial'", 0), 0u) << e.further()[0];
        EXPECT_NE(e.further()[1].find("These look like log10 values"), std::string::npos) << e.further()[1];
    }
}
