#pragma once
// What happens to an HDR frame after the lights and the glare (docs/architecture.md
// pipeline steps 4-6): adaptation, tone mapping, display model and encoding.
// Plain settings (no GL), part of a Scene; DisplayPipeline carries them out.
#include <cstdint>

#include "atonlab/display/display_model.h"
#include "atonlab/display/tonemap.h"

namespace atonlab::stimuli {

enum class AdaptationMode : std::uint8_t {
    fixed,    ///< the tone mapper adapts to the eye's level, Scene::adaptation_cd_m2
    dynamic,  ///< log-average of the frame (eq 4.15) + temporal adaptation (eq 4.16-4.17)
};

/// How the tone mapper's adaptation level is found. The level itself is not
/// here: it is the eye's, Scene::adaptation_cd_m2 (one value for the pupil,
/// Spencer's vision class, the image headers and a fixed tone mapper), and
/// DisplayPipeline::process() takes it as an argument. Dynamic adaptation has
/// no starting level: the first frame after DisplayPipeline::reset_adaptation()
/// adopts its own log-average.
struct AdaptationSettings {
    AdaptationMode mode = AdaptationMode::fixed;
    double epsilon_cd_m2 = display::kLogAverageEpsilonCdM2;  ///< ε of eq 4.15 (cd/m²)
    int stride = 1;  ///< dynamic: every stride-th pixel in x and y enters the log-average
};

/// Everything after the HDR frame: how it is adapted, tone-mapped and encoded.
struct OutputSettings {
    AdaptationSettings adaptation;
    display::ToneMapSettings tonemap;
    display::DisplayModel display = display::DisplayModel::srgb(100.0, 0.1);
    display::EncodeSettings encode;
    /// K2012 §6.2.2: glare billboards go to their own buffer, are tone-mapped on
    /// their own and added to a display-referred scene (simulators without HDR).
    bool ldr_glare = false;
};
/// InputError naming the key for an invalid combination (tone-map settings,
/// display model, bits outside 1..16, stride < 1).
void validate_output_settings(const OutputSettings& s);
/// The same, and the adaptation luminance the frames are shown at
/// (Scene::adaptation_cd_m2; key eye.adaptation_cd_m2) a positive finite number.
void validate_output_settings(const OutputSettings& s, double adaptation_cd_m2);

}  // namespace atonlab::stimuli
