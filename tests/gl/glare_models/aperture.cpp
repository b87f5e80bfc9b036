// The `aperture` glare model in a frame (stimuli/src/glare_models/aperture.cpp):
// a hand-made obstacle image diffracts into the streak its bar makes, the
// frame keeps the light's illuminance, and a missing image is refused naming
// its key. The GlareFrames fixture: tests/support/glare_frames.h.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/psf_generator.h"
#include "glare_frames.h"
#include "input_error.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;

TEST_F(GlareFrames, ApertureImageGivesItsDiffractionPattern) {
    // A hand-made obstacle: a clear disc crossed by one opaque bar, as a PNG.
    const int w = 64;
    std::vector<float> rgb(static_cast<std::size_t>(w) * w * 3, 0.0f);
    for (int y = 0; y < w; ++y)
        for (int x = 0; x < w; ++x) {
            const bool open = std::hypot(x - 31.5, y - 31.5) < 12.0 && std::abs(y - 31.5) > 2.0;
            for (int c = 0; c < 3; ++c) rgb[(static_cast<std::size_t>(y) * w + x) * 3 + c] = open ? 1.0f : 0.0f;
        }
    const auto dir = std::filesystem::temp_directory_path() / "atonlab_glare_test";
    std::filesystem::create_directories(dir);
    write_png_rgb8(dir / "bar.png", w, w, rgb);
    Scene scene = black_scene(GlareModel::aperture);
    scene.glare.values["aperture_image"] = (dir / "bar.png").string();
    scene.lights = {light_at({0.0, 0.0, -500.0})};
    EXPECT_NEAR(energy(scene) / (100.0 / 250000.0), 1.0, 0.01);
    ASSERT_NE(renderer->glare().psf(0), nullptr);
    // The bar (horizontal in the image) diffracts into a vertical streak: more energy along y than along x.
    const RgbPsf& p = *renderer->glare().psf(0);
    double along_x = 0, along_y = 0;
    for (int k = 10; k < 60; ++k) {
        along_x += p.at(p.n / 2 + k, p.n / 2).g;
        along_y += p.at(p.n / 2, p.n / 2 + k).g;
    }
    EXPECT_GT(along_y, 2 * along_x);
    scene.glare.values["aperture_image"] = (dir / "missing.png").string();
    EXPECT_NE(input_error_of([&] { renderer->render(scene, 0.0); }).find("aperture_image"), std::string::npos);
}

}  // namespace
}  // namespace atonlab::test
