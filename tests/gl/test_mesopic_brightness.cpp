// Mesopic brightness of coloured lights against CIE 191:2010 (docs/tone-mapping.md "Coloured
// lights at dusk: the displayed brightness against CIE 191"). IALA red, green, yellow and blue
// lights and a white one of equal photopic intensity, 500 m away over a D65 sky at the
// adaptation level (0.001 … 100 cd/m²), rendered with no glare and with the default eye's
// glare, tone-mapped by the empirical and the perceptual operator and encoded for an 8-bit
// sRGB display. The displayed luminance each light adds to the frame (its codes decoded
// through the display model, minus the frame without it, same dither) over white's is the
// displayed ratio. Beside it: the mesopic luminance ratio of the same lights by CIE 191:2010's
// MES2 (display/…/mesopic.h), the adaptation coefficient m of the D65 field at that level, the
// lights' S/P ratios from their representative spectra. Each operator runs with tonemap.mesopic =
// "k2012" (its own rods) and "cie191" (MES2's L_mes of each pixel, m from the field).
//
// What the test holds:
// - the GPU's displayed ratio equals the operator's own prediction from its equations in
//   double (CPU tone_curve with scotopic_luminance_rgb) within 5 % and 0.015 (the light's core
//   stays below the tone curve's knee at these intensities, so the ratio is the curve's slope
//   ratio; a red light at night adds a few code steps);
// - every k2012 ratio lies within a factor 1.5 of CIE 191's, or is one of the deviations the docs
//   explain (explained() below, with the reason): the test fails if one appears or goes;
// - every cie191 ratio lies within a factor 1.1 of CIE 191's across MES2's range 0.005-5 cd/m²
//   (0.01, 0.1, 1 here; the ends 0.005 and 5 and 0.03, 0.3, 3 in Cie191FollowsMes2AcrossItsWholeRange),
//   with and without glare (the rod signal is the frame's scotopic channel, each
//   light's own spectrum);
// - glare changes no light's displayed luminance by more than it changes white's, plus 5 %
//   (glare redistributes light; only the tone curve's non-linearity can change the sum).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "atonlab/display/colour.h"
#include "atonlab/display/display_model.h"
#include "atonlab/display/mesopic.h"
#include "atonlab/display/tonemap.h"
#include "atonlab/stimuli/display_pipeline.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/scene_file.h"
#include "gl_test_support.h"
#include "tonemap_sweep.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

const char* const kColours[] = {"red", "green", "yellow", "blue"};
const double kLevels[] = {0.001, 0.01, 0.1, 1.0, 10.0, 100.0};

// The deviations beyond a factor 1.5 that docs/tone-mapping.md explains, by operator:
// - "empirical" maps photopic luminance alone (K2012 eq 4.18-4.20, after Krawczyk et al. 2005):
//   every coloured light shows white's luminance at every level, so it departs from CIE 191
//   wherever MES2 gives rods weight and the light's S/P is far from white's (below ~1 cd/m²;
//   blue, S/P 19, still at 1 cd/m²).
// - "perceptual" (K2012 eq 4.21-4.26, after Durand & Dorsey 2000) weights rods by the inverse
//   of Ferwerda et al. 1996's threshold-versus-intensity curves, which give rods nearly all
//   the weight below ~0.1 cd/m², where MES2 still gives cones 20-50 % (red at 0.01 and 0.1
//   cd/m²), and cones nearly all of it at 1 cd/m², where MES2 gives rods 21 % (blue). Yellow, whose
//   die rods hardly see (S/P 0.21), follows red at 0.01 and 0.1 cd/m².
// Green and yellow carry their dies' S/P through the frame's scotopic channel (5.38 and 0.21), not
// the display primaries' (1.80 and 0.68), so they are no longer deviations of their own.
bool explained(const std::string& op, const std::string& colour, double level) {
    // op is "<operator> <mesopic model>"; cie191 is held to a factor 1.1 instead.
    if (op.ends_with("cie191")) return false;
    const std::string c = colour;
    if (op.starts_with("empirical")) return level <= 0.1 || (c == "blue" && level == 1.0);
    if (level == 0.01 || level == 0.1) return c == "red" || c == "yellow";
    if (level == 1.0) return c == "blue";
    return false;
}

