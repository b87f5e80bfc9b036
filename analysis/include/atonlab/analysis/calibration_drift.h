#pragma once
// A display's drift: every `atonlab calibrate check` of its calibrations over
// time (docs/calibration.md, "Drift"), read from the checks' results_json, as
// a table and a gnuplot figure: peak (white), black, effective gamma and the
// worst grey patch's error against the date, with each check's tolerance band
// shaded. Used by `atonlab calibrate show` (display-profile or study file) and
// by the analysis report (the copies a study file holds).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/store/store.h"

namespace atonlab::analysis {

/// One check, as results_json stores it (docs/calibration.md, "Checking").
/// A value results_json does not hold (or holds as null) is NaN.
struct DriftPoint {
    std::int64_t check_id = 0;
    std::int64_t calibration_id = 0;  ///< the calibration checked (row id in the file read)
    std::string checked_at;           ///< ISO 8601 date or date-time
    std::string calibration_measured_at;
    bool passed = false;
    std::vector<std::string> failed;  ///< the tolerances broken, by name
    double peak_cd_m2 = 0.0;          ///< white measured, cd/m²
    double peak_predicted_cd_m2 = 0.0;
    double black_cd_m2 = 0.0;  ///< black measured, cd/m²
    double black_predicted_cd_m2 = 0.0;
    double gamma_measured = 0.0;  ///< effective γ of the grey readings
    double gamma_predicted = 0.0;
    double worst_error_percent = 0.0;  ///< the largest |error %| of a grey patch above black
    std::string worst_patch;
    // The tolerances the check used.
    double tol_luminance_percent = 0.0, tol_black_cd_m2 = 0.0, tol_peak_percent = 0.0, tol_gamma = 0.0;
};

/// The check's values; std::nullopt when its results_json is not a check's.
std::optional<DriftPoint> drift_point(const store::CalibrationCheck& check);

/// Every check of every calibration of `display` in the file (a study or
/// display-profile file, through Store's display methods), oldest first (by
/// checked_at, then row id). A check whose results cannot be read is skipped
/// and named in `problems` when given.
std::vector<DriftPoint> display_drift(const store::Store& file, std::string_view display,
                                      std::vector<std::string>* problems = nullptr);

/// The table, one line per check: date, calibration, verdict, peak, black, γ
/// (measured, and predicted ± tolerance), worst patch error (tolerance).
std::string drift_table(const std::vector<DriftPoint>& points);

/// The gnuplot commands (no terminal or output) that draw the drift in four
/// panels from `data`, a tab-separated file written by drift_data_rows().
std::string drift_plot_body(const std::string& data_literal, const std::vector<DriftPoint>& points,
                            const std::string& title);

/// The rows of that data file: epoch seconds (UTC), passed, then for peak,
/// black and γ the measured value and the band's low and high ends, then the
/// worst error % and its tolerance.
std::vector<std::vector<std::string>> drift_data_rows(const std::vector<DriftPoint>& points);

/// Writes the figure to `out` (.svg or .png by extension) with `gnuplot`.
/// Returns "" when written, else one sentence saying why not (no checks, an
/// unknown extension, gnuplot missing or failing).
std::string plot_drift(const std::filesystem::path& out, const std::vector<DriftPoint>& points,
                       const std::string& title, const std::string& gnuplot = "gnuplot");

}  // namespace atonlab::analysis
