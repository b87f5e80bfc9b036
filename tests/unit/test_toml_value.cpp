// One TOML value parsed from its text (common/toml_value.h), and the scene
// override that carries it parsed (common/scene_override.h). Expected values
// are written out by hand from the TOML 1.0 grammar.
#include <gtest/gtest.h>

#include <string>

#include "atonlab/common/scene_override.h"
#include "atonlab/common/toml_value.h"

namespace atonlab {
namespace {

TEST(TomlValue, ReadsNumbers) {
    const auto i = TomlValue::parse("120");
    ASSERT_TRUE(i);
    EXPECT_TRUE(i->node().is_integer());
    EXPECT_EQ(i->node().value<std::int64_t>(), 120);
    const auto x = TomlValue::parse("-0.5");
    ASSERT_TRUE(x);
    EXPECT_TRUE(x->node().is_floating_point());
    EXPECT_EQ(x->node().value<double>(), -0.5);
    const auto e = TomlValue::parse("1e-3");
    ASSERT_TRUE(e);
    EXPECT_EQ(e->node().value<double>(), 1e-3);
    const auto inf = TomlValue::parse("inf");
    ASSERT_TRUE(inf);
    EXPECT_EQ(inf->type(), toml::node_type::floating_point);
}

TEST(TomlValue, ReadsStringsAsTomlWritesThem) {
    const auto basic = TomlValue::parse("\"none\"");
    ASSERT_TRUE(basic);
    EXPECT_EQ(basic->node().value<std::string>(), "none");
    const auto literal = TomlValue::parse("'a\\b'");
    ASSERT_TRUE(literal);
    EXPECT_EQ(literal->node().value<std::string>(), "a\\b") << "a literal string keeps its backslash";
    const auto escaped = TomlValue::parse("\"tab\\there\"");
    ASSERT_TRUE(escaped);
    EXPECT_EQ(escaped->node().value<std::string>(), "tab\there");
}

TEST(TomlValue, ReadsBooleans) {
    const auto t = TomlValue::parse("true");
    ASSERT_TRUE(t);
    EXPECT_EQ(t->node().value<bool>(), true);
    const auto f = TomlValue::parse("false");
    ASSERT_TRUE(f);
    EXPECT_EQ(f->node().value<bool>(), false);
    EXPECT_FALSE(TomlValue::parse("True")) << "TOML booleans are lower case";
}

TEST(TomlValue, ReadsArraysNestedArraysAndInlineTables) {
    const auto a = TomlValue::parse("[0.0, 3.0, -500.0]");
    ASSERT_TRUE(a);
    const toml::array* arr = a->node().as_array();
    ASSERT_NE(arr, nullptr);
    ASSERT_EQ(arr->size(), 3u);
    EXPECT_EQ(arr->get(2)->value<double>(), -500.0);

    const auto nested = TomlValue::parse("[[1, 2], [3]]");
    ASSERT_TRUE(nested);
    const toml::array* outer = nested->node().as_array();
    ASSERT_NE(outer, nullptr);
    ASSERT_EQ(outer->size(), 2u);
    ASSERT_TRUE(outer->get(1)->is_array());
    EXPECT_EQ(outer->get(1)->as_array()->get(0)->value<std::int64_t>(), 3);

    const auto table = TomlValue::parse("{ from_deg = 0, to_deg = 90 }");
    ASSERT_TRUE(table);
    ASSERT_TRUE(table->node().is_table());
    EXPECT_EQ(table->node().as_table()->get("to_deg")->value<std::int64_t>(), 90);

    const auto empty = TomlValue::parse("[]");
    ASSERT_TRUE(empty);
    EXPECT_TRUE(empty->node().as_array()->empty());
}

TEST(TomlValue, AllowsBlanksAndACommentAfterTheValue) {
    const auto v = TomlValue::parse("45   # degrees");
    ASSERT_TRUE(v);
    EXPECT_EQ(v->node().value<std::int64_t>(), 45);
}

TEST(TomlValue, RefusesTextThatIsNotOneValue) {
    std::string error;
    EXPECT_FALSE(TomlValue::parse("red", &error)) << "a bare word is not TOML";
    EXPECT_FALSE(error.empty());
    error.clear();
    EXPECT_FALSE(TomlValue::parse("1 2", &error)) << "a value followed by junk";
    EXPECT_FALSE(error.empty());
    error.clear();
    EXPECT_FALSE(TomlValue::parse("", &error)) << "empty text is no value";
    EXPECT_FALSE(error.empty());
    error.clear();
    EXPECT_FALSE(TomlValue::parse("   ", &error));
    error.clear();
    EXPECT_FALSE(TomlValue::parse("[1, 2", &error)) << "an unclosed array";
    EXPECT_FALSE(error.empty());
    error.clear();
    EXPECT_FALSE(TomlValue::parse("1\nw = 2", &error)) << "a second key after the value";
    EXPECT_EQ(error, "more than one value");
    EXPECT_FALSE(TomlValue::parse("\"unterminated"));
    EXPECT_TRUE(TomlValue::parse("1", nullptr)) << "the error is optional";
}

TEST(TomlValue, RefusesControlCharactersAndInvalidUtf8) {
    std::string error;
    EXPECT_FALSE(TomlValue::parse("\"a\x01b\"", &error)) << "a raw control character in a string";
    EXPECT_FALSE(error.empty());
    error.clear();
    EXPECT_FALSE(TomlValue::parse("\"doc\xb0\"", &error)) << "a byte that is not UTF-8";
    EXPECT_FALSE(error.empty());
}

TEST(TomlValue, StringTakesTextAsWritten) {
    const auto s = TomlValue::string("red \"quoted\" back\\slash");
    ASSERT_TRUE(s);
    EXPECT_EQ(s->node().value<std::string>(), "red \"quoted\" back\\slash");
    const auto control = TomlValue::string(std::string("nul\0bell\x07\n", 10));
    ASSERT_TRUE(control) << "control characters are escaped, not refused";
    EXPECT_EQ(control->node().value<std::string>(), std::string("nul\0bell\x07\n", 10));
    const auto empty = TomlValue::string("");
    ASSERT_TRUE(empty);
    EXPECT_EQ(empty->node().value<std::string>(), "");
    std::string error;
    EXPECT_FALSE(TomlValue::string("doc\xb0", &error)) << "no TOML string holds a byte that is not UTF-8";
    EXPECT_FALSE(error.empty());
}

TEST(TomlValue, NodesCarryTheirSourcePath) {
    const auto v = TomlValue::parse("[1, { a = 2 }]", nullptr, "--set light.buoy.sectors");
    ASSERT_TRUE(v);
    const auto& path = v->node().as_array()->get(1)->as_table()->get("a")->source().path;
    ASSERT_TRUE(path);
    EXPECT_EQ(*path, "--set light.buoy.sectors");
}

TEST(TomlValue, CopiesShareTheParsedNode) {
    const auto v = TomlValue::parse("[1, 2]");
    ASSERT_TRUE(v);
    const TomlValue copy = *v;
    EXPECT_EQ(&copy.node(), &v->node());
}

TEST(SceneOverride, ParsesItsValueOnceWhenMade) {
    const SceneOverride o = SceneOverride::parse("camera.yaw_deg = 45");
    ASSERT_NE(o.typed(), nullptr);
    EXPECT_EQ(o.typed()->node().value<std::int64_t>(), 45);
    EXPECT_TRUE(o.not_toml().empty());
    EXPECT_EQ(o.text(), "camera.yaw_deg=45") << "the stored form is the text as written";

    const SceneOverride a{"light.buoy.position_m", "[0.0, 3.0, -500.0]"};
    ASSERT_NE(a.typed(), nullptr);
    EXPECT_TRUE(a.typed()->node().is_array());
    EXPECT_EQ(a.text(), "light.buoy.position_m=[0.0, 3.0, -500.0]");
}

TEST(SceneOverride, TakesTextThatIsNotTomlAsAString) {
    const SceneOverride o = SceneOverride::parse("light.buoy.colour=red");
    ASSERT_NE(o.typed(), nullptr);
    EXPECT_EQ(o.typed()->node().value<std::string>(), "red");
    EXPECT_FALSE(o.not_toml().empty()) << "the loader's note says why it was read as a string";
    EXPECT_TRUE(o.unreadable().empty());
    EXPECT_EQ(o.text(), "light.buoy.colour=red");

    const SceneOverride bad{"light.buoy.colour", "doc\xb0"};
    EXPECT_EQ(bad.typed(), nullptr) << "not even a string";
    EXPECT_FALSE(bad.unreadable().empty());

    const SceneOverride none;
    EXPECT_EQ(none.typed(), nullptr);
}

}  // namespace
}  // namespace atonlab
