#pragma once
// `atonlab calibrate list` and `atonlab calibrate show --display NAME`
// (docs/calibration.md, "Listing and drift"): what a study file or the lab's
// display-profile file holds, read-only.
#include "calibrate_command.h"

namespace atonlab::runner {

/// Every display with its calibrations (date, source, geometry, peak, black,
/// γ) and the latest check of each. Exit 0; 2 when the file does not exist.
int run_list(const CalibrateOptions& options);

/// One display: its calibrations and every check over time (the drift table),
/// and with --plot the drift figure. Exit 0; 2 for an unknown display.
int run_show(const CalibrateOptions& options);

}  // namespace atonlab::runner
