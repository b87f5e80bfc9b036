#pragma once
// The wave-optics model's keys of [glare]: its spectral path and the eye model
// (eye_model.h; docs/scene-file.md "[glare]").
#include <span>
#include <string_view>

#include "atonlab/common/toml_reader.h"
#include "atonlab/stimuli/glare_models/glare_setting.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli::wave_optics {

/// Its settings, declared (glare_setting.h): each one's typed home is the
/// eye model, the spectral path or the anchors of GlareSettings.
std::span<const GlareSetting> settings();

/// Reads them into g (g.psf_size already read) and checks the eye model with
/// the scene's pupil (pupil_mm), failing at the key's line.
void read_keys(const toml_reader::Section& s, GlareSettings& g, double pupil_mm);

}  // namespace atonlab::stimuli::wave_optics
