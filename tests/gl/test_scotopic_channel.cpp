// The frame's scotopic channel (docs/tone-mapping.md "The scotopic channel"): the HDR target's alpha holds
// each pixel's scotopic luminance (scotopic cd/m²), S/P of each light's own spectrum times the luminance
// it adds, and the S/P of the sky's spectrum ([environment] spd, D65 by default) times the sky's.
// Expected S/P ratios are summed here from the CIE tables (CIE 1951 V', CIE 1931 ȳ, 1700/683), not
// taken from the code.
//
// - The sky alone (default, d65, led-white): alpha over Y is its spectrum's S/P in every pixel, and the
//   drawn colour its spectrum's chromaticity (CIE 1931 CMFs summed here).
//
// - Over a black sky, a light's alpha over its luminance is its spectrum's S/P, summed over the frame and
//   in every lit pixel, with and without glare (billboards; the `cie` veil takes its RGB weights).
// - A white light over a D65 sky gives the same frames as the RGB weights did (they were built to give
//   D65 its S/P): every displayed code within one step, the window's displayed sum to 1e-4.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "atonlab/display/colour.h"
#include "atonlab/display/display_model.h"
#include "atonlab/display/mesopic.h"
#include "atonlab/stimuli/display_pipeline.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/scene_file.h"
#include "gl_test_support.h"
#include "tonemap_sweep.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

double s_p_from_cie_tables(const Spectrum& spd) {
    double scotopic = 0.0, photopic = 0.0;
    for (int nm = 360; nm <= 830; ++nm) {
        scotopic += spd.at(nm) * cie1951_scotopic_efficiency(nm);
        photopic += spd.at(nm) * cie1931_cmf(nm).y;
    }
    return 1700.0 * scotopic / (683.0 * photopic);
}

