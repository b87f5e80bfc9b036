// A conditions file read by the one CSV reader (common/csv.h): RFC 4180 cells
// (quoted commas, doubled quotes, a line break in quotes, CRLF) become the
// condition's values directly, each read once, and its errors keep naming the
// CSV's row and column (docs/protocol-file.md "Conditions files").
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "atonlab/common/input_error.h"
#include "atonlab/protocols/protocol_file.h"
#include "protocol_file_test_support.h"

namespace {

namespace fs = std::filesystem;
using namespace atonlab::protocols;

const std::string kProtocol = std::string(protocol_file_test::kHeader) + R"(
[defaults]
task = "2afc"
level_key = "light.r.intensity_cd"
procedure = { kind = "staircase", start = 1.0, step_sizes = [0.1], step_type = "lin", n_reversals = 4 }

[[block]]
conditions_file = "c.csv"
)";

class ConditionsCsv : public ::testing::Test {
protected:
    void SetUp() override {
        dir = fs::temp_directory_path() / ("atonlab-conditions-csv-" + std::to_string(::getpid()));
        fs::create_directories(dir);
        std::ofstream(dir / "scene.toml") << "";
        std::ofstream(dir / "p.toml") << kProtocol;
    }
    void TearDown() override { fs::remove_all(dir); }
    Protocol load(const std::string& csv) {
        std::ofstream(dir / "c.csv", std::ios::binary) << csv;
        return load_protocol(dir / "p.toml");
    }
    fs::path dir;
};

TEST_F(ConditionsCsv, QuotedCellsCrLfAndALineBreakInQuotesAreRead) {
    const Protocol p = load(
        "name,prompt,procedure.start,light.t.colour,eye.adaptation_cd_m2\r\n"
        "a,\"Which is brighter, left or right?\",1.5,red,0.03\r\n"
        "b,\"Say \"\"left\"\"\nor \"\"right\"\"\",2,\"\"\"green\"\"\",1e-3\r\n"
        "c, plain , 0.5 ,white,0.1\r\n");
    ASSERT_EQ(p.blocks.size(), 1u);
    const auto& c = p.blocks[0].conditions;
    ASSERT_EQ(c.size(), 3u);
    EXPECT_EQ(c[0].prompt, "Which is brighter, left or right?");
    EXPECT_EQ(c[1].prompt, "Say \"left\"\nor \"right\"");
    EXPECT_EQ(c[2].prompt, "plain");  // blanks around an unquoted cell are not its text
    // The overrides' stored form: a cell that is TOML as written, any other text quoted as a TOML string.
    ASSERT_EQ(c[0].set.size(), 2u);
    EXPECT_EQ(c[0].set[0].text(), "light.t.colour=\"red\"");
    EXPECT_EQ(c[0].set[1].text(), "eye.adaptation_cd_m2=0.03");
    EXPECT_EQ(c[1].set[0].text(), "light.t.colour=\"green\"");
    EXPECT_EQ(c[1].set[1].text(), "eye.adaptation_cd_m2=1e-3");
    // Each override's origin is its row (the line it starts on) and column; row b starts on line 3
    // and spans two lines, so row c is on line 5.
    EXPECT_EQ(c[1].set[0].origin.line, 3);
    EXPECT_EQ(c[1].set[0].origin.column, 4);
    EXPECT_EQ(c[2].set[1].origin.line, 5);
    EXPECT_EQ(c[2].set[1].origin.column, 5);
}

TEST_F(ConditionsCsv, AnUnclosedQuoteIsAnErrorAtItsLineAndColumn) {
    try {
        (void)load("name,prompt\na,\"open\nb,x\n");
        ADD_FAILURE() << "no InputError";
    } catch (const atonlab::InputError& e) {
        ASSERT_TRUE(e.where());
        EXPECT_EQ(e.where()->file, (dir / "c.csv").string());
        EXPECT_EQ(e.where()->line, 2);
        EXPECT_EQ(e.where()->column, 3);
        EXPECT_NE(std::string(e.what()).find("never closed"), std::string::npos) << e.what();
    }
}

}  // namespace
