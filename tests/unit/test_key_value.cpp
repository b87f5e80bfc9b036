// The one reader of "key=value" (common/scene_override.h read_key_value,
// SceneOverride::parse) and the one reading of an element's override address
// (element_address), which the scene loader and the analysis share.
#include <gtest/gtest.h>

#include <string>

#include "atonlab/common/scene_override.h"

namespace atonlab {
namespace {

TEST(KeyValue, SplitsAtTheFirstEqualsTrimsAndTypesTheValueOnce) {
    const auto kv = read_key_value(" eye.adaptation_cd_m2 = 0.03 ");
    ASSERT_TRUE(kv);
    EXPECT_EQ(kv->key, "eye.adaptation_cd_m2");
    EXPECT_EQ(kv->text, "0.03");
    ASSERT_TRUE(kv->value);
    EXPECT_TRUE(kv->value->node().is_floating_point());
    EXPECT_EQ(*kv->value->node().value<double>(), 0.03);
    EXPECT_TRUE(kv->not_toml.empty());

    // Everything after the first '=' is the value: a string holding '='.
    const auto eq = read_key_value("tonemap.note=\"a=b\"");
    ASSERT_TRUE(eq && eq->value);
    EXPECT_EQ(*eq->value->node().value<std::string>(), "a=b");

    // Integers, booleans, arrays and strings keep their TOML types.
    EXPECT_TRUE(read_key_value("display.width_px=3840")->value->node().is_integer());
    EXPECT_TRUE(read_key_value("tonemap.blueshift=false")->value->node().is_boolean());
    EXPECT_TRUE(read_key_value("light.buoy.position_m=[0, 3, -500]")->value->node().is_array());

    // Text that is not TOML is a string, and says why it is not TOML.
    const auto word = read_key_value("light.buoy.colour=red");
    ASSERT_TRUE(word && word->value);
    EXPECT_EQ(*word->value->node().value<std::string>(), "red");
    EXPECT_FALSE(word->not_toml.empty());

    EXPECT_FALSE(read_key_value("no equals sign"));
    EXPECT_EQ(read_key_value("=1")->key, "");
}

TEST(KeyValue, SceneOverridesReadThroughIt) {
    const SceneOverride o = SceneOverride::parse("light.buoy.intensity_cd = 120");
    EXPECT_EQ(o.key, "light.buoy.intensity_cd");
    EXPECT_EQ(o.value, "120");
    ASSERT_TRUE(o.typed());
    EXPECT_EQ(*o.typed()->node().value<double>(), 120.0);
    EXPECT_EQ(o.text(), "light.buoy.intensity_cd=120");
    EXPECT_THROW((void)SceneOverride::parse("light.buoy.intensity_cd"), InputError);
    EXPECT_THROW((void)SceneOverride::parse(" = 1"), InputError);
}

TEST(KeyValue, ElementAddressesByNameOrIndex) {
    const auto by_name = element_address("light.buoy.colour", "light");
    ASSERT_TRUE(by_name);
    EXPECT_FALSE(by_name->index);
    EXPECT_EQ(by_name->name, "buoy");
    EXPECT_EQ(by_name->key, "colour");
    // A name may hold dots; the key after the last dot never does.
    const auto dotted = element_address("light.pier.head.rhythm", "light");
    ASSERT_TRUE(dotted);
    EXPECT_EQ(dotted->name, "pier.head");
    EXPECT_EQ(dotted->key, "rhythm");
    const auto by_index = element_address("disc[12].luminance_cd_m2", "disc");
    ASSERT_TRUE(by_index && by_index->index);
    EXPECT_EQ(*by_index->index, 12u);
    EXPECT_EQ(by_index->key, "luminance_cd_m2");
    // Not an address of this array, or malformed.
    EXPECT_FALSE(element_address("light.buoy.colour", "disc"));
    EXPECT_FALSE(element_address("eye.glare", "light"));
    EXPECT_FALSE(element_address("light.buoy.", "light"));
    EXPECT_FALSE(element_address("light[x].colour", "light"));
    EXPECT_FALSE(element_address("light[1234567].colour", "light"));
    EXPECT_FALSE(element_address("light[1]colour", "light"));
    EXPECT_FALSE(element_address("light", "light"));
}

}  // namespace
}  // namespace atonlab
