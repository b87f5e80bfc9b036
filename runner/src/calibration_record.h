#pragma once
// A display calibration as the study file keeps it (docs/calibration.md):
// the GOG fit of calibration.h written to calibrations.fit_json, the readings
// behind it, the display's geometry; and back again, the DisplayModel a
// session encodes for.
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/stimuli/calibration.h"
#include "atonlab/stimuli/display_model.h"
#include "atonlab/store/store.h"

namespace atonlab::runner {

/// The display's size, resolution and viewing distance.
struct DisplayGeometry {
    int width_px = 0;
    int height_px = 0;
    double width_m = 0.0;   ///< visible picture width, metres
    double height_m = 0.0;  ///< visible picture height, metres
    double viewing_distance_m = 0.0;

    /// Pixels per degree of visual angle at the screen's centre: one pixel of
    /// pitch p = width_m / width_px subtends 2 atan(p / 2d) there.
    double pixels_per_degree() const;
    /// "1920 x 1080 px, 0.598 x 0.336 m at 0.9 m: 42.1 px/deg at the centre".
    std::string describe() const;
};

/// fit_json of a measured or imported calibration (its layout is in
/// docs/calibration.md): model "gog", the per-ramp fits, measured black,
/// white and contrast, pixels per degree, and under "display" the three GOG
/// channels of the DisplayModel that sessions encode for. `method` is
/// "measured" or "imported".
std::string measured_fit_json(const stimuli::CalibrationReport& report, const stimuli::DisplayModel& model,
                              const DisplayGeometry& geometry, std::string_view method);

/// True when the calibration holds a measured GOG fit (measured_fit_json), not
/// the nominal model that `atonlab run` records for an uncalibrated display.
bool is_measured(const store::Calibration& calibration);

/// The DisplayModel of a measured calibration (named after its display),
/// validated. Throws InputError naming the calibration when it is not one.
stimuli::DisplayModel display_model_of(const store::Calibration& calibration);

/// The display's latest measured calibration (nominal rows skipped).
std::optional<store::Calibration> latest_measured_calibration(const store::Store& store, std::string_view display);

/// The readings of an imported file, as the store keeps them (patch names
/// "grey-0.502", source lines, X and Z when the file has them).
std::vector<store::CalibrationReading> readings_from_measurements(const std::vector<stimuli::Measurement>& ms);

/// The fit in a few lines: per ramp γ (GOG), effective γ, black, peak, RMSE;
/// the measured black, white and contrast ratio; the geometry.
void print_fit_summary(std::FILE* out, const stimuli::CalibrationReport& report, const stimuli::DisplayModel& model,
                       const DisplayGeometry& geometry);

}  // namespace atonlab::runner
