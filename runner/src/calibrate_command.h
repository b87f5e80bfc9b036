#pragma once
// `atonlab calibrate (measure | import FILE | check) --display NAME --db STUDY.db`
// (docs/calibration.md). Exit status: 0 stored / check passed, 1 check failed
// or the operator gave up (nothing stored), 2 bad input, 3 no GL or no
// usable screen, 4 the study file failed, 5 the instrument failed (nothing stored).
#include <optional>
#include <string>

#include "calibrate/instrument.h"
#include "calibration_check.h"

namespace CLI {
class App;
}

namespace atonlab::runner {

struct CalibrateOptions {
    std::string mode;  ///< "measure", "import" or "check": the subcommand given
    std::string display;
    std::string db;
    std::string file;  ///< import: the .csv or .ti3
    // Geometry (measure, import); unset: from the display's latest calibration.
    std::optional<int> width_px, height_px;
    std::optional<double> width_m, height_m, viewing_distance_m;
    std::string date;  ///< measured_at / checked_at; empty: now (UTC)
    // Showing patches (measure, check).
    std::string readings;
    bool headless = false;
    int monitor = 0;
    double window_percent = 100.0;
    double patch_seconds = 0.0;
    bool list_patches = false;
    int grey_levels = 17;
    int colour_levels = 9;
    InstrumentOptions instrument;  ///< --instrument and its options; kind "": typed or --readings
    // check
    CheckTolerances tolerances;
    std::string plot;
    bool no_plot = false;
    bool quiet = false;
};

void add_calibrate_command(CLI::App& app, CalibrateOptions& options);
/// Runs whichever of measure, import, check was given. Throws InputError (2)
/// and gl::ContextUnavailable (3) for main() to report; a StoreError is
/// reported here (4).
int run_calibrate(const CalibrateOptions& options);

}  // namespace atonlab::runner
