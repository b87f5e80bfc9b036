#pragma once
// What the adding-light and mesopic tests sweep (tests/display/test_adding_light.cpp,
// tests/gl/test_adding_light.cpp, tests/gl/test_mesopic_brightness.cpp): every tone operator ×
// hue mode × blueshift setting (off, per pixel, per adaptation) × mesopic model (k2012, cie191), and a scene of one
// light 500 m ahead over a uniform sky on a 160 × 90 px display at 50 px/deg.
#include <string>
#include <vector>

#include "atonlab/display/tonemap.h"

namespace atonlab::test {

/// 6 operators × 3 hue modes × 3 blueshift settings × 2 mesopic models: 108 settings, the other keys at
/// their defaults.
inline std::vector<display::ToneMapSettings> every_tonemap_setting() {
    using namespace atonlab::display;
    std::vector<ToneMapSettings> out;
    for (const ToneOperator op : {ToneOperator::empirical, ToneOperator::perceptual, ToneOperator::reinhard,
                                  ToneOperator::kakimoto, ToneOperator::linear, ToneOperator::clamp}) {
        for (const HuePreservation hue : {HuePreservation::none, HuePreservation::xyY, HuePreservation::rgb}) {
            for (int blue = 0; blue < 3; ++blue) {
                for (const MesopicModel mesopic : {MesopicModel::k2012, MesopicModel::cie191}) {
                    ToneMapSettings s;
                    s.tone_operator = op;
                    s.hue_preservation = hue;
                    s.blueshift = blue != 0;
                    s.blueshift_luminance = blue == 2 ? BlueshiftLuminance::adaptation : BlueshiftLuminance::pixel;
                    s.mesopic = mesopic;
                    out.push_back(s);
                }
            }
        }
    }
    return out;
}

/// One light of `colour` and `intensity_cd` (none when 0) 500 m ahead at eye height over a uniform
/// sky of `sky_cd_m2`, the eye fixed at `adaptation_cd_m2` with `glare`; 160 × 90 px on 0.05 m at
/// 0.9 m (50 px/deg, the light at the centre). 1 cd there puts about 32.8 cd/m² into its pixel.
inline std::string one_light_scene(const std::string& glare, double adaptation_cd_m2, double sky_cd_m2,
                                   const std::string& colour, double intensity_cd) {
    std::string s = R"(
[display]
width_px = 160
height_px = 90
width_m = 0.05
viewing_distance_m = 0.9

[camera]
position_m = [0.0, 2.0, 0.0]

[environment]
background = "uniform"
)";
    s += "luminance_cd_m2 = " + std::to_string(sky_cd_m2) + "\n\n[eye]\nadaptation = \"fixed\"\n";
    s += "adaptation_cd_m2 = " + std::to_string(adaptation_cd_m2) + "\nglare = \"" + glare +
         "\"\n\n[glare]\npsf_size = 256\n";
    if (intensity_cd > 0.0) {
        s += "\n[[light]]\nname = \"light\"\nposition_m = [0.0, 2.0, -500.0]\ncolour = \"" + colour + "\"\n";
        s += "intensity_cd = " + std::to_string(intensity_cd) + "\n";
    }
    return s;
}

}  // namespace atonlab::test