bool in_mes2_range(double level) {
    return level > kMesopicLowerPhotopicCdM2 && level < kMesopicUpperPhotopicCdM2;
}

double frame_sum_cd_m2(const EncodedImage& codes, const DisplayModel& d) {
    double sum = 0.0;
    for (std::size_t i = 0; i < codes.rgb.size(); i += 3)
        sum += displayed_luminance_cd_m2(d, {codes.rgb[i], codes.rgb[i + 1], codes.rgb[i + 2]}, codes.bits);
    return sum;
}

// The operator's prediction in double: L_d of a pixel of photopic luminance L (cd/m²) of the
// colour, per unit L, in the linear part of the curve (a small L over the sky's).
// Under cie191 the curve sees the field-spectrum luminance of equal L_mes (mesopic_equivalent_cd_m2).
// The rod signal is the frame's scotopic channel: the D65 sky's S/P and the light's own spectrum's.
double predicted_slope(const ToneMapSettings& s, const std::string& colour, double level) {
    const glm::dvec3 sky(level), rgb = *iala_colour_rgb(colour) * (1e-3 * level);
    const double sp_light = scotopic_to_photopic_ratio(*named_spectrum(*iala_colour_spectrum_name(colour)));
    const double v_sky = mesopic_field_s_p_ratio() * level, v = v_sky + sp_light * luminance_of_linear_rgb(rgb);
    if (s.mesopic == MesopicModel::cie191) {
        const double m = mesopic_field_adaptation(level), sp = mesopic_field_s_p_ratio();
        const double l_sky = mesopic_equivalent_cd_m2(level, v_sky, m),
                     l = mesopic_equivalent_cd_m2(level * 1.001, v, m);
        return tone_curve(l, sp * l, level, s) - tone_curve(l_sky, sp * l_sky, level, s);
    }
    return tone_curve(level * 1.001, v, level, s) - tone_curve(level, v_sky, level, s);
}

double cie191_ratio(const std::string& colour, double level) {
    // MES2's m is the visual field's (the D65 sky at the level); each light's mesopic luminance
    // at that m is (m L_p + (1 - m) V'(λ0) L_s) / (m + (1 - m) V'(λ0)), L_s = S/P · L_p.
    const auto sp = [](const std::string& c) {
        return scotopic_to_photopic_ratio(*named_spectrum(*iala_colour_spectrum_name(c)));
    };
    const double m = mesopic_luminance_cd_m2(level, sp("white")).adaptation_m, v0 = 683.0 / 1699.0;
    return (m + (1.0 - m) * v0 * sp(colour)) / (m + (1.0 - m) * v0 * sp("white"));
}

// The displayed luminance (cd/m², summed over the frame) each colour's light adds over the sky
// alone, by "<operator> <mesopic model>" and colour ("white", "red", …). `scale`: a colour's
// intensity over white's (1 where not given).
using AddedByColour = std::map<std::string, std::map<std::string, double>>;
AddedByColour added_by_colour(FrameRenderer& frame, DisplayPipeline& display, const std::string& glare, double level,
                              const std::vector<MesopicModel>& models,
                              const std::map<std::string, double>& scale = {}) {
    // The light's core is about its intensity × 32.8 cd/m² per cd (500 m, 50 px/deg):
    // three times the sky's luminance, inside the tone curves' near-linear part and far
    // above one code step at every level.
    const double intensity = 3.0 * level / 32.8;
    AddedByColour added;
    for (const std::string colour : {"", "white", "red", "green", "yellow", "blue"}) {
        const double i_cd = colour.empty() ? 0.0 : intensity * (scale.contains(colour) ? scale.at(colour) : 1.0);
        const Scene scene = parse_scene(one_light_scene(glare, level, level, colour, i_cd), "mesopic.toml", {});
        frame.render(scene, 0.0);
        for (const ToneOperator op : {ToneOperator::empirical, ToneOperator::perceptual}) {
            for (const MesopicModel mes : models) {
                OutputSettings o = scene.output;
                o.tonemap.tone_operator = op;
                o.tonemap.mesopic = mes;
                display.process(frame.hdr_texture(), o, scene.adaptation_cd_m2, 0.0, 0, frame.pre_exposure(), true);
                const double sum = frame_sum_cd_m2(display.read_codes(), scene.output.display);
                const std::string name =
                    std::string(tone_operator_name(op)) + " " + std::string(mesopic_model_name(mes));
                if (colour.empty())
                    added[name]["sky"] = sum;
                else
                    added[name][colour] = sum - added[name]["sky"];
            }
        }
    }
    return added;
}

