#pragma once
// `atonlab calibrate (measure | import FILE | check | show) --display NAME` and
// `atonlab calibrate list`, on a study file (--db STUDY.db) or the lab's
// display-profile file (--profiles FILE, ATONLAB_PROFILES or the per-user
// default; docs/calibration.md). Exit status: 0 stored / check passed, 1
// check failed or the operator gave up (nothing stored), 2 bad input, 3 no GL
// or no usable screen, 4 the study or profile file failed, 5 the instrument
// failed (nothing stored).
#include <optional>
#include <string>

#include "calibrate/instrument.h"
#include "calibration_check.h"

namespace CLI {
class App;
}

namespace atonlab::runner {

struct CalibrateOptions {
    std::string mode;  ///< "measure", "import", "check", "list" or "show": the subcommand given
    std::string display;
    /// --db: a study file. Empty: the display-profile file (--profiles, else
    /// ATONLAB_PROFILES, else the per-user default; profile_location.h).
    std::string db;
    std::string profiles;  ///< --profiles FILE
    /// Set by run_calibrate: `db` holds the display-profile file's path.
    bool profiles_file = false;
    /// Set by run_calibrate: that path is the per-user default (its folder may be created).
    bool profiles_default = false;
    std::string drive_scale;  ///< import: --drive-scale fraction|8bit|10bit (CSV drive levels)
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
