// A condition whose reference is a scene [[disc]] (reference_disc; docs/protocol-file.md
// "Extended references"): side by side, the disc moves by "disc.NAME.position_m",
// its luminance is the level, the views name it; giving both reference_light and
// reference_disc is refused naming the file, line and key.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "atonlab/protocols/protocol.h"
#include "atonlab/protocols/protocol_file.h"
#include "protocol_file_test_support.h"

using namespace atonlab::protocols;

namespace {

const std::string kProtocol = std::string(protocol_file_test::kHeader) + R"(
[[block]]
[[block.condition]]
name = "glare"
task = "2afc"
presentation = "side-by-side"
test_light = "test"
reference_disc = "plain"
left_position_m = [-1.0, 0.0, -10.0]
right_position_m = [1.0, 0.0, -10.0]
level_key = "disc.plain.luminance_cd_m2"
procedure = { kind = "constant-stimuli", levels = [1.0, 1.5], repetitions = 2 }
)";

bool has(const std::vector<std::string>& v, const std::string& s) {
    return std::find(v.begin(), v.end(), s) != v.end();
}

TEST(ProtocolDisc, SideBySideMovesTheDiscAndSetsItsLuminance) {
    const Protocol p = parse_protocol(kProtocol, "inline.toml");
    const Condition& c = p.blocks[0].conditions[0];
    EXPECT_EQ(c.reference_disc, "plain");
    EXPECT_EQ(c.reference_light, "");
    EXPECT_EQ(c.judged(Role::Reference), "plain");
    Proposal prop;
    prop.level = 1.0;
    prop.test_on_left = true;
    Stimulus s = make_stimulus(p, c, prop);
    ASSERT_EQ(s.frames.size(), 1u);
    EXPECT_TRUE(has(s.frames[0].override_texts(), "light.test.position_m=[-1, 0, -10]"));
    EXPECT_TRUE(has(s.frames[0].override_texts(), "disc.plain.position_m=[1, 0, -10]"));
    EXPECT_TRUE(has(s.frames[0].override_texts(), "disc.plain.luminance_cd_m2=10"));  // 10^1 cd/m²
    ASSERT_EQ(s.views.size(), 2u);
    EXPECT_EQ(s.views[0].light, "test");
    EXPECT_EQ(s.views[1].light, "plain");
    EXPECT_EQ(s.views[1].role, Role::Reference);
    prop.test_on_left = false;
    s = make_stimulus(p, c, prop);
    EXPECT_TRUE(has(s.frames[0].override_texts(), "disc.plain.position_m=[-1, 0, -10]"));
    EXPECT_EQ(s.views[0].light, "plain");
}

TEST(ProtocolDisc, ReferenceLightAndDiscTogetherAreRefused) {
    std::string text = kProtocol;
    text.replace(text.find("reference_disc"), 0, "reference_light = \"white\"\n");
    try {
        (void)parse_protocol(text, "inline.toml");
        FAIL() << "no InputError";
    } catch (const atonlab::InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("inline.toml:18:"), std::string::npos) << what;
        EXPECT_NE(what.find("reference_disc"), std::string::npos) << what;
        EXPECT_NE(what.find("not both"), std::string::npos) << what;
    }
}

}  // namespace
