// The cie191 mesopic variant of the tone mapper (tonemap.mesopic = "cie191"; docs/tone-mapping.md
// "The mesopic variant"). Expected values come from CIE 191:2010's MES2 equations solved here, with the
// light's S/P from its representative spectrum through CIE S 010's V' and V (mesopic.h), not from the
// tone mapper: a pixel of the field's spectrum is drawn exactly as under k2012, and the displayed
// luminance of coloured pixels of equal photopic luminance stands in MES2's ratio of their L_mes.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "atonlab/display/colour.h"
#include "atonlab/display/mesopic.h"
#include "atonlab/display/tonemap.h"

namespace atonlab::display {
namespace {

constexpr ToneOperator kOperators[] = {ToneOperator::empirical, ToneOperator::perceptual, ToneOperator::reinhard,
                                       ToneOperator::kakimoto,  ToneOperator::linear,     ToneOperator::clamp};

double sp_of(const std::string& colour) {
    return scotopic_to_photopic_ratio(*named_spectrum(*iala_colour_spectrum_name(colour)));
}

// MES2's L_mes at a given m, CIE 191:2010 (V'(λ0) = 683/1699), for L_s = S/P · L_p.
double l_mes(double m, double lp, double sp) {
    const double v0 = 683.0 / 1699.0;
    return (m * lp + (1.0 - m) * v0 * sp * lp) / (m + (1.0 - m) * v0);
}

TEST(MesopicVariant, NamesRoundTrip) {
    EXPECT_EQ(mesopic_model_name(MesopicModel::k2012), "k2012");
    EXPECT_EQ(mesopic_model_name(MesopicModel::cie191), "cie191");
    EXPECT_EQ(mesopic_model_from_name("cie191"), MesopicModel::cie191);
    EXPECT_EQ(mesopic_model_from_name("k2012"), MesopicModel::k2012);
    EXPECT_FALSE(mesopic_model_from_name("mes2"));
    EXPECT_EQ(ToneMapSettings{}.mesopic, MesopicModel::k2012);  // the default is today's
}

TEST(MesopicVariant, FieldAdaptationIsMes2sOfD65) {
    // The field is D65 (S/P 2.4645); m follows the standard's own solution and its range ends.
    EXPECT_NEAR(mesopic_field_s_p_ratio(), 2.4645, 5e-4);
    for (const double l : {0.01, 0.03, 0.1, 0.3, 1.0, 3.0})
        EXPECT_NEAR(mesopic_field_adaptation(l), mesopic_luminance_cd_m2(l, 2.4645).adaptation_m, 1e-4) << l;
    EXPECT_EQ(mesopic_field_adaptation(0.001), 0.0);
    EXPECT_EQ(mesopic_field_adaptation(0.005), 0.0);
    EXPECT_EQ(mesopic_field_adaptation(5.0), 1.0);
    EXPECT_EQ(mesopic_field_adaptation(100.0), 1.0);
}

TEST(MesopicVariant, EquivalentLuminanceIsLinearAndKeepsTheField) {
    const double sp = mesopic_field_s_p_ratio();
    for (const double m : {0.0, 0.2, 0.6, 1.0}) {
        // A field-spectrum pixel: L_eq = L_p.
        EXPECT_NEAR(mesopic_equivalent_cd_m2(0.7, sp * 0.7, m), 0.7, 1e-14) << m;
        // Linear with non-negative weights: the sum of two is the sum of their L_eq, and more never less.
        const double a = mesopic_equivalent_cd_m2(0.2, 0.01, m), b = mesopic_equivalent_cd_m2(0.05, 3.0, m);
        EXPECT_NEAR(mesopic_equivalent_cd_m2(0.25, 3.01, m), a + b, 1e-14) << m;
        EXPECT_GE(mesopic_equivalent_cd_m2(0.2, 0.02, m), a) << m;
        EXPECT_GE(mesopic_equivalent_cd_m2(0.3, 0.01, m), a) << m;
    }
    // Photopic (m = 1): L_p alone; scotopic (m = 0): L_s / S/P_field.
    EXPECT_DOUBLE_EQ(mesopic_equivalent_cd_m2(0.3, 9.0, 1.0), 0.3);
    EXPECT_NEAR(mesopic_equivalent_cd_m2(0.3, 9.0, 0.0), 9.0 / sp, 1e-14);
}

TEST(MesopicVariant, D65PixelsAreDrawnAsUnderK2012ByEveryOperator) {
    // A field-spectrum pixel has L_eq = L_p, so every operator draws it as k2012 does.
    for (const ToneOperator op : kOperators) {
        ToneMapSettings k, c;
        k.tone_operator = c.tone_operator = op;
        c.mesopic = MesopicModel::cie191;
        for (const double lwa : {1e-4, 0.003, 0.02, 0.3, 2.0, 40.0}) {
            for (const double factor : {0.01, 0.5, 1.0, 3.0, 100.0}) {
                const glm::dvec3 px(lwa * factor);
                const glm::dvec3 a = tonemap_pixel(px, lwa, k), b = tonemap_pixel(px, lwa, c);
                for (int ch = 0; ch < 3; ++ch)
                    EXPECT_NEAR(b[ch], a[ch], 1e-9 * std::max(1.0, a[ch]))
                        << tone_operator_name(op) << " L_wa " << lwa << " x" << factor;
            }
        }
    }
}

TEST(MesopicVariant, DisplayedLuminanceStandsInMes2sRatios) {
    // The perceptual curve is linear in its input at a fixed adaptation, so with the blueshift off the
    // displayed luminance of a red or blue IALA light (drawn in one primary, whose scotopic weight is its
    // spectrum's S/P) over white's of equal photopic luminance is MES2's L_mes ratio at the field's m.
    ToneMapSettings s;
    s.tone_operator = ToneOperator::perceptual;
    s.blueshift = false;
    s.mesopic = MesopicModel::cie191;
    const double sp_white = sp_of("white");
    for (const double lwa : {0.001, 0.01, 0.1, 1.0, 10.0}) {
        const double m = lwa <= 0.005 ? 0.0 : lwa >= 5.0 ? 1.0 : mesopic_luminance_cd_m2(lwa, sp_white).adaptation_m;
        const double lp = 0.1 * lwa;  // well below display white
        const double white = luminance_of_linear_rgb(tonemap_pixel(glm::dvec3(lp), lwa, s));
        for (const std::string colour : {"red", "blue"}) {
            const glm::dvec3 rgb = *iala_colour_rgb(colour) / luminance_of_linear_rgb(*iala_colour_rgb(colour)) * lp;
            const double shown = luminance_of_linear_rgb(tonemap_pixel(rgb, lwa, s));
            const double want = l_mes(m, lp, sp_of(colour)) / l_mes(m, lp, sp_white);
            EXPECT_NEAR(shown / white, want, 1e-6 * want) << colour << " at " << lwa;
        }
    }
}

TEST(MesopicVariant, TheRodSignalIsThePixelsScotopicLuminanceWhenGiven) {
    // tonemap_pixel(rgb, V, ...) takes V as the rod signal (the frame's scotopic channel); without V
    // it is the RGB weights' V. With V = the weights' V the two agree; a green pixel carrying its
    // die's S/P (5.38 per cd/m²) is drawn brighter at night than with the drawn chromaticity's weights.
    const glm::dvec3 green = *iala_colour_rgb("green") / luminance_of_linear_rgb(*iala_colour_rgb("green")) * 0.003;
    for (const MesopicModel mes : {MesopicModel::k2012, MesopicModel::cie191}) {
        ToneMapSettings s;
        s.tone_operator = ToneOperator::perceptual;
        s.mesopic = mes;
        const glm::dvec3 a = tonemap_pixel(green, 0.01, s),
                         b = tonemap_pixel(green, scotopic_luminance_rgb(green), 0.01, s);
        for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(a[c], b[c]) << mesopic_model_name(mes);
        const double die = luminance_of_linear_rgb(tonemap_pixel(green, sp_of("green") * 0.003, 0.01, s));
        EXPECT_GT(die, 1.5 * luminance_of_linear_rgb(a)) << mesopic_model_name(mes);
        // NaN and negative V count as 0.
        EXPECT_EQ(tonemap_pixel(green, std::nan(""), 0.01, s), tonemap_pixel(green, 0.0, 0.01, s));
        EXPECT_EQ(tonemap_pixel(green, -1.0, 0.01, s), tonemap_pixel(green, 0.0, 0.01, s));
    }
}

}  // namespace
}  // namespace atonlab::display
