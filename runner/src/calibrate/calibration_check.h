#pragma once
// `atonlab calibrate check`: a few grey patches re-measured and compared with
// the display model of the stored calibration, against named tolerances
// (docs/calibration.md, "Checking").
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "atonlab/display/display_model.h"
#include "atonlab/store/records.h"
#include "calibration_patches.h"
#include "photometer_input.h"

namespace atonlab::runner {

/// The tolerances, by the names the check reports and stores.
struct CheckTolerances {
    /// luminance_percent: |measured − predicted| / predicted of every grey patch above black (white included), %.
    double luminance_percent = 5.0;
    /// black_cd_m2: |measured − predicted| of the black patch, cd/m².
    double black_cd_m2 = 0.05;
    /// peak_percent: |measured − predicted| / predicted of the white patch, %.
    double peak_percent = 5.0;
    /// gamma: |effective γ of the readings − effective γ of the model| over the same grey patches.
    double gamma = 0.1;
};

struct CheckPatch {
    Patch patch;
    double predicted_cd_m2 = 0.0;  ///< the calibration's display model at the patch's codes
    PhotometerReading measured;
    double error_cd_m2 = 0.0;    ///< measured − predicted
    double error_percent = 0.0;  ///< 100 (measured − predicted) / predicted (NaN for a prediction of 0)
};

struct CheckOutcome {
    std::vector<CheckPatch> patches;
    double luminance_percent = 0.0;  ///< the largest |error %| over the grey patches above black
    std::string worst_patch;         ///< where it was
    double black_cd_m2 = 0.0;        ///< |error| of black, cd/m²
    double peak_percent = 0.0;       ///< |error %| of white
    double gamma_measured = 0.0;   ///< slope of log10(L − L_black) on log10(drive) over the grey patches above black
    double gamma_predicted = 0.0;  ///< the same slope of the model's predictions
    double gamma = 0.0;            ///< |gamma_measured − gamma_predicted| (NaN when it cannot be computed)
    std::vector<std::string> failed;  ///< the tolerances broken, by name, in the order above
    bool passed() const { return failed.empty(); }
};

/// Compares the readings (one per patch: black, greys, white) with the model.
CheckOutcome evaluate_check(const display::DisplayModel& model, const std::vector<Patch>& patches,
                            const std::vector<PhotometerReading>& readings, const CheckTolerances& tolerances);

/// results_json of the check row (layout in docs/calibration.md).
std::string check_results_json(const CheckOutcome& outcome, const CheckTolerances& tolerances,
                               const store::Calibration& calibration);

/// The per-patch table and the verdict, one line per tolerance.
void print_check(std::FILE* out, const CheckOutcome& outcome, const CheckTolerances& tolerances);

/// Measured against predicted luminance by code value, with the tolerance
/// band, drawn by gnuplot (an .svg, or a .png by extension). Returns "" when
/// written, else why not (gnuplot missing or failing): the check stands without it.
std::string plot_check(const std::filesystem::path& out, const CheckOutcome& outcome, const CheckTolerances& tolerances,
                       const display::DisplayModel& model, const std::string& title);

}  // namespace atonlab::runner
