// The glare models' declared settings (glare_models/glare_setting.h): each one
// reaches the glare stage's kernel cache key, and reads the same from a scene
// file as from `atonlab glare`'s options and the Python module's keywords.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/common/toml_value.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/scene_file.h"
#include "scene_file_test_support.h"

namespace {

namespace fs = std::filesystem;
using namespace atonlab::stimuli;

constexpr const char* kScene = atonlab::stimuli::scene_file_test::kOneBuoyScene;

// A folder holding aperture.png (aperture_image's example), where the scenes are read from.
class GlareSettingsTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir = fs::temp_directory_path() / fmt::format("atonlab-glare-settings-{}", ::getpid());
        fs::create_directories(dir);
        write_png_rgb8((dir / "aperture.png").string(), 4, 4, std::vector<float>(4 * 4 * 3, 1.0f));
    }
    void TearDown() override { fs::remove_all(dir); }

    // A scene drawn with `model`, with [table] key = value when key is given.
    Scene scene(const GlareModelType& model, const GlareSetting* s = nullptr, std::string_view value = {}) const {
        std::string text = fmt::format("{}[eye]\nglare = \"{}\"\n", kScene, model.name());
        if (s && s->table == GlareTable::eye) text += fmt::format("{} = {}\n", s->key, value);
        text += "[glare]\n";
        if (s && s->table == GlareTable::glare) text += fmt::format("{} = {}\n", s->key, value);
        return parse_scene(text, (dir / "scene.toml").string());
    }
    fs::path dir;
};

TEST_F(GlareSettingsTest, EverySettingOfEveryModelChangesItsKernelsCacheKey) {
    // One setting at a time set to its declared example (a valid value other than the default):
    // the glare stage's cache key changes, so the stage builds a new kernel. A setting that did not
    // reach the key would draw with a stale kernel and no error.
    int settings = 0;
    for (const GlareModelType* m : glare_models()) {
        const Scene plain = scene(*m);
        const std::string plain_key = glare_kernel_key(plain, m->id(), "d65");
        for (const GlareSetting& s : m->settings()) {
            ++settings;
            SCOPED_TRACE(fmt::format("{}: {}.{} = {}", m->name(), glare_table_name(s.table), s.key, s.example));
            ASSERT_FALSE(s.example.empty());
            const Scene changed = scene(*m, &s, s.example);
            EXPECT_NE(glare_setting_text(changed.glare, s), glare_setting_text(plain.glare, s));
            EXPECT_NE(glare_kernel_key(changed, m->id(), "d65"), plain_key);
            // Another model's key does not hold it: its kernels stay cached.
            for (const GlareModelType* other : glare_models()) {
                if (other == m) continue;
                EXPECT_EQ(glare_kernel_key(changed, other->id(), "d65"), glare_kernel_key(plain, other->id(), "d65"))
                    << other->name();
            }
        }
    }
    // wave-optics 27, gaussian-bloom 1, spencer 1, aperture 3, cie 2.
    EXPECT_EQ(settings, 34);
}

TEST_F(GlareSettingsTest, OptionsAndKeywordsReadEverySettingAsTheSceneFileDoes) {
    // apply_glare_settings is `atonlab glare`'s and the Python module's path: the model's own reader.
    for (const GlareModelType* m : glare_models())
        for (const GlareSetting& s : m->settings()) {
            SCOPED_TRACE(fmt::format("{}: {}", m->name(), s.key));
            const Scene file = scene(*m, &s, s.example);
            GlareSettings given;
            given.model = m->id();
            std::string example(s.example);
            if (s.key == "aperture_image") example = fmt::format("\"{}\"", (dir / "aperture.png").string());
            apply_glare_settings({{std::string(s.key), *atonlab::TomlValue::parse(example)}}, given, 4.0);
            EXPECT_EQ(glare_setting_text(given, s), glare_setting_text(file.glare, s));
        }
    GlareSettings g;
    try {
        apply_glare_settings({{"bloom_sigma_deg", *atonlab::TomlValue::parse("-1")}}, g, 4.0);
        ADD_FAILURE() << "a negative sigma was taken";
    } catch (const atonlab::InputError& e) {
        ASSERT_TRUE(e.where());
        EXPECT_EQ(e.where()->key, "bloom_sigma_deg");
        EXPECT_NE(std::string(e.what()).find("greater than 0"), std::string::npos) << e.what();
    }
    EXPECT_THROW(apply_glare_settings({{"no_such_setting", *atonlab::TomlValue::parse("1")}}, g, 4.0),
                 atonlab::InputError);
}

TEST(GlareSettings, DefaultsAreWhatTheModelsDraw) {
    // The declared defaults, read back as the models read them (docs/scene-file.md's default column).
    const GlareSettings g;
    EXPECT_EQ(glare_number(g, "bloom_sigma_deg"), 0.25);
    EXPECT_EQ(glare_text(g, "spencer_vision"), "auto");
    EXPECT_EQ(glare_number(g, "aperture_width_mm"), 18.0);
    EXPECT_FALSE(glare_flag(g, "aperture_with_pupil"));
    EXPECT_EQ(cie_observer(g).age_years, 25.0);
    EXPECT_EQ(cie_observer(g).pigmentation, 0.5);
    EXPECT_THROW((void)glare_text(g, "aperture_image"), atonlab::InputError);  // no default: no image
    EXPECT_EQ(glare_setting_option("bloom_sigma_deg"), "--bloom-sigma-deg");
}

}  // namespace
