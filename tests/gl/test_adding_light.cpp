// Adding light never darkens, on the GPU path (docs/tone-mapping.md "Adding light never
// darkens"; the CPU reference's sweep is tests/display/test_adding_light.cpp): a red, a
// green and a white light 500 m away over a uniform night-to-day sky, rendered by the
// FrameRenderer with no glare and with the default eye's glare, then tone-mapped and
// encoded by the DisplayPipeline for every operator × blueshift reading × hue mode × mesopic
// model on an
// 8-bit display. Against the same frame without the light (same dither frame), every
// pixel of the 41 × 41 window around the light shows at least its displayed luminance
// (decoded through the display model), to within one code step of each channel (a channel
// whose drive falls as the chroma turns may round down alone: see the CPU test), the
// window's sum is at least the sky's and does not fall as the light brightens (to within
// 0.75 of a code step of each pixel the light changes). The suite's bounded form checks each
// setting in a third of the scenes (every setting and every scene still checked, the
// settings of a scene rotating with it); ATONLAB_LONG_TESTS=1 checks every setting in
// every scene.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "atonlab/display/display_model.h"
#include "atonlab/stimuli/display_pipeline.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/scene_file.h"
#include "gl_test_support.h"
#include "long_tests.h"
#include "tonemap_sweep.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

constexpr int kHalf = 20;  // the window: 41 × 41 px around the light's centre

struct Window {
    std::vector<double> pixel_cd_m2, step_cd_m2;
    double sum_cd_m2 = 0.0;
};

Window window_of(const EncodedImage& codes, const DisplayModel& d) {
    Window w;
    const int max_code = (1 << codes.bits) - 1;
    for (int y = codes.height / 2 - kHalf; y <= codes.height / 2 + kHalf; ++y) {
        for (int x = codes.width / 2 - kHalf; x <= codes.width / 2 + kHalf; ++x) {
            const std::size_t i = (static_cast<std::size_t>(y) * codes.width + x) * 3;
            const glm::ivec3 c(codes.rgb[i], codes.rgb[i + 1], codes.rgb[i + 2]);
            const double l = displayed_luminance_cd_m2(d, c, codes.bits);
            double step = 0.0;
            for (int k = 0; k < 3; ++k)
                step += d.channel_luminance_cd_m2(k, std::min(c[k] + 1, max_code) / double(max_code)) -
                        d.channel_luminance_cd_m2(k, c[k] / double(max_code));
            w.pixel_cd_m2.push_back(l);
            w.step_cd_m2.push_back(step);
            w.sum_cd_m2 += l;
        }
    }
    return w;
}

using AddingLight = GLTest;

TEST_F(AddingLight, NeverLowersTheDisplayedLuminanceOfARenderedFrame) {
    FrameRenderer frame;
    DisplayPipeline display;
    const std::vector<ToneMapSettings> settings = every_tonemap_setting();
    long checks = 0, failures = 0;
    int scene_index = 0;
    for (const std::string glare : {"none", "wave-optics"}) {
        for (const double adaptation : {0.001, 0.1, 10.0, 1000.0}) {
            for (const double sky_factor : {0.0, 1.0, 10.0}) {
                const double sky = sky_factor * adaptation;
                const int this_scene = scene_index++;
                auto checked = [&](std::size_t k) { return long_tests() || (k + this_scene) % 3 == 0; };
                // Codes of every setting for one scene, dither frame 0.
                auto codes_of = [&](const std::string& text) {
                    const Scene scene = parse_scene(text, "adding-light.toml", {});
                    frame.render(scene, 0.0);
                    std::vector<Window> out;
                    for (std::size_t k = 0; k < settings.size(); ++k) {
                        if (!checked(k)) {
                            out.emplace_back();
                            continue;
                        }
                        const ToneMapSettings& s = settings[k];
                        OutputSettings o = scene.output;
                        o.tonemap.tone_operator = s.tone_operator;
                        o.tonemap.hue_preservation = s.hue_preservation;
                        o.tonemap.blueshift = s.blueshift;
                        o.tonemap.blueshift_luminance = s.blueshift_luminance;
                        o.tonemap.mesopic = s.mesopic;
                        // The frame's scotopic channel, as the pipeline uses it (pipeline.cpp).
                        display.process(frame.hdr_texture(), o, scene.adaptation_cd_m2, 0.0, 0, frame.pre_exposure(),
                                        true);
                        out.push_back(window_of(display.read_codes(), scene.output.display));
                    }
                    return out;
                };
                const std::vector<Window> without = codes_of(one_light_scene(glare, adaptation, sky, "white", 0.0));
                for (const std::string colour : {"red", "green", "white"}) {
                    // 1 cd at 500 m puts 4e-6 lx into a pixel of (1/50)° squared, 1.22e-7 sr:
                    // 32.8 cd/m². Intensities put the core at about 0.1, 10 and 1000 times the
                    // adaptation (less where the light's footprint spreads it).
                    std::vector<Window> previous = without;
                    for (const double core_factor : {0.1, 10.0, 1000.0}) {
                        const double intensity = core_factor * adaptation / 32.8;
                        const std::vector<Window> with = codes_of(one_light_scene(glare, adaptation, sky, colour, intensity));
                        for (std::size_t k = 0; k < settings.size(); ++k) {
                            if (!checked(k)) continue;
                            const ToneMapSettings& s = settings[k];
                            for (const Window* reference : {&without[k], static_cast<const Window*>(&previous[k])}) {
                                ++checks;
                                double changed_steps = 0.0;
                                bool ok = true;
                                for (std::size_t i = 0; i < with[k].pixel_cd_m2.size(); ++i) {
                                    const double step = std::max(with[k].step_cd_m2[i], reference->step_cd_m2[i]);
                                    if (with[k].pixel_cd_m2[i] != reference->pixel_cd_m2[i]) changed_steps += step;
                                    ok = ok && reference->pixel_cd_m2[i] - with[k].pixel_cd_m2[i] <= step * (1.0 + 1e-9);
                                }
                                // The sum: to within 0.75 of a code step of each pixel the light changes
                                // (a light that turns a pixel's chroma may round one channel down by a
                                // step while the others' rise is still below one, in each of the few
                                // pixels a faint light touches: green, 0.7152 of a grey step, at most;
                                // measured 0.69 of one pixel's step, a red light adding 10 % of a
                                // 0.001 cd/m² sky under cie191; the reported failure was 4-6 codes in
                                // every channel of the core).
                                ok = ok && reference->sum_cd_m2 - with[k].sum_cd_m2 <= 0.75 * changed_steps;
                                if (!ok && failures++ < 8) {
                                    ADD_FAILURE()
                                        << colour << " light, glare " << glare << ", L_wa " << adaptation << ", sky "
                                        << sky << ", core x" << core_factor << ", "
                                        << tone_operator_name(s.tone_operator) << " hue "
                                        << hue_preservation_name(s.hue_preservation) << " blueshift " << s.blueshift
                                        << "/" << blueshift_luminance_name(s.blueshift_luminance) << " mesopic "
                                        << mesopic_model_name(s.mesopic) << ": window " << with[k].sum_cd_m2
                                        << " against " << reference->sum_cd_m2
                                        << " cd/m2 (summed; the changed pixels' code steps " << changed_steps << ")";
                                }
                            }
                        }
                        previous = with;
                    }
                }
            }
        }
    }
    std::printf("%ld window comparisons, %ld failures\n", checks, failures);
    EXPECT_EQ(failures, 0);
}

}  // namespace
}  // namespace atonlab::test