using MesopicBrightness = GLTest;

TEST_F(MesopicBrightness, ColouredLightsAgainstWhiteBesideCie191) {
    FrameRenderer frame;
    DisplayPipeline display;
    int unexplained = 0, explained_but_within = 0;
    std::printf(
        "| L_wa (cd/m²) | operator | mesopic | glare | red | green | yellow | blue |\n"
        "|---|---|---|---|---|---|---|---|\n");
    for (const double level : kLevels) {
        std::map<std::string, std::map<std::string, double>> glare_change;   // op -> colour -> with/without
        std::map<std::string, std::map<std::string, double>> without_glare;  // op -> colour -> cd/m² summed
        for (const std::string glare : {"none", "wave-optics"}) {
            const auto added =
                added_by_colour(frame, display, glare, level, {MesopicModel::k2012, MesopicModel::cie191});
            for (const auto& [op, by_colour] : added) {
                char head[96];
                std::snprintf(head, sizeof head, "| %g | %s | %s | %s |", level, op.substr(0, op.find(' ')).c_str(),
                              op.substr(op.find(' ') + 1).c_str(), glare.c_str());
                std::string row = head;
                ToneMapSettings s;
                s.tone_operator = *tone_operator_from_name(op.substr(0, op.find(' ')));
                s.mesopic = *mesopic_model_from_name(op.substr(op.find(' ') + 1));
                const bool cie191 = s.mesopic == MesopicModel::cie191;
                for (const char* colour : kColours) {
                    const double ratio = by_colour.at(colour) / by_colour.at("white");
                    const double cie = cie191_ratio(colour, level);
                    const double predicted = predicted_slope(s, colour, level) / predicted_slope(s, "white", level);
                    // 5 %, and 0.015 of white's added luminance: a red light at night adds 2-5 % of
                    // white's, a few code steps, whose quantisation that is.
                    // Not for empirical under cie191: a light's L_eq is up to 20 times white's there (blue),
                    // where Reinhard's curve already compresses (blue at 1 cd/m²: 2.26 against the slope's
                    // 2.43), so the small-signal slope is no prediction; the MES2 factor 1.1 holds it.
                    if (!(cie191 && s.tone_operator == ToneOperator::empirical)) {
                        EXPECT_NEAR(ratio, predicted, 0.05 * predicted + 0.015)
                            << op << " " << colour << " at " << level << " cd/m2, " << glare << ": displayed " << ratio
                            << ", operator's " << predicted;
                    }
                    if (cie191 && in_mes2_range(level)) {
                        // Issue 43: within a factor 1.1 of MES2, with and without glare.
                        EXPECT_TRUE(ratio / cie <= 1.1 && cie / ratio <= 1.1)
                            << op << " " << colour << " at " << level << " cd/m2 (" << glare << "): displayed " << ratio
                            << " of white, CIE 191 " << cie;
                    }
                    const bool within = ratio / cie <= 1.5 && cie / ratio <= 1.5;
                    if (!within && !cie191 && !explained(op, colour, level)) {
                        ++unexplained;
                        ADD_FAILURE() << op << " " << colour << " at " << level << " cd/m2 (" << glare
                                      << "): displayed " << ratio << " of white, CIE 191 " << cie
                                      << ": not explained in the docs";
                    }
                    // An explanation is stale when the ratio is clearly within (a factor 1.4).
                    if (!cie191 && explained(op, colour, level) && ratio / cie < 1.4 && cie / ratio < 1.4) {
                        ++explained_but_within;
                        ADD_FAILURE() << op << " " << colour << " at " << level << " cd/m2 (" << glare
                                      << "): explained as a deviation, but displayed " << ratio
                                      << " of white against CIE 191 " << cie;
                    }
                    char cell[64];
                    std::snprintf(cell, sizeof cell, " %.3f / %.3f%s |", ratio, cie, within ? "" : " *");
                    row += cell;
                }
                std::printf("%s\n", row.c_str());
                // glare_change: the no-glare sum first, then glare's sum over it.
                for (const char* colour : {"white", "red", "green", "yellow", "blue"}) {
                    double& g = glare_change[op][colour];
                    if (glare == "none") without_glare[op][colour] = by_colour.at(colour);
                    g = glare == "none" ? by_colour.at(colour) : by_colour.at(colour) / g;
                }
            }
        }
        // Glare changes a coloured light's displayed luminance no more than white's, to 5 % (the
        // glare's dim tail is a code step or less over much of the frame). Not judged where the
        // light adds under 0.15 of white's luminance (red, and yellow with its die's S/P 0.21, at
        // night under perceptual: 0.02-0.10 of white's, a few code steps, whose quantisation is
        // 5-30 % of it; measured: yellow at 0.01 cd/m², 0.102 of white's, 0.954 against 1.010), nor for empirical under
        // cie191 at 0.01 cd/m² and below: its key α(L_wa) <= 0.0042 draws the frame within a few codes of the display's
        // black, and a coloured light's halo, now unlike white's, is quantised (measured: green 1.07 and yellow 0.80
        // against white's 1.00 at 0.001 cd/m²); its MES2 factor 1.1 with glare holds at 0.01 cd/m².
        for (const auto& [op, by_colour] : glare_change) {
            if (op == "empirical cie191" && level <= 0.01) continue;
            for (const char* colour : kColours) {
                if (without_glare[op][colour] < 0.15 * without_glare[op]["white"]) continue;
                EXPECT_NEAR(by_colour.at(colour), by_colour.at("white"), 0.05)
                    << op << " " << colour << " at " << level << " cd/m2: glare / no glare " << by_colour.at(colour)
                    << ", white's " << by_colour.at("white");
            }
        }
    }
    EXPECT_EQ(unexplained, 0);
    // An explanation that no longer applies is stale: the docs must follow the table.
    EXPECT_EQ(explained_but_within, 0);
}

