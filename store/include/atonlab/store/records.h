#pragma once
// The rows the store keeps, as plain values (the schema is in store/src/schema.cpp,
// explained in docs/store.md). Times are in seconds, lengths in metres; wall-clock
// stamps are ISO 8601 UTC text written by the store ("2024-05-01T12:00:00.123Z").
#include <compare>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace atonlab::store {

/// The row id of a session; only meaningful inside the study file it came from.
struct SessionId {
    std::int64_t value = 0;
    friend auto operator<=>(const SessionId&, const SessionId&) = default;
};

/// The row id of a display calibration.
struct CalibrationId {
    std::int64_t value = 0;
    friend auto operator<=>(const CalibrationId&, const CalibrationId&) = default;
};

/// A session is `running` until finish_session(); a process that dies leaves it
/// `running`, and a later run may mark it `crashed` or resume it.
enum class SessionStatus { running, quit, completed, crashed };

/// "running", "quit", "completed", "crashed": the text stored in sessions.status.
const char* to_string(SessionStatus status) noexcept;
/// The inverse of to_string; std::nullopt for any other text.
std::optional<SessionStatus> session_status_from_string(std::string_view text) noexcept;

/// A display's geometry and its measured (or imported) calibration.
struct Calibration {
    std::string display_name;  ///< e.g. "lab-oled-1"; displays are keyed by name
    int width_px = 0;
    int height_px = 0;
    double width_m = 0.0;   ///< visible image width, metres
    double height_m = 0.0;  ///< visible image height, metres
    double viewing_distance_m = 0.0;
    std::string fit_json = "{}";  ///< the fitted display model's parameters, JSON text
    std::string source;           ///< how it was obtained: "measured", "imported FILE", ...
    std::string measured_at;      ///< ISO 8601 date or date-time of the measurement

    // Filled by the store on read.
    CalibrationId id{};
    std::string recorded_at;  ///< when the store wrote the row
};

/// One photometer reading behind a calibration (table calibration_readings):
/// the patch shown and what the meter read. Luminance in cd/m².
struct CalibrationReading {
    std::string patch;    ///< the patch's name: "black", "grey-128", "red-064", ... (not empty)
    std::string channel;  ///< "red", "green", "blue", "grey" (R = G = B, black and white included) or "other"
    double level = 0.0;   ///< drive of the lit channel(s) in [0, 1]; for "other" the largest of R, G, B
    /// The integer code value sent for the lit channel(s), at `bits` per channel;
    /// none when only a fraction is known (an imported file).
    std::optional<int> code;
    std::optional<int> bits;                             ///< with `code`: bits per channel, 1..16
    double drive_r = 0.0, drive_g = 0.0, drive_b = 0.0;  ///< the patch's drive levels, [0, 1]
    double luminance_cd_m2 = 0.0;                        ///< the reading, Y in cd/m², >= 0
    /// CIE 1931 X and Z on the same absolute scale as Y (cd/m²), when the meter gave them.
    std::optional<double> xyz_x_cd_m2, xyz_z_cd_m2;
    std::optional<int> source_line;  ///< 1-based line of the file it came from; none when typed
    /// What the instrument said for this patch, raw (`calibrate --instrument`); none
    /// for typed or file readings (schema version 3).
    std::optional<std::string> transcript;

    friend bool operator==(const CalibrationReading&, const CalibrationReading&) = default;
};

/// The row id of a calibration check.
struct CalibrationCheckId {
    std::int64_t value = 0;
    friend auto operator<=>(const CalibrationCheckId&, const CalibrationCheckId&) = default;
};

/// A calibration re-measured on a few patches and compared with its model
/// (table calibration_checks). Never updated: a new check is a new row.
struct CalibrationCheck {
    CalibrationId calibration{};      ///< the calibration that was checked
    std::string checked_at;           ///< ISO 8601 date or date-time of the measurement (YYYY-MM-DD...)
    bool passed = false;              ///< every tolerance held
    std::string results_json = "{}";  ///< tolerances, measured values and patches, JSON text (docs/calibration.md)
    std::string source;               ///< how the readings were taken: "measured", "readings FILE", ...

    // Filled by the store on read.
    CalibrationCheckId id{};
    std::string recorded_at;
};

/// What begin_session() needs.
struct SessionStart {
    std::string observer_code;                 ///< 1-32 of [A-Za-z0-9_-]: a code, never a name
    std::string protocol_text;                 ///< the protocol file's full text (stored once per hash)
    std::string protocol_name;                 ///< e.g. the file name, for people reading the file
    std::uint64_t seed = 0;                    ///< the session's random seed
    std::optional<CalibrationId> calibration;  ///< the calibration the runner used, if any
    /// The scene file's full text (stored once per hash, like the protocol's);
    /// empty: none stored (the session's scene_id is NULL).
    std::string scene_text;
    std::string scene_name;  ///< e.g. the scene file's name as the protocol gives it
    /// What the display showed of the stimuli before the first trial, JSON
    /// (docs/running.md, "Displayability"); empty: not worked out (stored NULL).
    std::string displayability_json;
    /// The software that ran the session; empty means this library's own version
    /// (software_version()).
    std::string software_version;
    /// A simulated session (`atonlab simulate`, docs/simulate.md): its
    /// observer, true values and design, JSON; empty for any other session
    /// (stored NULL). Schema version 7.
    std::string simulation_json;
};

