#pragma once
// Shows a list of patches and collects one photometer reading for each: from
// a readings file, or typed by the operator on the terminal (or into the
// patch window) with re-entry on a typo, r to show a patch again, b to go
// back one patch and q to give up (docs/calibration.md, "Measuring").
#include <optional>
#include <vector>

#include "calibration_patches.h"
#include "patch_screen.h"
#include "photometer_input.h"

namespace atonlab::runner {

struct PatchSessionOptions {
    /// The readings, one per patch, when they come from a file; none: typed.
    std::optional<std::vector<PhotometerReading>> scripted;
    /// With scripted readings: how long each patch stays up, s (a logging meter's
    /// integration time); 0 shows each for one frame.
    double patch_seconds = 0.0;
    /// Typed readings: a reading more than this fraction below the reading of a
    /// lower level of the same ramp must be typed twice (a typo guard; the
    /// tolerance of display::check_monotonic).
    double typo_tolerance = 0.05;
    bool quiet = false;  ///< scripted: no line per patch
};

/// One reading per patch, in order; std::nullopt when the operator gave up
/// (q, Escape or the window closed, or the terminal's input ended).
std::optional<std::vector<PhotometerReading>> collect_readings(const std::vector<Patch>& patches, PatchScreen& screen,
                                                               const PatchSessionOptions& options);

}  // namespace atonlab::runner
