#pragma once
// Measuring the patches with an instrument (docs/calibration.md, "Measuring
// with an instrument"): each patch shown, a settle time, repeat readings that
// must agree (else the patch is measured again, a bounded number of times),
// their mean and standard uncertainty, and every reading's raw transcript.
#include <optional>
#include <vector>

#include "calibration_patches.h"
#include "patch_screen.h"
#include "photometer_input.h"
#include "instrument.h"

namespace atonlab::runner {

/// One reading per patch, in order, each with its uncertainty and transcript;
/// std::nullopt when the operator gave up (Escape or the window closed).
/// Throws InstrumentError naming the patch (an instrument failure, or repeat
/// readings that never agreed).
std::optional<std::vector<PhotometerReading>> measure_with_instrument(const std::vector<Patch>& patches,
                                                                      PatchScreen& screen, Instrument& instrument,
                                                                      const InstrumentOptions& options, bool quiet);

}  // namespace atonlab::runner
