// Conditions files (CSV beside the protocol): the same schedule as the TOML
// twin, errors at the CSV's row and column, the stored text parsing without
// the CSV; and every frame's overrides carrying where they were written.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "protocol_file_test_support.h"

namespace {

using namespace atonlab::protocols;                      // NOLINT: the test exercises the whole namespace
using namespace atonlab::protocols::protocol_file_test;  // NOLINT: the shared examples and readers
namespace fs = std::filesystem;

}  // namespace

// ---- Conditions files ------------------------------------------------------------------

TEST(ConditionsFile, TheCsvExampleGivesTheSameScheduleAsItsTomlTwin) {
    const Protocol toml = load_protocol(example("glare_brightness_2afc.toml"));
    const Protocol csv = load_protocol(example("glare_brightness_2afc_csv.toml"));
    ASSERT_EQ(csv.blocks.size(), toml.blocks.size());
    for (std::size_t b = 0; b < toml.blocks.size(); ++b) {
        ASSERT_EQ(csv.blocks[b].conditions.size(), toml.blocks[b].conditions.size());
        for (std::size_t c = 0; c < toml.blocks[b].conditions.size(); ++c)
            EXPECT_EQ(csv.blocks[b].conditions[c].name, toml.blocks[b].conditions[c].name);
    }
    // The same trials, stimuli and procedure states on the same answers, seed for seed.
    for (const std::uint64_t seed : {toml.seed, std::uint64_t{99}}) {
        SCOPED_TRACE(seed);
        Schedule a(toml, seed), b(csv, seed);
        Rng rng(3);
        std::size_t n = 0;
        while (true) {
            const auto ta = a.next();
            const auto tb = b.next();
            ASSERT_EQ(ta.has_value(), tb.has_value());
            if (!ta) break;
            ASSERT_EQ(ta->procedure_id, tb->procedure_id) << "trial " << n;
            EXPECT_EQ(ta->proposal.level, tb->proposal.level);
            EXPECT_EQ(ta->proposal.test_on_left, tb->proposal.test_on_left);
            ASSERT_EQ(ta->stimulus.frames.size(), tb->stimulus.frames.size());
            for (std::size_t f = 0; f < ta->stimulus.frames.size(); ++f) {
                EXPECT_EQ(ta->stimulus.frames[f].override_texts(), tb->stimulus.frames[f].override_texts())
                    << "trial " << n;
            }
            EXPECT_EQ(a.state(), b.state());
            const Response r = random_response(ta->task, rng);
            a.record(r);
            b.record(r);
            ++n;
        }
        EXPECT_GT(n, 100u);
    }
}

TEST(ConditionsFile, ErrorsNameTheCsvFileRowAndColumn) {
    const fs::path dir = fs::temp_directory_path() / "atonlab-conditions-file-test";
    fs::create_directories(dir);
    {
        std::ofstream(dir / "scene.toml") << "";
        std::ofstream(dir / "c.csv") << "name,procedure.start,eye.adaptation_cd_m2,level_scale\n"
                                        "a,1.0,0.1,log10\n"
                                        "b,\"[1.0, x]\",0.1,log10\n"
                                        "c,1.0,0.1,logarithmic\n";
        std::ofstream(dir / "p.toml") << std::string(kHeader) + R"(
[defaults]
task = "2afc"
level_key = "light.r.intensity_cd"
procedure = { kind = "staircase", step_sizes = [0.1], step_type = "lin", n_reversals = 4 }

[[block]]
conditions_file = "c.csv"
)";
    }
    try {
        (void)load_protocol(dir / "p.toml");
        ADD_FAILURE() << "no InputError";
    } catch (const atonlab::InputError& e) {
        const std::string csv = (dir / "c.csv").string();
        EXPECT_EQ(e.where()->file, csv) << e.what();
        EXPECT_EQ(e.where()->line, 3) << e.what();
        ASSERT_EQ(e.further().size(), 1u) << e.what();
        EXPECT_EQ(e.further()[0].rfind(csv + ":4: column 4 'level_scale': ", 0), 0u) << e.further()[0];
    }
    {
        std::ofstream(dir / "c.csv") << "name,procedure.strat\n"
                                        "a,1.0\n";
    }
    try {
        (void)load_protocol(dir / "p.toml");
        ADD_FAILURE() << "no InputError";
    } catch (const atonlab::InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind((dir / "c.csv").string() + ":2: column 2 'procedure.strat': ", 0), 0u)
            << e.what();
    }
    {
        std::ofstream(dir / "c.csv") << "name,colour\n"
                                        "a,red\n";
    }
    try {
        (void)load_protocol(dir / "p.toml");
        ADD_FAILURE() << "no InputError";
    } catch (const atonlab::InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind((dir / "c.csv").string() + ":1: column 2 'colour': not a column", 0), 0u)
            << e.what();
    }
    fs::remove_all(dir);
}

