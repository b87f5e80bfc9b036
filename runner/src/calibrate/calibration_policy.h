#pragma once
// Which display calibration an `atonlab run` session uses, and what it warns
// about before the session (docs/calibration.md, "Sessions"): the protocol's
// [display] name selects the display's latest measured calibration in the
// lab's display-profile file or in the study file (the later measured of the
// two; the profile file's on a tie), whose GOG model then encodes every
// frame; one from the profile file is copied into the study file with its
// readings and latest check (copy_into_study), so the study stays
// self-contained; without a name, or
// without a measured calibration, the session keeps the scene's nominal
// display model (recorded as a nominal calibration row, as before). Warnings:
// no measured calibration, its latest check failed, older than
// max_calibration_age_days, measured for another geometry.
#include <optional>
#include <string>
#include <vector>

#include "atonlab/protocols/protocol.h"
#include "atonlab/display/display_model.h"
#include "atonlab/stimuli/scene.h"
#include "atonlab/store/store.h"

namespace atonlab::runner {

/// When the protocol gives no max_calibration_age_days.
inline constexpr double kDefaultMaxCalibrationAgeDays = 30.0;

/// A calibration of the display-profile file that a session uses: what is
/// copied into the study file before the session begins.
struct ProfileCopy {
    std::string profiles_file;  ///< the display-profile file's path, for the copy's source
    store::Calibration calibration;
    std::vector<store::CalibrationReading> readings;
    std::optional<store::CalibrationCheck> latest_check;  ///< the check the session's warnings used
};

/// The display-profile file as `atonlab run` reads it.
struct RunProfiles {
    const store::Store* file = nullptr;  ///< Profiles::displays(); nullptr: no profile file
    std::string path;                    ///< for messages
};

struct SessionCalibration {
    /// The measured calibration of the study file the session uses
    /// (sessions.calibration_id); none: `from_profiles`, else record the
    /// scene's nominal display model as before.
    std::optional<store::CalibrationId> calibration;
    /// The display-profile file's calibration the session uses, to be copied
    /// into the study file (copy_into_study gives the session's calibration_id).
    std::optional<ProfileCopy> from_profiles;
    /// Its display model: replaces the scene's for encoding (apply_display_model).
    std::optional<display::DisplayModel> display;
    /// One sentence each, for stderr before the session starts.
    std::vector<std::string> warnings;
    /// Said unless the run is quiet: the protocol names no display, so there is
    /// no calibration to look for (the behaviour of protocols written before names).
    std::vector<std::string> notes;
};

/// The decision for a session. `store`: the study file, or nullptr when it
/// does not exist yet (so holds no calibration). `resumed_with`: the
/// calibration a resumed session recorded when it began (that one is used
/// again, measured or not). `today`: YYYY-MM-DD (UTC), the date ages are
/// counted to; `db` names the study file in messages.
SessionCalibration session_calibration(const store::Store* store, const protocols::Display& display,
                                       std::optional<store::CalibrationId> resumed_with, const std::string& today,
                                       const std::string& db, const RunProfiles& profiles = {});

/// Stores `copy` in the study file (the calibration with its readings, then
/// its latest check) unless an identical copy is there already (same display,
/// date, geometry and fit_json; a check with the same date and results), and
/// returns the study file's id of that calibration. Idempotent: a second
/// session with the same calibration adds nothing.
store::CalibrationId copy_into_study(store::Store& study, const ProfileCopy& copy);

/// Today's date, UTC, YYYY-MM-DD.
std::string utc_today();

/// Whole days from the date that `iso` starts with (YYYY-MM-DD...) to `today`
/// (YYYY-MM-DD); std::nullopt when either is not a date.
std::optional<long> days_between(const std::string& iso, const std::string& today);

/// The scene encodes for `model`: its display model and the tone mapper's
/// display peak (K2012 eq 4.21's L_dmax) follow it.
void apply_display_model(stimuli::Scene& scene, const display::DisplayModel& model);

/// Prints the warnings, one "atonlab: warning: ..." line each, to stderr, and
/// unless `quiet` the notes ("atonlab: note: ...").
void print_calibration_warnings(const SessionCalibration& calibration, bool quiet);

}  // namespace atonlab::runner
