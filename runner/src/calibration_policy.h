#pragma once
// Which display calibration an `atonlab run` session uses, and what it warns
// about before the session (docs/calibration.md, "Sessions"): the protocol's
// [display] name selects the display's latest measured calibration in the
// study file, whose GOG model then encodes every frame; without a name, or
// without a measured calibration, the session keeps the scene's nominal
// display model (recorded as a nominal calibration row, as before). Warnings:
// no measured calibration, its latest check failed, older than
// max_calibration_age_days, measured for another geometry.
#include <optional>
#include <string>
#include <vector>

#include "atonlab/protocols/protocol.h"
#include "atonlab/stimuli/display_model.h"
#include "atonlab/stimuli/scene.h"
#include "atonlab/store/store.h"

namespace atonlab::runner {

/// When the protocol gives no max_calibration_age_days.
inline constexpr double kDefaultMaxCalibrationAgeDays = 30.0;

struct SessionCalibration {
    /// The measured calibration the session uses (sessions.calibration_id);
    /// none: record the scene's nominal display model as before.
    std::optional<store::CalibrationId> calibration;
    /// Its display model: replaces the scene's for encoding (apply_display_model).
    std::optional<stimuli::DisplayModel> display;
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
                                       const std::string& db);

/// Today's date, UTC, YYYY-MM-DD.
std::string utc_today();

/// Whole days from the date that `iso` starts with (YYYY-MM-DD...) to `today`
/// (YYYY-MM-DD); std::nullopt when either is not a date.
std::optional<long> days_between(const std::string& iso, const std::string& today);

/// The scene encodes for `model`: its display model and the tone mapper's
/// display peak (K2012 eq 4.21's L_dmax) follow it.
void apply_display_model(stimuli::Scene& scene, const stimuli::DisplayModel& model);

/// Prints the warnings, one "atonlab: warning: ..." line each, to stderr, and
/// unless `quiet` the notes ("atonlab: note: ...").
void print_calibration_warnings(const SessionCalibration& calibration, bool quiet);

}  // namespace atonlab::runner