double luminance(const float* p) {
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

using ScotopicChannel = GLTest;

TEST_F(ScotopicChannel, EachLightsAlphaIsItsSpectrumsSpTimesItsLuminance) {
    FrameRenderer frame;
    for (const std::string glare : {"none", "wave-optics", "cie"}) {
        for (const std::string colour : {"white", "red", "green", "yellow", "blue"}) {
            const Scene scene = parse_scene(one_light_scene(glare, 0.1, 0.0, colour, 0.05), "sp.toml", {});
            frame.render(scene, 0.0);
            const ImageRGBA32F hdr = frame.read_hdr();
            const double sp_light = s_p_from_cie_tables(*named_spectrum(*iala_colour_spectrum_name(colour)));
            // The cie veil mixes its lights: its scotopic luminance comes from the RGB weights.
            const glm::dvec3 rgb = *iala_colour_rgb(colour);
            const double sp =
                glare == "cie" ? glm::dot(scotopic_weights_rgb(), rgb) / luminance_of_linear_rgb(rgb) : sp_light;
            double sum_y = 0.0, sum_v = 0.0, worst = 0.0;
            for (std::size_t i = 0; i + 3 < hdr.rgba.size(); i += 4) {
                const double y = luminance(&hdr.rgba[i]), v = hdr.rgba[i + 3];
                sum_y += y;
                sum_v += v;
                if (y > 1e-7 && glare != "cie") worst = std::max(worst, std::abs(v / y - sp) / sp);
            }
            std::printf("%-11s %-6s S/P %.4f: alpha/Y summed %.4f, worst pixel %.1e\n", glare.c_str(), colour.c_str(),
                        sp, sum_v / sum_y, worst);
            ASSERT_GT(sum_y, 0.0) << glare << " " << colour;
            // The veil's channels may lose different shares outside the frame: 1e-3 there.
            EXPECT_NEAR(sum_v / sum_y, sp, (glare == "cie" ? 1e-3 : 1e-4) * sp) << glare << " " << colour;
            // fp32 per pixel: the luminance is a sum of three channels, alpha one product.
            EXPECT_LT(worst, 1e-4) << glare << " " << colour;
        }
    }
    // The sky alone: its spectrum's S/P ([environment] spd; D65 by default), and its spectrum's
    // chromaticity (summed here from the CIE 1931 CMFs), in every pixel.
    for (const std::string spd : {"", "d65", "led-white"}) {
        std::vector<SceneOverride> sets;
        if (!spd.empty()) sets.push_back(SceneOverride::parse("environment.spd=\"" + spd + "\""));
        frame.render(parse_scene(one_light_scene("none", 0.1, 0.1, "white", 0.0), "sky.toml", sets), 0.0);
        const ImageRGBA32F sky = frame.read_hdr();
        const Spectrum spectrum = *named_spectrum(spd.empty() ? "d65" : spd);
        const double sp = s_p_from_cie_tables(spectrum);
        glm::dvec3 xyz(0.0);
        for (int nm = 360; nm <= 830; ++nm) xyz += spectrum.at(nm) * glm::dvec3(cie1931_cmf(nm));
        const glm::dvec2 xy(xyz.x / (xyz.x + xyz.y + xyz.z), xyz.y / (xyz.x + xyz.y + xyz.z));
        double worst_sp = 0.0, worst_xy = 0.0;
        for (std::size_t i = 0; i + 3 < sky.rgba.size(); i += 4) {
            const float* p = &sky.rgba[i];
            worst_sp = std::max(worst_sp, std::abs(p[3] / luminance(p) - sp) / sp);
            const glm::dvec3 drawn = linear_rgb_to_xyz(glm::dvec3(p[0], p[1], p[2]));
            const glm::dvec2 drawn_xy = glm::dvec2(drawn) / (drawn.x + drawn.y + drawn.z);
            worst_xy = std::max(worst_xy, glm::length(drawn_xy - xy));
        }
        std::printf("sky %-9s S/P %.4f xy (%.4f, %.4f): alpha/Y worst pixel %.1e, xy worst %.1e\n",
                    spd.empty() ? "(default)" : spd.c_str(), sp, xy.x, xy.y, worst_sp, worst_xy);
        EXPECT_LT(worst_sp, 1e-4) << spd;
        // The CIE tables' D65 lies 3e-5 from Rec.709's rounded white point, which draws it.
        EXPECT_LT(worst_xy, 2e-4) << spd;
    }
}

TEST_F(ScotopicChannel, WhiteLightFramesAreUnchangedByTheChannel) {
    // The RGB weights give D65 white its S/P, so frames of a white (D65) light over a D65 sky differ
    // between the channel and the weights only by rounding (fp32: alpha one product, the weights a dot).
    FrameRenderer frame;
    DisplayPipeline display;
    int worst_code = 0;
    long differing = 0, channels = 0;
    double worst_sum = 0.0;
    for (const std::string glare : {"none", "wave-optics"}) {
        for (const double level : {0.001, 0.01, 0.1, 1.0, 10.0}) {
            const Scene scene =
                parse_scene(one_light_scene(glare, level, level, "white", 3.0 * level / 32.8), "white.toml", {});
            frame.render(scene, 0.0);
            for (const ToneOperator op : {ToneOperator::perceptual, ToneOperator::empirical}) {
                for (const MesopicModel mes : {MesopicModel::k2012, MesopicModel::cie191}) {
                    OutputSettings o = scene.output;
                    o.tonemap.tone_operator = op;
                    o.tonemap.mesopic = mes;
                    EncodedImage codes[2];
                    for (const bool channel : {false, true}) {
                        display.process(frame.hdr_texture(), o, scene.adaptation_cd_m2, 0.0, 0, frame.pre_exposure(),
                                        channel);
                        codes[channel ? 1 : 0] = display.read_codes();
                    }
                    double sums[2] = {0.0, 0.0};
                    for (std::size_t i = 0; i < codes[0].rgb.size(); ++i) {
                        const int d = std::abs(int(codes[0].rgb[i]) - int(codes[1].rgb[i]));
                        worst_code = std::max(worst_code, d);
                        differing += d != 0 ? 1 : 0;
                        ++channels;
                    }
                    for (int k = 0; k < 2; ++k)
                        for (std::size_t i = 0; i < codes[k].rgb.size(); i += 3)
                            sums[k] += displayed_luminance_cd_m2(
                                scene.output.display, {codes[k].rgb[i], codes[k].rgb[i + 1], codes[k].rgb[i + 2]}, 8);
                    worst_sum = std::max(worst_sum, std::abs(sums[1] - sums[0]) / sums[0]);
                }
            }
        }
    }
    std::printf(
        "white light frames, channel against weights: %ld of %ld codes differ, by at most %d; the frame's "
        "displayed sum by at most %.2e of itself\n",
        differing, channels, worst_code, worst_sum);
    EXPECT_LE(worst_code, 1);
    EXPECT_LT(worst_sum, 1e-4);
}

}  // namespace
}  // namespace atonlab::test