/// A session as stored.
struct SessionRecord {
    SessionId id{};
    std::string observer_code;
    std::int64_t protocol_id = 0;
    std::string protocol_name;
    std::string protocol_sha256;  ///< lowercase hex SHA-256 of the protocol text (FIPS 180-4)
    std::string software_version;
    std::uint64_t seed = 0;
    std::optional<CalibrationId> calibration;
    std::string started_at;
    std::optional<std::string> ended_at;  ///< set by finish_session()
    SessionStatus status = SessionStatus::running;
    int resume_count = 0;  ///< how many times resume_session() reopened it
    std::int64_t trial_count = 0;
    std::optional<std::string> displayability_json;  ///< SessionStart's; none for a session from before schema v3
    /// Lowercase hex SHA-256 of the stored scene text; none when the session
    /// stored no scene (a session from before schema v6).
    std::optional<std::string> scene_sha256;
    std::string scene_name;  ///< SessionStart's; empty with no scene stored
    std::optional<std::string> simulation_json;  ///< SessionStart's; none for any other session (schema v7)
    /// Why the runner stopped the session before its end, JSON (docs/running.md);
    /// none when it did not (schema v7).
    std::optional<std::string> stop_json;
};

/// One trial: what was shown, what the observer answered, how well the frames
/// were timed, and the procedure's state after the answer.
struct TrialRecord {
    std::int64_t trial_index = 0;             ///< 0-based within the session, no gaps (the store enforces it)
    int block = 0;                            ///< 0-based block of the protocol
    std::string condition_id;                 ///< the protocol's condition name
    std::string procedure_id;                 ///< which procedure instance proposed the stimulus
    double level = 0.0;                       ///< the procedure's level, in the procedure's own units (see its docs)
    std::optional<bool> test_on_left;         ///< 2AFC: where the test stimulus was; none for yes/no and adjustment
    std::string stimulus_json = "{}";         ///< every stimulus parameter (the resolved scene keys), JSON text
    std::string response;                     ///< protocols::response_word of the answer, or "timeout" / "missed"
    std::optional<double> response_value;     ///< method of adjustment: the value the observer set
    double response_time_s = 0.0;             ///< stimulus onset to answer, seconds, >= 0
    double onset_time_s = 0.0;                ///< stimulus onset on the runner's clock, seconds since session start
    int dropped_frames = 0;                   ///< frames the presentation missed, >= 0
    bool missed_deadline = false;             ///< the onset frame itself was late
    std::string procedure_state_json = "{}";  ///< the procedure's state after this trial, JSON text

    // Filled by the store on read.
    std::string recorded_at;
};

/// Everything a runner needs to continue a session: replay `trials` through the
/// protocol's procedures (parsed from `protocol_text`) and go on at next_trial_index.
struct ResumePoint {
    SessionRecord session;
    std::string protocol_text;
    std::vector<TrialRecord> trials;  ///< in trial_index order, 0 .. next_trial_index-1
    std::int64_t next_trial_index = 0;
};

/// The stimulus as rendered for one condition of one session, e.g. an EXR file's bytes.
struct Snapshot {
    SessionId session{};
    std::string condition_id;
    std::string format = "exr";  ///< what `data` is: "exr" for an OpenEXR file's bytes
    std::vector<std::byte> data;
    std::string sha256;       ///< of data; the store fills and verifies it
    std::string recorded_at;  ///< filled by the store
};

/// A trial that Store::salvage() could read, with the session it belongs to.
struct SalvagedTrial {
    SessionId session{};
    TrialRecord trial;
};

/// A session or trial row that Store::salvage() left out, and why.
struct SkippedRow {
    std::string table;  ///< "sessions" or "trials"
    std::int64_t row_id = 0;
    std::string why;  ///< "breaks CHECK (json_valid(stimulus_json))", "cannot be read (…)", "cannot be found (…)"
};

/// What Store::salvage() could read of a damaged study file.
struct Salvage {
    std::vector<SessionRecord> sessions;   ///< readable sessions; trial_count = the trials read for each
    std::vector<SalvagedTrial> trials;     ///< readable trials, by session, then trial_index
    std::int64_t unreadable_sessions = 0;  ///< session row ids up to the largest that could not be read
    std::int64_t unreadable_trials = 0;    ///< trial row ids up to the largest that could not be read
    std::vector<std::string> problems;     ///< one sentence for each part that could not be read at all
    std::vector<SkippedRow> skipped;       ///< every session and trial row id up to the largest that was left out
};

}  // namespace atonlab::store