// Issue 43: cie191 within a factor 1.1 of MES2 over its whole range, 0.005-5 cd/m² (the ends and
// points between the decades the table shows), with and without glare, for both operators.
// Each coloured light's intensity is white's over its MES2 ratio, so that every light gives the
// tone curve the same mesopic luminance if the renderer follows MES2: all sit at one point of the
// curve, and a red light at 0.005 cd/m² (0.019 of white's L_mes) is not a code step or two over the
// sky but as many as white's. The displayed ratio per candela is then (added / white's) × that
// intensity ratio, and must be MES2's.
TEST_F(MesopicBrightness, Cie191FollowsMes2AcrossItsWholeRange) {
    FrameRenderer frame;
    DisplayPipeline display;
    for (const double level : {kMesopicLowerPhotopicCdM2, 0.03, 0.3, 3.0, kMesopicUpperPhotopicCdM2}) {
        std::map<std::string, double> scale;
        for (const char* colour : kColours) scale[colour] = 1.0 / cie191_ratio(colour, level);
        for (const std::string glare : {"none", "wave-optics"}) {
            for (const auto& [op, by_colour] :
                 added_by_colour(frame, display, glare, level, {MesopicModel::cie191}, scale)) {
                for (const char* colour : kColours) {
                    const double ratio = by_colour.at(colour) / by_colour.at("white") / scale.at(colour),
                                 cie = cie191_ratio(colour, level);
                    std::printf("%g cd/m2 %s %s %s: %.3f / %.3f\n", level, op.c_str(), glare.c_str(), colour, ratio,
                                cie);
                    EXPECT_TRUE(ratio / cie <= 1.1 && cie / ratio <= 1.1)
                        << op << " " << colour << " at " << level << " cd/m2 (" << glare << "): displayed " << ratio
                        << " of white per cd, CIE 191 " << cie;
                }
            }
        }
    }
}
}  // namespace
}  // namespace atonlab::test
