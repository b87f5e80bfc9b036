#pragma once
// A display calibration as the study file keeps it (docs/calibration.md):
// the readings behind it, and the DisplayModel a session encodes for read back
// from calibrations.fit_json (written and read by atonlab/display/fit_json.h).
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/display/calibration.h"
#include "atonlab/display/display_model.h"
#include "atonlab/display/fit_json.h"
#include "atonlab/display/geometry.h"
#include "atonlab/store/store.h"

namespace atonlab::runner {

/// True when the calibration holds a measured GOG fit (display::measured_fit_json), not
/// the nominal model that `atonlab run` records for an uncalibrated display.
bool is_measured(const store::Calibration& calibration);

/// The DisplayModel of a measured calibration (named after its display),
/// validated. Throws InputError naming the calibration when it is not one.
display::DisplayModel display_model_of(const store::Calibration& calibration);

/// The display's latest measured calibration (nominal rows skipped).
std::optional<store::Calibration> latest_measured_calibration(const store::Store& store, std::string_view display);

/// The readings of an imported file, as the store keeps them (patch names
/// "grey-0.502", source lines, X and Z when the file has them).
std::vector<store::CalibrationReading> readings_from_measurements(const std::vector<display::Measurement>& ms);

/// The fit in a few lines: per ramp γ (GOG), effective γ, black, peak, RMSE;
/// the measured black, white and contrast ratio; the geometry.
void print_fit_summary(std::FILE* out, const display::CalibrationReport& report, const display::DisplayModel& model,
                       const display::DisplayGeometry& geometry);

}  // namespace atonlab::runner
