// The scotopic channel's per-light S/P (docs/tone-mapping.md "The scotopic channel"): each light carries
// the S/P of its own spectrum (its `spd`, else its IALA colour's representative die), computed here from
// the CIE tables (CIE 1951 V'(λ) and the CIE 1931 ȳ = V(λ), K'm/Km = 1700/683) by a separate 1 nm sum,
// not by the code's scotopic_to_photopic_ratio.
#include <gtest/gtest.h>

#include <string>

#include "atonlab/display/colour.h"
#include "atonlab/display/mesopic.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/scene_file.h"

namespace atonlab::stimuli {
namespace {

double s_p_from_cie_tables(const display::Spectrum& spd) {
    double scotopic = 0.0, photopic = 0.0;
    for (int nm = 360; nm <= 830; ++nm) {
        const double v = spd.at(nm);
        scotopic += v * display::cie1951_scotopic_efficiency(nm);
        photopic += v * display::cie1931_cmf(nm).y;
    }
    return 1700.0 * scotopic / (683.0 * photopic);
}

Light light_of(const std::string& keys) {
    const std::string text =
        "[display]\nwidth_px = 64\nheight_px = 64\nwidth_m = 0.05\nviewing_distance_m = 0.9\n"
        "[[light]]\nname = \"l\"\nposition_m = [0.0, 0.0, -100.0]\nintensity_cd = 1.0\n" +
        keys;
    return parse_scene(text, "sp.toml", {}).lights.at(0);
}

TEST(ScotopicChannel, EachLightCarriesItsDiesSpFromTheCieTables) {
    // The dies of IALA green (505 nm) and yellow (592 nm): S/P 5.38 and 0.211, against the display
    // primaries' V/Y 1.80 and 0.68 the RGB weights gave them (docs/tone-mapping.md "Scotopic weights").
    struct Case {
        const char* colour;
        double expected_about;
        double within;
    };
    for (const Case c : {Case{"green", 5.38, 0.01}, Case{"yellow", 0.211, 0.001}, Case{"red", 0.047, 0.001},
                         Case{"blue", 19.04, 0.05}, Case{"white", 2.4645, 0.001}}) {
        const Light l = light_of(std::string("colour = \"") + c.colour + "\"\n");
        const double own = s_p_from_cie_tables(*display::named_spectrum(l.spd));
        EXPECT_NEAR(light_s_p_ratio(l), own, 1e-9 * own) << c.colour;
        EXPECT_NEAR(own, c.expected_about, c.within) << c.colour;
    }
    // An explicit spd wins over the colour.
    const Light led = light_of("spd = \"led-green\"\n");
    EXPECT_NEAR(light_s_p_ratio(led), s_p_from_cie_tables(*display::named_spectrum("led-green")), 1e-9);
    // A light without a spectrum (built in code, or given by xy) is seen by the rods through its drawn
    // colour's RGB weights: white is D65's S/P to the weights' rounding, and an xy at the red die's
    // chromaticity has about the die's S/P (0.047), not D65's 2.46.
    EXPECT_NEAR(light_s_p_ratio(Light{}), s_p_from_cie_tables(display::d65_spectrum()), 2e-3);
    const glm::dvec2 red_xy = *display::iala_colour_xy("red");
    const Light red_by_xy = light_of("xy = [" + std::to_string(red_xy.x) + ", " + std::to_string(red_xy.y) + "]\n");
    EXPECT_TRUE(red_by_xy.spd.empty());
    const double red_die = s_p_from_cie_tables(*display::named_spectrum(*display::iala_colour_spectrum_name("red")));
    EXPECT_NEAR(light_s_p_ratio(red_by_xy), red_die, 0.25 * red_die) << "an xy red light's rods";
    EXPECT_NEAR(sky_s_p_ratio(Environment{}), s_p_from_cie_tables(display::d65_spectrum()), 1e-9);
}

Environment environment_of(const std::string& keys) {
    const std::string text =
        "[display]\nwidth_px = 64\nheight_px = 64\nwidth_m = 0.05\nviewing_distance_m = 0.9\n"
        "[environment]\nluminance_cd_m2 = 0.01\n" +
        keys;
    return parse_scene(text, "sky.toml", {}).environment;
}

TEST(ScotopicChannel, TheSkyCarriesItsOwnSpectrumsSp) {
    // Default: D65, drawn in the display's white (1, 1, 1) exactly, so default frames are unchanged.
    const Environment d65 = environment_of("");
    EXPECT_EQ(d65.spd, "d65");
    EXPECT_EQ(d65.rgb_per_cd_m2, glm::dvec3(1.0));
    EXPECT_NEAR(sky_s_p_ratio(d65), s_p_from_cie_tables(display::d65_spectrum()), 1e-9);
    EXPECT_EQ(environment_of("spd = \"d65\"\n").rgb_per_cd_m2, glm::dvec3(1.0));
    // The white LED (a blue pump under a phosphor): its own S/P, 2.04, below D65's 2.46, and its
    // chromaticity, luminance 1 (Rec.709's Y weights, printed to 4 digits), red above blue.
    const Environment led = environment_of("spd = \"led-white\"\n");
    const double own = s_p_from_cie_tables(*display::named_spectrum("led-white"));
    EXPECT_NEAR(sky_s_p_ratio(led), own, 1e-9 * own);
    EXPECT_NEAR(own, 2.04, 0.01);
    EXPECT_NEAR(0.2126 * led.rgb_per_cd_m2.r + 0.7152 * led.rgb_per_cd_m2.g + 0.0722 * led.rgb_per_cd_m2.b, 1.0, 1e-4);
    EXPECT_GT(led.rgb_per_cd_m2.r, led.rgb_per_cd_m2.b);
}

}  // namespace
}  // namespace atonlab::stimuli
