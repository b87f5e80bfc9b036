#pragma once
// The display a session shows on, when no measured calibration names it.
#include <filesystem>

#include "atonlab/stimuli/scene.h"
#include "atonlab/store/store.h"

namespace atonlab::runner {

/// The display the session shows on, as a calibration row: the scene's
/// nominal display model (the geometry is the protocol's). Reused when the
/// latest row of that display says the same.
store::CalibrationId record_display(store::Store& store, const stimuli::Scene& scene,
                                    const std::filesystem::path& scene_file);

}  // namespace atonlab::runner
