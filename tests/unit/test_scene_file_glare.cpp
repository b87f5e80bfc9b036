// The scene file's glare: [eye] glare and pupil, the [glare] table, a light's
// own model, the CIE observer and the spectral path, and their errors.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/scene_file.h"
#include "scene_file_test_support.h"

using atonlab::InputError;
using namespace atonlab::stimuli;
using namespace atonlab::display;
using namespace atonlab::stimuli::scene_file_test;  // NOLINT: the shared scenes and readers

namespace {

TEST(SceneFileGlare, ModelsPupilAndTableAreRead) {
    const std::string text = std::string(kMinimal) +
                             "[eye]\nglare = \"spencer\"\npupil_mm = 5.5\n[glare]\nwindow = \"epanechnikov\"\n"
                             "psf_size = 256\nradius_deg = 2.5\nspencer_vision = \"mesopic\"\nclear_pupil = true\nseed = 7\n";
    const Scene scene = parse_scene(text, "glare.toml");
    EXPECT_EQ(scene.glare.model, GlareModel::spencer);
    EXPECT_EQ(scene.glare.pupil_mm, 5.5);
    EXPECT_EQ(scene.glare.window, GlareWindow::epanechnikov);
    EXPECT_EQ(scene.glare.psf_size, 256);
    EXPECT_EQ(scene.glare.radius_deg, 2.5);
    EXPECT_EQ(spencer_vision_for(scene), SpencerVision::mesopic);
    EXPECT_EQ(scene.glare.placement, ComputePlacement::automatic);  // not given
    for (auto [name, want] : {std::pair{"gpu", ComputePlacement::gpu}, std::pair{"cpu", ComputePlacement::cpu},
                              std::pair{"automatic", ComputePlacement::automatic}})
        EXPECT_EQ(parse_scene(std::string(kMinimal) + "[glare]\nplacement = \"" + name + "\"\n", "p.toml").glare.placement,
                  want)
            << name;
    EXPECT_FALSE(scene.glare.eye.gratings.enabled);
    EXPECT_FALSE(scene.glare.eye.halo_radius_deg.has_value());
    EXPECT_EQ(scene.glare.eye.seed, 7u);
    // Every model name round-trips; --set switches glare off.
    for (const char* m : {"none", "wave-optics", "gaussian-bloom", "spencer", "aperture", "cie"})
        EXPECT_EQ(glare_model_name(*glare_model_from_name(m)), m);
}

TEST(SceneFileGlare, EachLightMayGiveItsOwnModel) {
    // Issue 14: [[light]] glare overrides [eye] glare for that light; --set reaches it.
    const std::string text = std::string(kMinimal) +
                             "[eye]\nglare = \"wave-optics\"\n"
                             "[[light]]\nname = \"test\"\nposition_m = [0, 2, -500]\nintensity_cd = 1\n"
                             "[[light]]\nname = \"reference\"\nposition_m = [0, 2, -500]\nintensity_cd = 1\n"
                             "glare = \"none\"\n";
    const Scene s = parse_scene(text, kFile);
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_FALSE(s.lights[0].glare.has_value());
    EXPECT_EQ(light_glare_model(s, s.lights[0]), GlareModel::wave_optics);  // the eye's
    EXPECT_EQ(light_glare_model(s, s.lights[1]), GlareModel::none);         // its own
    EXPECT_TRUE(any_light_glare(s));
    EXPECT_EQ(glare_models_used(s), (std::vector<GlareModel>{GlareModel::wave_optics, GlareModel::none}));
    const Scene set = parse_scene(text, kFile, sets({"light.test.glare=\"cie\"", "light.reference.glare=\"spencer\"",
                                                     "eye.glare=\"none\""}));
    EXPECT_EQ(light_glare_model(set, set.lights[0]), GlareModel::cie);
    EXPECT_EQ(light_glare_model(set, set.lights[1]), GlareModel::spencer);
    EXPECT_EQ(set.glare.model, GlareModel::none);
    EXPECT_EQ(glare_path(GlareModel::none), GlarePath::direct);
    EXPECT_EQ(glare_path(GlareModel::cie), GlarePath::veil);
    EXPECT_EQ(glare_path(GlareModel::spencer), GlarePath::billboard);
    // An unknown model names the light's key and line.
    const std::string bad = with_light("position_m = [0, 2, -100]\nintensity_cd = 1\nglare = \"sparkle\"\n");
    expect_error_at(bad, line_of(bad, "glare = \"sparkle\""), "light[0].glare", "unknown glare model \"sparkle\"");
    // The billboard's width limit holds for a light's own model too (the eye has none).
    // (45° at 126 px per degree: over 11 000 px.)
    const std::string narrow = "[display]\nwidth_px = 800\nheight_px = 600\nwidth_m = 0.1\nviewing_distance_m = 0.9\n"
                               "[glare]\nradius_deg = 45\n";
    const std::string wide =
        narrow + "[[light]]\nposition_m = [0, 2, -100]\nintensity_cd = 1\nglare = \"gaussian-bloom\"\n";
    EXPECT_NE(std::string(error_of(wide).what()).find("the glare billboard is"), std::string::npos);
    EXPECT_NO_THROW(parse_scene(narrow, kFile));
}

TEST(SceneFileGlare, CieModelAndObserverAreRead) {
    const std::string text =
        std::string(kMinimal) + "[eye]\nglare = \"cie\"\ncie_age_years = 62\ncie_pigmentation = 1.0\n";
    const Scene scene = parse_scene(text, "cie.toml");
    EXPECT_EQ(scene.glare.model, GlareModel::cie);
    EXPECT_EQ(cie_observer(scene.glare).age_years, 62.0);
    EXPECT_EQ(cie_observer(scene.glare).pigmentation, 1.0);
    // Defaults: the CIE's 25-year-old, brown eyes (p = 0.5); and --set reaches both keys.
    const Scene plain = parse_scene(std::string(kMinimal), "cie.toml");
    EXPECT_EQ(cie_observer(plain.glare).age_years, 25.0);
    EXPECT_EQ(cie_observer(plain.glare).pigmentation, 0.5);
    const Scene set = parse_scene(text, "cie.toml", sets({"eye.cie_age_years=40", "eye.glare=\"cie\""}));
    EXPECT_EQ(cie_observer(set.glare).age_years, 40.0);
}

TEST(SceneFileGlare, SpectralPathIsRead) {
    EXPECT_EQ(parse_scene(std::string(kMinimal), "s.toml").glare.spectral_path, SpectralPath::anchored);
    const Scene s =
        parse_scene(std::string(kMinimal) + "[glare]\nspectral_path = \"exact\"\nspectral_anchors = 9\n", "s.toml");
    EXPECT_EQ(s.glare.spectral_path, SpectralPath::exact);
    EXPECT_EQ(s.glare.spectral_anchors, 9);
    for (const char* p : {"anchored", "rescaled", "exact"})
        EXPECT_EQ(spectral_path_name(*spectral_path_from_name(p)), p);
    const std::string glare = std::string(kMinimal) + "[glare]\n";
    expect_error_at(glare + "spectral_path = \"fast\"\n", 7, "glare.spectral_path", "unknown spectral path");
    expect_error_at(glare + "spectral_anchors = 0\n", 7, "glare.spectral_anchors", "between");
}

TEST(SceneFileGlare, BadCieObserverNamesFileLineAndKey) {
    const std::string eye = std::string(kMinimal) + "[eye]\nglare = \"cie\"\n";
    expect_error_at(eye + "cie_age_years = -3\n", 8, "eye.cie_age_years", "between 0 and 100");
    expect_error_at(eye + "cie_pigmentation = 2\n", 8, "eye.cie_pigmentation", "between 0 and 1.2");
    // Each within range, together beyond what a positive GSF can conserve.
    expect_error_at(eye + "cie_age_years = 100\ncie_pigmentation = 1.2\n", 8, "eye.cie_age_years",
                    "more than all of it");
    const InputError e = error_of(std::string(kMinimal), sets({"eye.cie_age_years=-1"}));
    EXPECT_EQ(e.where()->option, "--set");
    EXPECT_EQ(e.where()->key, "eye.cie_age_years");
}

TEST(SceneFileGlare, BadGlareInputNamesTheKey) {
    const std::string eye = std::string(kMinimal) + "[eye]\n";
    expect_error_at(eye + "pupil_mm = 0\n", 7, "eye.pupil_mm", "greater than 0");
    expect_error_at(eye + "pupil_mm = -3\n", 7, "eye.pupil_mm", "greater than 0");
    const std::string glare = std::string(kMinimal) + "[glare]\n";
    expect_error_at(glare + "psf_size = 300\n", 7, "glare.psf_size", "power of two");
    expect_error_at(glare + "window = \"box\"\n", 7, "glare.window", "unknown glare window");
    expect_error_at(glare + "placement = \"tpu\"\n", 7, "glare.placement", "\"automatic\", \"gpu\" or \"cpu\"");
    expect_error_at(glare + "spencer_vision = \"owl\"\n", 7, "glare.spencer_vision", "unknown vision");
    expect_error_at(glare + "aperture_image = \"no-such-lashes.png\"\n", 7, "glare.aperture_image", "does not exist");
    expect_error_at(glare + "grating_count = -1\n", 7, "glare.grating_count", "between");
    // The old key names the new one; a defocus the grid cannot sample says why, at its line.
    expect_error_at(glare + "fresnel_distance_mm = 24\n", 7, "glare.fresnel_distance_mm", "defocus_diopters");
    expect_error_at(glare + "defocus_diopters = -30\n", 7, "glare.defocus_diopters", "more than π between texels");
    expect_error_at(glare + "eye_preset = \"k2013\"\n", 7, "glare.eye_preset", "unknown eye preset");
    // The limit is the scene's pupil's: λ0 N / (p W) = 2.04 D at 8 mm and N = 512, 4.09 D at 4 mm.
    const std::string three_d = "[glare]\ndefocus_diopters = 3\n";
    expect_error_at(std::string(kMinimal) + "[eye]\npupil_mm = 8\n" + three_d, 9, "glare.defocus_diopters",
                    "at most ±2.04 D");
    EXPECT_DOUBLE_EQ(parse_scene(std::string(kMinimal) + "[eye]\npupil_mm = 4\n" + three_d, kFile)
                         .glare.eye.defocus_diopters,
                     3.0);
    const Scene k2012 = parse_scene(glare + "eye_preset = \"k2012\"\nseed = 7\n", kFile);
    EXPECT_EQ(k2012.glare.eye.scale, EyeScale::k2012_single);
    EXPECT_DOUBLE_EQ(k2012.glare.eye.defocus_diopters, 0.2);
    EXPECT_EQ(k2012.glare.eye.seed, 7u);  // the preset first, then the keys
    expect_error_at(glare + "sparkle = 1\n", 7, "glare.sparkle", "unknown key");
}

}  // namespace
