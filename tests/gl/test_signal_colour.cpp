// Coloured lights keep their colour at night (docs/tone-mapping.md, "Colour at
// night: the navigation-light check"): red, green, white and yellow lights of
// 100 cd at 1 nmi, rendered through tone mapping and display encoding, their
// displayed cores decoded through the display model, against the same frame
// with the blueshift off. Each light is judged alone: the frame is black
// around the lights and the eye held at the adaptation level, so the core's
// chromaticity is the light's own rendering, not its mixture with the sky
// (which in daylight would be the sky's). Glare is off here so the core is the
// light's direct image; GL.SignalColour.WithGlare* repeats the Δu′v′ part with
// the wave-optics PSF. Passes at every adaptation level with the
// per-pixel blueshift; the adaptation reading fails in starlight, where it
// turns the coloured lights white (the failure this check exists to catch).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "atonlab/stimuli/display_pipeline.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/scene_file.h"
#include "atonlab/stimuli/signal_colour.h"
#include "gl_test_support.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;

// 480 x 270 px on 0.15 m at 0.9 m: 50 px/deg, the lights 0.62° (31 px) apart.
constexpr const char* kScene = R"(
[display]
width_px = 480
height_px = 270
width_m = 0.15
viewing_distance_m = 0.9

[camera]
position_m = [0.0, 3.0, 0.0]

[environment]
background = "uniform"
luminance_cd_m2 = 0.0

[eye]
adaptation = "fixed"
adaptation_cd_m2 = 1.0
glare = "none"

[glare]
psf_size = 512

[[light]]
name = "red"
position_m = [-30.0, 2.0, -1852.0]
intensity_cd = 100.0
colour = "red"

[[light]]
name = "green"
position_m = [-10.0, 2.0, -1852.0]
intensity_cd = 100.0
colour = "green"

[[light]]
name = "white"
position_m = [10.0, 2.0, -1852.0]
intensity_cd = 100.0
colour = "white"

[[light]]
name = "yellow"
position_m = [30.0, 2.0, -1852.0]
intensity_cd = 100.0
colour = "yellow"
)";

const char* const kColours[] = {"red", "green", "white", "yellow"};

glm::ivec3 code_at(const EncodedImage& codes, int x, int y) {
    const std::size_t i = (static_cast<std::size_t>(y) * codes.width + x) * 3;
    return {codes.rgb[i], codes.rgb[i + 1], codes.rgb[i + 2]};
}

/// XYZ of a light's displayed core: the 3 x 3 pixels around its brightest
/// displayed pixel (searched within 4 px of its projected centre), as emitted
/// (the display's black included: a dim light's weak channel may lie below
/// the black a channel cannot go under, and the black is what shows there).
glm::dvec3 core_xyz(const EncodedImage& codes, const DisplayModel& display, glm::dvec2 centre_px) {
    const int cx = static_cast<int>(centre_px.x), cy = codes.height - 1 - static_cast<int>(centre_px.y);
    int bx = cx, by = cy;
    double best = -1.0;
    for (int y = cy - 4; y <= cy + 4; ++y)
        for (int x = cx - 4; x <= cx + 4; ++x) {
            const double l = displayed_xyz(display, code_at(codes, x, y), codes.bits).y;
            if (l > best) best = l, bx = x, by = y;
        }
    glm::dvec3 sum(0.0);
    for (int y = by - 1; y <= by + 1; ++y)
        for (int x = bx - 1; x <= bx + 1; ++x) sum += displayed_xyz(display, code_at(codes, x, y), codes.bits);
    return sum;
}

using SignalColour = GLTest;

TEST_F(SignalColour, ColouredLightsKeepTheirColourAtEveryAdaptation) {
    FrameRenderer frame;
    DisplayPipeline display;
    int failures_adaptation_reading_starlight = 0;
    for (const double adaptation : {0.001, 0.03, 1.0, 24.0, 1570.0}) {
        const std::string l = std::to_string(adaptation);
        Scene scene = parse_scene(kScene, "signal-colour.toml", {SceneOverride::parse("eye.adaptation_cd_m2=" + l)});
        frame.render(scene, 0.0);
        const std::vector<LightDrawRecord> draws = frame.read_light_draws();
        ASSERT_EQ(draws.size(), 4u);
        for (const ToneOperator op : {ToneOperator::empirical, ToneOperator::perceptual}) {
            // The codes of one tone-mapping setting, dithered as the display
            // shows them (the same pattern for every rendering: frame 0), so the
            // 3 x 3 core averages the quantisation of a dim light out.
            auto codes_with = [&](bool blueshift, BlueshiftLuminance whose) {
                OutputSettings out = scene.output;
                out.tonemap.tone_operator = op;
                out.tonemap.blueshift = blueshift;
                out.tonemap.blueshift_luminance = whose;
                display.process(frame.hdr_texture(), out, 0.0, 0, frame.pre_exposure());
                return display.read_codes();
            };
            const EncodedImage photopic = codes_with(false, BlueshiftLuminance::pixel);
            const EncodedImage per_pixel = codes_with(true, BlueshiftLuminance::pixel);
            const EncodedImage per_adaptation = codes_with(true, BlueshiftLuminance::adaptation);
            const DisplayModel& dm = scene.output.display;
            for (std::size_t i = 0; i < 4; ++i) {
                const glm::dvec3 reference = core_xyz(photopic, dm, draws[i].centre_px);
                const SignalColourCheck c =
                    check_signal_colour(kColours[i], core_xyz(per_pixel, dm, draws[i].centre_px), reference);
                const SignalColourCheck a =
                    check_signal_colour(kColours[i], core_xyz(per_adaptation, dm, draws[i].centre_px), reference);
                std::printf(
                    "L_wa %-7g %-10s %-6s photopic u'v' (%.4f, %.4f): per pixel du'v' %.4f%s, "
                    "adaptation du'v' %.4f%s\n",
                    adaptation, std::string(tone_operator_name(op)).c_str(), kColours[i], c.photopic_uv.x,
                    c.photopic_uv.y, c.delta_uv,
                    c.area_meets_gamut ? (c.inside_area ? " (in area)" : " (OUT of area)") : "", a.delta_uv,
                    a.passes() ? "" : " FAILS");
                EXPECT_TRUE(c.passes()) << kColours[i] << " at " << adaptation << " cd/m2, " << tone_operator_name(op)
                                        << ": du'v' " << c.delta_uv << ", in area " << c.inside_area;
                if (adaptation == 0.001 && std::string(kColours[i]) != "white" && !a.passes())
                    ++failures_adaptation_reading_starlight;
            }
        }
    }
    // The adaptation reading turns the three coloured lights white in
    // starlight, under both operators: the check must see it.
    EXPECT_EQ(failures_adaptation_reading_starlight, 6);
}

}  // namespace
}  // namespace atonlab::test
