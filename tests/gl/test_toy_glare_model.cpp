// A glare model from one file (toy_glare_model/toy_disc.cpp, compiled into
// this executable, registered by its one registry line) draws from a scene
// file's keys through the real frame renderer: its name in [eye] glare and
// its own setting in [glare], read, checked and keyed by its declaration
// alone (docs/architecture.md "How to add a glare model").
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "atonlab/common/scene_override.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/scene_file.h"
#include "gl_test_support.h"
#include "input_error.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;

// 320×240 px of a 0.1 m display at 0.9 m (about 50 px per degree), black, one
// 100 cd light 1 km straight ahead (a point: its direct image is one pixel).
Scene toy_scene(std::string_view model, std::string_view glare_keys, const std::vector<SceneOverride>& set = {}) {
    return parse_scene(fmt::format(R"([display]
width_px = 320
height_px = 240
width_m = 0.1
viewing_distance_m = 0.9
[camera]
position_m = [0, 0, 0]
[environment]
background = "uniform"
luminance_cd_m2 = 0
[eye]
adaptation_cd_m2 = 1
glare = "{}"
[glare]
{}
[[light]]
name = "buoy"
position_m = [0, 0, -1000]
intensity_cd = 100
)",
                                   model, glare_keys),
                       "toy.toml", set);
}

class ToyGlareModel : public RendererTest {};

TEST_F(ToyGlareModel, DrawsFromASceneFilesKeysWithItsOwnSetting) {
    ASSERT_TRUE(glare_model_from_name("toy-disc")) << "the toy model's registry line did not run";
    const Scene none = toy_scene("none", "");
    const ImageRGBA32F direct = render(none);
    const double focal_px = renderer->projection().focal_px;
    const double direct_lux = image_illuminance_lux(direct, focal_px);
    // The light's illuminance at 1 km: 100 cd / (1000 m)² (inverse square law).
    EXPECT_NEAR(direct_lux / 1e-4, 1.0, 0.01);
    const double px_per_deg = none.display.pixels_per_degree_at_centre();

    // Rendered with the same renderer one after the other: a setting missing
    // from the kernel cache key would draw the second disc with the first's kernel.
    for (double radius_deg : {0.5, 1.0}) {
        const Scene scene = toy_scene("toy-disc", fmt::format("toy_radius_deg = {}", radius_deg));
        const ImageRGBA32F img = render(scene);
        // Glare moves the light's energy, it neither adds nor loses any (docs/architecture.md "Physical invariants").
        EXPECT_NEAR(image_illuminance_lux(img, focal_px) / direct_lux, 1.0, 0.01) << radius_deg;
        // A uniform disc: lit at 0.8 of its radius, dark at 1.2 (the disc's edge texels are
        // area-weighted, so the test stays a few pixels from the edge: 0.2 × 25 px = 5 px).
        const int cx = img.width / 2, cy = img.height / 2;
        const auto lum = [&](double r_deg) {
            const int x = cx + static_cast<int>(std::lround(r_deg * px_per_deg));
            return img.pixel(x, cy)[1];
        };
        EXPECT_GT(lum(0.8 * radius_deg), 0.0f) << radius_deg;
        EXPECT_EQ(lum(1.2 * radius_deg), 0.0f) << radius_deg;
        // Uniform: the same luminance at a third and at two thirds of the radius, within 2% (its texels' sampling).
        EXPECT_NEAR(lum(radius_deg / 3) / lum(2 * radius_deg / 3), 1.0, 0.02) << radius_deg;
    }
}

TEST(ToyGlareModelKeys, ItsSettingIsCheckedAtItsLineAndRefusedElsewhere) {
    // Its check, from its declaration, at the key's line; its key is [glare]'s and no other table's.
    const std::string what = input_error_of([] { (void)toy_scene("toy-disc", "toy_radius_deg = 9"); });
    EXPECT_NE(what.find("toy.toml:15"), std::string::npos) << what;
    EXPECT_NE(what.find("toy_radius_deg must be between 0 and 5, got 9."), std::string::npos) << what;
    const std::string eye =
        input_error_of([] { (void)toy_scene("toy-disc", "", {SceneOverride::parse("eye.toy_radius_deg=1")}); });
    EXPECT_NE(eye.find("unknown key"), std::string::npos) << eye;
}

}  // namespace
}  // namespace atonlab::test
