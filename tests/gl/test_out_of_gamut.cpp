// display.out_of_gamut = "keep-signal-colour" on the GPU path (docs/tone-mapping.md "Out of
// gamut: colour or luminance"): scenes/tonemap-four-lights.toml (four 100 cd lights at 100 m,
// the thesis's empirical operator with xyY hue preservation and the blueshift, the eye's
// wave-optics glare), sky and adaptation together at 0.001, 0.1 and 10 cd/m². Each coloured
// core's displayed chromaticity (its codes decoded through the display model, the display's
// black included) lies inside its COLREGs area as far as the Rec.709 primaries allow: inside
// green's, and for red and yellow, whose areas the triangle does not meet, no farther from
// the area than the triangle's nearest point, to 0.01 in xy. Under the default
// (keep-luminance) the same cores are drawn near white: that is printed, not required.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "atonlab/display/gamut.h"
#include "atonlab/stimuli/display_pipeline.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/scene_file.h"
#include "atonlab/stimuli/signal_colour.h"
#include "gl_test_support.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;
using OutOfGamutFrames = GLTest;

glm::ivec3 code_at(const EncodedImage& codes, glm::dvec2 centre_px) {
    const int x = static_cast<int>(centre_px.x), y = codes.height - 1 - static_cast<int>(centre_px.y);
    const std::size_t i = (static_cast<std::size_t>(y) * codes.width + x) * 3;
    return {codes.rgb[i], codes.rgb[i + 1], codes.rgb[i + 2]};
}

double distance_to_area(glm::dvec2 xy, const std::vector<glm::dvec2>& area) {
    return glm::length(nearest_point_of_polygon(xy, area) - xy);
}

TEST_F(OutOfGamutFrames, KeepSignalColourPutsEachColouredCoreInItsArea) {
    const std::string file = std::string(ATONLAB_SOURCE_DIR) + "/scenes/tonemap-four-lights.toml";
    const char* const names[] = {"white", "red", "green", "yellow"};  // the scene's order
    FrameRenderer frame;
    DisplayPipeline display;
    for (const double level : {0.001, 0.1, 10.0}) {
        const std::string l = std::to_string(level);
        const Scene scene = load_scene(file, {SceneOverride::parse("display.width_px=480"),
                                              SceneOverride::parse("display.height_px=270"),
                                              SceneOverride::parse("environment.luminance_cd_m2=" + l),
                                              SceneOverride::parse("eye.adaptation_cd_m2=" + l)});
        frame.render(scene, 0.0);
        const std::vector<LightDrawRecord> draws = frame.read_light_draws();
        ASSERT_EQ(draws.size(), 4u);
        for (const OutOfGamut choice : {OutOfGamut::keep_luminance, OutOfGamut::keep_signal_colour}) {
            OutputSettings out = scene.output;
            out.encode.out_of_gamut = choice;
            out.tonemap.out_of_gamut = choice;
            display.process(frame.hdr_texture(), out, scene.adaptation_cd_m2, 0.0, 0, frame.pre_exposure());
            const EncodedImage codes = display.read_codes();
            for (std::size_t i = 1; i < 4; ++i) {
                const glm::ivec3 code = code_at(codes, draws[i].centre_px);
                const glm::dvec3 xyz = displayed_xyz(out.display, code, codes.bits);
                const glm::dvec2 xy = glm::dvec2(xyz.x, xyz.y) / (xyz.x + xyz.y + xyz.z);
                const std::vector<glm::dvec2> area = *signal_colour_area(names[i]);
                // As far as the primaries allow: the displayable part's distance from the area.
                const SignalColour c = static_cast<SignalColour>(i);
                const double allowed = distance_to_area(displayable_signal_area(c).front(), area);
                const double d = distance_to_area(xy, area);
                std::printf("%-18s %6g cd/m2 %-6s codes (%3d, %3d, %3d) xy (%.4f, %.4f): %.4f from its area "
                            "(the display's nearest %.4f)\n",
                            std::string(out_of_gamut_name(choice)).c_str(), level, names[i], code.r, code.g, code.b,
                            xy.x, xy.y, d, allowed);
                if (choice == OutOfGamut::keep_signal_colour) {
                    EXPECT_LE(d, allowed + 0.01) << names[i] << " at " << level << " cd/m2";
                }
            }
        }
    }
}

}  // namespace
}  // namespace atonlab::test
