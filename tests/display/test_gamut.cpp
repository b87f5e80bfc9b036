// display.out_of_gamut (gamut.h; docs/tone-mapping.md "Out of gamut: colour or luminance"):
// each choice against hand-worked values, the signal-colour areas' displayable parts against
// the geometry of the COLREGs corners and the Rec.709 primaries as specified, and each
// choice's effect on "adding light never darkens": kept under keep-luminance, bounded under
// the other three.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "atonlab/display/colour.h"
#include "atonlab/display/gamut.h"
#include "atonlab/display/tonemap.h"

namespace atonlab::display {
namespace {

// Rec. ITU-R BT.709-6 primaries as the standard prints them; the luminance weights the
// encoder uses (derived from them: 0.2126, 0.7152, 0.0722 to four decimals).
const glm::dvec2 kRed{0.64, 0.33}, kGreen{0.30, 0.60}, kBlue{0.15, 0.06};
const glm::dvec3 kW{luminance_of_linear_rgb({1, 0, 0}), luminance_of_linear_rgb({0, 1, 0}),
                    luminance_of_linear_rgb({0, 0, 1})};

glm::dvec2 xy_of(glm::dvec3 rgb) {
    const glm::dvec3 xyz = linear_rgb_to_xyz(rgb);
    return glm::dvec2(xyz.x, xyz.y) / (xyz.x + xyz.y + xyz.z);
}

glm::dvec3 rgb_of(glm::dvec2 xy, double y) {
    return xyz_to_linear_rgb(xyY_to_xyz(glm::dvec3(xy, y)));
}

double max_of(glm::dvec3 v) {
    return std::max(v.r, std::max(v.g, v.b));
}

TEST(OutOfGamut, NamesRoundTrip) {
    ASSERT_EQ(out_of_gamut_names().size(), 4u);
    for (const auto& n : out_of_gamut_names()) EXPECT_EQ(out_of_gamut_name(*out_of_gamut_from_name(n)), n);
    EXPECT_EQ(out_of_gamut_name(OutOfGamut::keep_luminance), "keep-luminance");
    EXPECT_FALSE(out_of_gamut_from_name("keep_luminance").has_value());
}

TEST(OutOfGamut, InGamutColoursAreShownAsTheyAreUnderEveryChoice) {
    for (const auto& n : out_of_gamut_names()) {
        const OutOfGamut g = *out_of_gamut_from_name(n);
        EXPECT_EQ(fit_to_gamut({0.3, 1.0, 0.0}, kW, g), glm::dvec3(0.3, 1.0, 0.0)) << n;
        EXPECT_EQ(fit_to_gamut({-1.0, NAN, 0.5}, kW, g), glm::dvec3(0.0, 0.0, 0.5)) << n;
    }
}

TEST(OutOfGamut, ClipChannelsAndKeepChromaticityByHand) {
    EXPECT_EQ(fit_to_gamut({3.0, 0.5, -1.0}, kW, OutOfGamut::clip_channels), glm::dvec3(1.0, 0.5, 0.0));
    EXPECT_EQ(fit_to_gamut({4.0, 2.0, 1.0}, kW, OutOfGamut::keep_chromaticity), glm::dvec3(1.0, 0.5, 0.25));
    const glm::dvec3 c(5.0, 0.0, 0.0);
    EXPECT_EQ(fit_to_gamut(c, kW, OutOfGamut::keep_luminance), fit_to_gamut_keeping_luminance(c, kW));
    EXPECT_EQ(fit_to_gamut(c, kW, OutOfGamut::keep_luminance), glm::dvec3(1.0));  // Y = 1.06 > 1: white
}

// The COLREGs red and yellow areas lie outside the Rec.709 triangle; the point of the
// triangle nearest red's is the red primary, nearest yellow's the foot of the perpendicular
// from yellow's nearest corner onto the red-green edge. Green's area meets the triangle.
TEST(OutOfGamut, DisplayableSignalAreasFollowFromTheCornersAndThePrimaries) {
    const auto& red = displayable_signal_area(SignalColour::red);
    ASSERT_EQ(red.size(), 1u);
    EXPECT_NEAR(red[0].x, kRed.x, 1e-9);
    EXPECT_NEAR(red[0].y, kRed.y, 1e-9);

    // Yellow: distances of the area's corners to the line through R and G.
    const glm::dvec2 d = glm::normalize(kGreen - kRed), n(-d.y, d.x);
    glm::dvec2 nearest(0.0);
    double best = 1e9;
    const std::vector<glm::dvec2> yellow_area = *signal_colour_area("yellow");
    for (const glm::dvec2 c : yellow_area) {
        const double dist = std::abs(glm::dot(c - kRed, n));
        if (dist < best) best = dist, nearest = c;
    }
    const glm::dvec2 foot = nearest - glm::dot(nearest - kRed, n) * n;
    const auto& yellow = displayable_signal_area(SignalColour::yellow);
    ASSERT_EQ(yellow.size(), 1u);
    EXPECT_NEAR(yellow[0].x, foot.x, 1e-9);
    EXPECT_NEAR(yellow[0].y, foot.y, 1e-9);
    EXPECT_NEAR(foot.x, 0.5631, 5e-4);  // worked by hand from (0.575, 0.406)
    EXPECT_NEAR(foot.y, 0.3910, 5e-4);

    // Green: a polygon inside both, holding the IALA green of K2012 table 4.1 (0.28, 0.52).
    const auto& green = displayable_signal_area(SignalColour::green);
    ASSERT_GE(green.size(), 3u);
    const std::vector<glm::dvec2> gamut = {kRed, kGreen, kBlue};
    const std::vector<glm::dvec2> green_area = *signal_colour_area("green");
    for (const glm::dvec2 c : green) {
        EXPECT_LE(glm::length(nearest_point_of_polygon(c, green_area) - c), 1e-9);
        EXPECT_LE(glm::length(nearest_point_of_polygon(c, gamut) - c), 1e-9);
    }
    EXPECT_TRUE(inside_polygon({0.28, 0.52}, green));
    EXPECT_FALSE(inside_polygon(kGreen, green));
}

TEST(OutOfGamut, KeepSignalColourByHand) {
    const OutOfGamut k = OutOfGamut::keep_signal_colour;
    // A red core asked for half the display's white: full red, Y = 0.2126.
    const glm::dvec3 red = fit_to_gamut(rgb_of(kRed, 0.5), kW, k);
    EXPECT_NEAR(glm::length(red - glm::dvec3(1.0, 0.0, 0.0)), 0.0, 1e-12);
    // Pinkish cores (red with some white) are still red's: the red primary.
    for (const glm::dvec3 c : {glm::dvec3(3.0, 0.05, 0.05), glm::dvec3(3.0, 0.2, 0.2)}) {
        const glm::dvec3 pink = fit_to_gamut(c, kW, k);
        EXPECT_NEAR(glm::length(pink - glm::dvec3(1.0, 0.0, 0.0)), 0.0, 1e-12) << c.g;
    }
    // Yellow at white's luminance: the area's nearest displayable point at full drive.
    const glm::dvec3 y = fit_to_gamut(rgb_of({0.5396, 0.4097}, 1.0), kW, k);
    EXPECT_NEAR(max_of(y), 1.0, 1e-12);
    EXPECT_NEAR(y.b, 0.0, 1e-12);
    const glm::dvec2 yxy = xy_of(y), target = displayable_signal_area(SignalColour::yellow)[0];
    EXPECT_NEAR(yxy.x, target.x, 1e-9);
    EXPECT_NEAR(yxy.y, target.y, 1e-9);
    // Green inside its displayable area: its own chromaticity, scaled until it fits.
    const glm::dvec3 g_in = rgb_of({0.28, 0.52}, 1.0);
    const glm::dvec3 g = fit_to_gamut(g_in, kW, k);
    EXPECT_NEAR(glm::length(g - g_in / max_of(g_in)), 0.0, 1e-12);
    // Never brighter than asked: a slightly out-of-gamut red keeps its luminance if it can.
    const glm::dvec3 r = fit_to_gamut(glm::dvec3(1.2, 0.1, 0.1), kW, k);
    EXPECT_LE(glm::dot(kW, r), glm::dot(kW, glm::dvec3(1.2, 0.1, 0.1)) + 1e-12);
    // White and blue (which has no area: white's is nearer) keep their luminance.
    for (const glm::dvec3 c : {glm::dvec3(2.0, 2.0, 1.8), rgb_of(kBlue, 0.5)})
        EXPECT_EQ(fit_to_gamut(c, kW, k), fit_to_gamut_keeping_luminance(c, kW));
}

// Which colour a chromaticity is taken for: the IALA colours of K2012 table 4.1 their own (its
// yellow, (0.5396, 0.4097), lies nearer white's area than yellow's in xy, but in yellow's hue);
// white, near-whites a blueshift or a sky leaves outside white's narrow area, and blue (which has
// no area) white.
TEST(OutOfGamut, EachIalaColourIsTakenForItsOwnSignalColour) {
    EXPECT_EQ(nearest_signal_colour(kRed), SignalColour::red);
    EXPECT_EQ(nearest_signal_colour({0.62, 0.32}), SignalColour::red);  // red-optimum
    EXPECT_EQ(nearest_signal_colour({0.28, 0.52}), SignalColour::green);
    EXPECT_EQ(nearest_signal_colour({0.5396, 0.4097}), SignalColour::yellow);
    EXPECT_EQ(nearest_signal_colour({0.3127, 0.3290}), SignalColour::white);
    EXPECT_EQ(nearest_signal_colour({0.29, 0.34}), SignalColour::white);  // 0.025 from D65
    EXPECT_EQ(nearest_signal_colour({0.30, 0.30}), SignalColour::white);  // the blueshift's xy
    EXPECT_EQ(nearest_signal_colour(kBlue), SignalColour::white);
    EXPECT_EQ(nearest_signal_colour({0.40, 0.20}), SignalColour::white);  // purple: no area within 15°
    // Each coloured area's own corners are its own.
    for (const SignalColour c : {SignalColour::red, SignalColour::green, SignalColour::yellow})
        for (const glm::dvec2 corner : signal_colour_area(c)) EXPECT_EQ(nearest_signal_colour(corner), c);
}

// "Adding light never darkens" under each choice: a grey or bluish sky pixel, a light of every
// IALA colour added at rising levels, through the tone mapper and the choice's fit (what the
// encoder shows, relative to white). keep-luminance keeps the rule exactly. The other three
// can darken where adding a coloured light turns an out-of-gamut pixel more saturated (its
// full-drive luminance falls) or, under keep-signal-colour, moves it from white's side to a
// colour's: they are bounded by the least luminance a colour has at full drive, the blue
// primary's 0.07218 of white (its derived weight), i.e. Y_after >= min(Y_before, 0.07218).
TEST(OutOfGamut, AddingLightDarkensOnlyAsEachChoiceStates) {
    std::vector<ToneMapSettings> settings(3);
    settings[0].tone_operator = ToneOperator::empirical;  // the four-lights scene's (xyY, blueshift)
    settings[0].blueshift_luminance = BlueshiftLuminance::pixel;
    settings[1].tone_operator = ToneOperator::reinhard;
    settings[1].hue_preservation = HuePreservation::none;
    settings[1].blueshift = false;
    settings[2].tone_operator = ToneOperator::clamp;
    settings[2].hue_preservation = HuePreservation::rgb;
    for (const auto& name : out_of_gamut_names()) {
        const OutOfGamut g = *out_of_gamut_from_name(name);
        long darkened = 0, checks = 0;
        double worst_ratio = 1.0;
        for (ToneMapSettings s : settings) {
            s.out_of_gamut = g;
            const auto shown = [&](glm::dvec3 rgb, double la) {
                return glm::dot(kW, fit_to_gamut(tonemap_pixel(rgb, la, s), kW, g));
            };
            for (int a = -3; a <= 3; ++a) {
                const double la = std::pow(10.0, a);
                for (const glm::dvec3 sky : {glm::dvec3(1.0), glm::dvec3(0.8, 0.85, 1.2)}) {
                    for (const double bg : {0.0, 0.1, 1.0, 10.0, 100.0}) {
                        const glm::dvec3 base = sky / glm::dot(kW, sky) * (bg * la);
                        for (const auto& colour : iala_colour_names()) {
                            const glm::dvec3 c = *iala_colour_rgb(colour);
                            double before = shown(base, la);
                            for (int k = -8; k <= 12; ++k) {
                                const double after = shown(base + c * (la * std::pow(10.0, k / 2.0)), la);
                                ++checks;
                                if (after < before - 1e-9) {
                                    ++darkened;
                                    worst_ratio = std::min(worst_ratio, after / before);
                                }
                                if (g == OutOfGamut::keep_luminance) {
                                    EXPECT_GE(after, before - 1e-9) << name << " " << colour;
                                } else {
                                    EXPECT_GE(after, std::min(before, kW.b) - 1e-12) << name << " " << colour;
                                }
                                before = after;
                            }
                        }
                    }
                }
            }
        }
        std::printf("%-18s %ld of %ld steps darken; the worst keeps %.3f of the luminance before\n",
                    std::string(name).c_str(), darkened, checks, worst_ratio);
        if (g == OutOfGamut::keep_luminance) {
            EXPECT_EQ(darkened, 0);
        }
        if (g == OutOfGamut::keep_chromaticity || g == OutOfGamut::clip_channels) {
            EXPECT_GT(darkened, 0) << name << ": the docs say it can darken; the sweep should find where";
        }
    }
}

}  // namespace
}  // namespace atonlab::display
