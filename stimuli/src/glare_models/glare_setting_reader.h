#pragma once
// Reading the declared settings of one model from a scene file's table (glare_setting.h).
#include <span>

#include "atonlab/common/toml_reader.h"
#include "atonlab/stimuli/glare_models/glare_setting.h"

namespace atonlab::stimuli {

/// Reads each of `settings` of `table` that is stored in GlareSettings::values
/// (no typed_text) and that s gives: type-checked as its declaration's type,
/// then by its check, failing at the key's line.
void read_declared_settings(const toml_reader::Section& s, GlareTable table, std::span<const GlareSetting> settings,
                            GlareSettings& g);

}  // namespace atonlab::stimuli