// Every override of a frame carries where it was written (the scene loader
// names a refused value there): a condition's own at its string's line and
// column, the display at its [display] lines, the level and the side-by-side
// positions (which the protocol makes) at the condition's line, and a
// conditions file's at its row and column.
TEST(ProtocolOverrides, EachFramesOverridesCarryWhereTheyWereWritten) {
    const std::string body = R"(
[[block]]
name = "b"

[[block.condition]]
name = "glare"
task = "2afc"
presentation = "side-by-side"
test_light = "t"
reference_light = "r"
left_position_m = [-1, 0, -10]
right_position_m = [1, 0, -10]
level_key = "light.r.intensity_cd"
set = ["eye.glare=\"none\"", "eye.adaptation_cd_m2=0.01"]
procedure = { kind = "staircase", start = 1.0, step_sizes = [0.1], step_type = "lin", n_reversals = 4 }
)";
    const std::string text = std::string(kHeader) + body;
    const Protocol p = parse(body);
    const Condition& c = p.blocks[0].conditions[0];
    const Stimulus s = make_stimulus(p, c, Proposal{1.0, true});
    ASSERT_EQ(s.frames.size(), 1u);
    const auto line = [&](const std::string& needle) {
        const auto at = text.find(needle);
        EXPECT_NE(at, std::string::npos) << needle;
        return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
    };
    std::map<std::string, atonlab::SourceLocation> origin;
    for (const atonlab::SceneOverride& o : s.frames[0].overrides) origin[o.key] = o.origin;
    for (const char* key : {"width_px", "height_px", "width_m", "viewing_distance_m"}) {
        const atonlab::SourceLocation& w = origin["display." + std::string(key)];
        EXPECT_EQ(w.file, "inline.toml") << key;
        EXPECT_EQ(w.line, line(std::string(key) + " = ")) << key;
    }
    const atonlab::SourceLocation& glare = origin["eye.glare"];
    EXPECT_EQ(glare.file, "inline.toml");
    EXPECT_EQ(glare.line, line("set = [\"eye.glare"));
    EXPECT_EQ(glare.column, static_cast<int>(std::string("set = [").size()) + 1);
    EXPECT_EQ(glare.key, "block[0].condition[0].set[0]");
    EXPECT_EQ(origin["eye.adaptation_cd_m2"].key, "block[0].condition[0].set[1]");
    EXPECT_GT(origin["eye.adaptation_cd_m2"].column, glare.column);
    for (const char* made : {"light.r.intensity_cd", "light.t.position_m", "light.r.position_m"}) {
        EXPECT_EQ(origin[made].file, "inline.toml") << made;
        EXPECT_EQ(origin[made].line, c.line) << made;
        EXPECT_FALSE(origin[made].from_command_line()) << made;
    }
    EXPECT_EQ(c.line, line("[[block.condition]]"));

    // A conditions file's override: its CSV row and column.
    const fs::path dir = fs::temp_directory_path() / "atonlab-override-origin-test";
    fs::create_directories(dir);
    {
        std::ofstream(dir / "scene.toml") << "";
        std::ofstream(dir / "c.csv") << "name,eye.adaptation_cd_m2\n"
                                        "a,0.1\n";
        std::ofstream(dir / "p.toml") << std::string(kHeader) + R"(
[defaults]
task = "2afc"
level_key = "light.r.intensity_cd"
procedure = { kind = "staircase", start = 1.0, step_sizes = [0.1], step_type = "lin", n_reversals = 4 }

[[block]]
conditions_file = "c.csv"
)";
    }
    const Protocol from_csv = load_protocol(dir / "p.toml");
    const std::vector<atonlab::SceneOverride>& set = from_csv.blocks.at(0).conditions.at(0).set;
    ASSERT_EQ(set.size(), 1u);
    EXPECT_EQ(set[0].origin.file, (dir / "c.csv").string());
    EXPECT_EQ(set[0].origin.line, 2);
    EXPECT_EQ(set[0].origin.column, 2);
    fs::remove_all(dir);
}

TEST(ConditionsFile, TheStoredTextCarriesTheCsvSoThatItParsesWithoutIt) {
    const fs::path file = example("glare_brightness_2afc_csv.toml");
    std::ifstream in(file);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string stored = with_conditions_files(text, file);
    EXPECT_NE(stored.find("\n#@conditions_file glare_brightness_2afc.conditions.csv\n#@|block,name,"),
              std::string::npos);
    // Parsed from the text alone (no such folder: the CSV cannot be opened), as analyze does.
    const Protocol p = parse_protocol(stored, "/nonexistent/glare_brightness_2afc_csv.toml");
    const Protocol twin = load_protocol(example("glare_brightness_2afc.toml"));
    ASSERT_EQ(p.blocks.size(), twin.blocks.size());
    for (std::size_t b = 0; b < p.blocks.size(); ++b) {
        ASSERT_EQ(p.blocks[b].conditions.size(), twin.blocks[b].conditions.size());
        for (std::size_t c = 0; c < p.blocks[b].conditions.size(); ++c) {
            std::vector<std::string> a, t;
            for (const atonlab::SceneOverride& o : p.blocks[b].conditions[c].set) a.push_back(o.text());
            for (const atonlab::SceneOverride& o : twin.blocks[b].conditions[c].set) t.push_back(o.text());
            EXPECT_EQ(a, t);
        }
    }
    // A protocol without a conditions file is stored as it is.
    const std::string plain = "[protocol]\nscene = \"s.toml\"\n";
    EXPECT_EQ(with_conditions_files(plain, "p.toml"), plain);
    // Without the CSV and without the stored copy, the error names the key.
    try {
        (void)parse_protocol(text, "/nonexistent/glare_brightness_2afc_csv.toml");
        ADD_FAILURE() << "no InputError";
    } catch (const atonlab::InputError& e) {
        EXPECT_EQ(e.where()->key, "block[0].conditions_file") << e.what();
        EXPECT_NE(std::string(e.what()).find("cannot read the conditions file"), std::string::npos) << e.what();
    }
}
