// The protocol keys of the full-screen runner (docs/protocol-file.md):
// [timing] repeat_missed, max_missed_in_a_row, max_missed_fraction,
// refresh_hz, adaptation_skippable and [screens]
// text_cd_m2, cue_cd_m2, text_size_deg, fixation: their defaults, their
// values, and one-sentence errors at the key's line for a wrong type or range.
#include <gtest/gtest.h>

#include <string>

#include "atonlab/protocols/protocol_file.h"

namespace atonlab::protocols {
namespace {

std::string protocol_with(const std::string& timing, const std::string& screens) {
    return R"([protocol]
scene = "s.toml"
seed = 1

[display]
width_px = 64
height_px = 64
width_m = 0.1
viewing_distance_m = 1.0

[timing]
)" + timing +
           R"(

[screens]
)" + screens +
           R"(

[[block]]
task = "yes-no"
level_key = "light.a.intensity_cd"
procedure = { kind = "quest", t_guess = 1.0, n_trials = 2, gamma = 0.02 }

[[block.condition]]
name = "c"
)";
}

TEST(ProtocolScreenKeys, Defaults) {
    const Protocol p = parse_protocol(protocol_with("", ""), "p.toml");
    EXPECT_FALSE(p.timing.repeat_missed);
    EXPECT_EQ(p.timing.max_missed_in_a_row, 5);  // the issue's defaults
    EXPECT_EQ(p.timing.max_missed_fraction, 0.1);
    EXPECT_FALSE(p.timing.refresh_hz.has_value());
    EXPECT_FALSE(p.timing.adaptation_skippable);
    EXPECT_EQ(p.screens.text_cd_m2, 10.0);
    EXPECT_EQ(p.screens.cue_cd_m2, 1.0);
    EXPECT_EQ(p.screens.text_size_deg, 0.5);
    EXPECT_TRUE(p.screens.fixation);
}

TEST(ProtocolScreenKeys, ValuesAreRead) {
    const Protocol p =
        parse_protocol(protocol_with("repeat_missed = true\nrefresh_hz = 119.88\nadaptation_skippable = true\n"
                                     "max_missed_in_a_row = 3\nmax_missed_fraction = 0.25",
                                     "text_cd_m2 = 25\ncue_cd_m2 = 0.2\ntext_size_deg = 0.8\nfixation = false"),
                       "p.toml");
    EXPECT_TRUE(p.timing.repeat_missed);
    EXPECT_EQ(p.timing.refresh_hz, 119.88);
    EXPECT_EQ(p.timing.max_missed_in_a_row, 3);
    EXPECT_EQ(p.timing.max_missed_fraction, 0.25);
    EXPECT_TRUE(p.timing.adaptation_skippable);
    EXPECT_EQ(p.screens.text_cd_m2, 25.0);
    EXPECT_EQ(p.screens.cue_cd_m2, 0.2);
    EXPECT_EQ(p.screens.text_size_deg, 0.8);
    EXPECT_FALSE(p.screens.fixation);
}

void expect_error(const std::string& timing, const std::string& screens, const std::string& key, int line,
                  const std::string& says) {
    SCOPED_TRACE(key);
    try {
        (void)parse_protocol(protocol_with(timing, screens), "p.toml");
        FAIL() << "accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where()->key, key) << e.what();
        EXPECT_EQ(e.where()->line, line) << e.what();
        EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
}

TEST(ProtocolScreenKeys, WrongValuesAreOneSentenceAtTheirLine) {
    // [timing] is line 11, its first key line 12; [screens] follows two lines after the timing keys.
    expect_error("repeat_missed = \"yes\"", "", "timing.repeat_missed", 12, "expected true or false");
    expect_error("refresh_hz = 0", "", "timing.refresh_hz", 12, "1 to 1000 Hz");
    expect_error("adaptation_skippable = 1", "", "timing.adaptation_skippable", 12, "expected true or false");
    expect_error("repeat_miss = true", "", "timing.repeat_miss", 12, "Did you mean 'repeat_missed'");
    expect_error("max_missed_in_a_row = 0", "", "timing.max_missed_in_a_row", 12, "between 1 and");
    expect_error("max_missed_in_a_row = 2.5", "", "timing.max_missed_in_a_row", 12, "expected an integer");
    expect_error("max_missed_fraction = 0", "", "timing.max_missed_fraction", 12, "above 0 and at most 1");
    expect_error("max_missed_fraction = 1.5", "", "timing.max_missed_fraction", 12, "above 0 and at most 1");
    expect_error("", "text_cd_m2 = -1", "screens.text_cd_m2", 15, "text_cd_m2");
    expect_error("", "cue_cd_m2 = 0", "screens.cue_cd_m2", 15, "cue_cd_m2");
    expect_error("", "text_size_deg = 20", "screens.text_size_deg", 15, "0.05 to 10 degrees");
    expect_error("", "fixation = \"cross\"", "screens.fixation", 15, "expected true or false");
}

}  // namespace
}  // namespace atonlab::protocols
