#pragma once
// Store: one study's SQLite file (docs/store.md). A writer commits every trial in
// its own transaction before record_trial() returns (WAL, synchronous=FULL), so
// a response the runner was told is stored survives a killed process and a power
// cut. Readers (open_read_only) can read while a writer session runs.
//
// One Store is one SQLite connection: use it from one thread at a time. Several
// Stores (in one or several processes) may open the same file. A moved-from
// Store may only be destroyed or assigned to.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/store/error.h"
#include "atonlab/store/records.h"

namespace atonlab::store {

struct StoreOptions {
    /// How long a statement waits for another connection's lock before StoreErrc::busy.
    int busy_timeout_ms = 5000;
    /// 0: no limit. Otherwise the file may not grow past this many bytes (rounded
    /// down to whole pages; PRAGMA max_page_count): writes beyond it fail with
    /// StoreErrc::disk_full exactly as a full disk would. Lets a lab cap a study's
    /// size, and lets tests exercise the disk-full path.
    std::int64_t max_size_bytes = 0;
    /// Check an existing file before it is used (docs/store.md, "Opening"):
    /// its schema against the one atonlab's migrations make for its version
    /// (StoreErrc::schema_altered), then SQLite's PRAGMA integrity_check and
    /// the constraints over every row (StoreErrc::corrupt); a refused file is
    /// left unchanged. false only for salvage: reading what is left of a file
    /// known to be damaged or altered (read-only opens).
    bool verify = true;
    /// true: every commit is on disk when it returns (synchronous = FULL).
    /// false: commits are not synced (synchronous = OFF) and the caller makes
    /// the file durable itself once it is written (syncfs before renaming it
    /// into place): only for a file that can be written again from scratch,
    /// such as a simulated session (docs/simulate.md). Never for a person's session.
    bool durable = true;
    /// The longest text or blob the connection reads or writes
    /// (SQLITE_LIMIT_LENGTH; docs/store.md, "Limits"): 256 MiB, over a thousand
    /// times the largest snapshot measured (182 KB). A file holding a longer value is refused
    /// at open (with verify) or where the value is read. Lower it only to test
    /// that refusal; SQLite itself allows at most 1,000,000,000 bytes.
    std::int64_t max_value_bytes = std::int64_t{256} << 20;
};

class Store {
public:
    /// Opens `path` for reading and writing, creating it (and its schema) if it
    /// does not exist, migrating an older schema in one transaction. An existing
    /// file is checked before anything is written to it: an SQLite file (not a
    /// truncated or foreign one), an atonlab study, a schema no newer than this
    /// code's, and (StoreOptions::verify) no damage by PRAGMA integrity_check.
    /// Throws StoreError: cannot_open (missing directory, ...), not_a_database,
    /// not_a_study, newer_schema, corrupt (all with the file untouched),
    /// read_only, io_error, busy.
    static Store create_or_open(const std::filesystem::path& path, const StoreOptions& options = {});
    /// As create_or_open, but the file must already exist (a typo in a path does
    /// not silently start a new, empty study).
    static Store open_existing(const std::filesystem::path& path, const StoreOptions& options = {});
    /// Opens an existing study with SQLITE_OPEN_READONLY; may run alongside a
    /// writer. Every write method then throws StoreErrc::read_only. A file whose
    /// schema is older than this code throws older_schema (migrating needs a writer).
    static Store open_read_only(const std::filesystem::path& path, const StoreOptions& options = {});

    Store(Store&&) noexcept;
    Store& operator=(Store&&) noexcept;
    Store(const Store&) = delete;
    Store& operator=(const Store&) = delete;
    ~Store();

    const std::filesystem::path& path() const noexcept;
    bool read_only() const noexcept;

    // --- Displays -----------------------------------------------------------
    /// Stores a calibration (and its display, by name, if new) with the
    /// photometer readings it was fitted to, in one transaction: all or nothing.
    /// Readings are checked (names, channels, ranges) before anything is written.
    CalibrationId put_calibration(const Calibration& calibration, std::span<const CalibrationReading> readings = {});
    /// The display's calibration with the latest measured_at (then the latest
    /// stored), or std::nullopt when the display has none.
    std::optional<Calibration> latest_calibration(std::string_view display_name) const;
    Calibration calibration(CalibrationId id) const;
    /// Every calibration of the display, latest first (as latest_calibration orders them).
    std::vector<Calibration> calibrations(std::string_view display_name) const;
    /// The readings stored with a calibration, in measuring order (none for a
    /// calibration stored without readings). not_found for an unknown id.
    std::vector<CalibrationReading> calibration_readings(CalibrationId id) const;

    /// Stores a check of a calibration (the calibration must exist).
    CalibrationCheckId put_calibration_check(const CalibrationCheck& check);
    /// The calibration's check with the latest checked_at (then the latest
    /// stored), or std::nullopt when it has never been checked.
    std::optional<CalibrationCheck> latest_calibration_check(CalibrationId id) const;
    /// Every check of the calibration, latest first.
    std::vector<CalibrationCheck> calibration_checks(CalibrationId id) const;
    /// The names of the displays the file holds calibrations of, in name order.
    std::vector<std::string> display_names() const;

    // --- Sessions -----------------------------------------------------------
    /// Records the observer and the protocol (once per text hash) if new and
    /// starts a `running` session. One transaction.
    SessionId begin_session(const SessionStart& start);
    /// Ends a running session with `status` (quit, completed or crashed) and
    /// stamps ended_at. Throws invalid_argument for `running` or a session that
    /// is not running.
    void finish_session(SessionId session, SessionStatus status);
    /// Checkpoints the WAL into the file and switches it to a rollback
    /// journal (journal_mode = DELETE), so that a reader opening it read-only
    /// leaves no -wal and -shm files beside it: for a file written once and
    /// then only read, as a simulated session (docs/simulate.md: a simulation
    /// folder holds a file per session). The next writer switches it back to WAL.
    void switch_to_rollback_journal();
    /// Ends a running session as `quit` because the runner stopped it before
    /// its end (not the observer: docs/running.md, "Missed frames and
    /// timeouts"): stamps ended_at and appends `stop`, a JSON object, to the
    /// session's stop_json array with a "stopped_at" time (UTC) added. One
    /// transaction. The array keeps every stop of the session: resume_session()
    /// leaves it as it is, so a session stopped, resumed and completed says
    /// when and why it stopped on the way. Throws invalid_argument for a
    /// session that is not running or a `stop` that is not a JSON object.
    void stop_session(SessionId session, std::string_view stop);
    /// Reopens a session left running (its process died), crashed or quit, so
    /// record_trial may continue it; counts the resume. Returns the resume point.
    /// A completed session cannot be resumed.
    ResumePoint resume_session(SessionId session);

    std::vector<SessionRecord> sessions() const;
    SessionRecord session(SessionId session) const;
    /// The protocol text the session ran (byte for byte what begin_session got).
    std::string protocol_text(SessionId session) const;
    /// The scene text the session rendered (byte for byte what begin_session
    /// got), or std::nullopt when none was stored (a session from before
    /// schema version 6, or begun without one).
    std::optional<std::string> scene_text(SessionId session) const;

    // --- Trials -------------------------------------------------------------
    /// Appends one trial in its own transaction, durable when this returns.
    /// trial.trial_index must be the session's next index (its trial count) and
    /// the session must be running; otherwise invalid_argument and nothing is
    /// written. On any failure (disk full, I/O error) the trial is not stored and
    /// every earlier trial is intact.
    void record_trial(SessionId session, const TrialRecord& trial);
    /// Records consecutive trials in ONE transaction, each checked as
    /// record_trial checks it; all are stored or none. For a simulated session,
    /// which can be recomputed from its seed (docs/simulate.md): a person's
    /// session keeps record_trial's one commit per answer.
    void record_trials(SessionId session, std::span<const TrialRecord> trials);
    /// The session's trials in trial_index order.
    std::vector<TrialRecord> trials(SessionId session) const;
    std::int64_t trial_count(SessionId session) const;
    /// The session, its protocol and its trials, read in one snapshot: what a
    /// runner replays through its procedures to continue.
    ResumePoint resume_point(SessionId session) const;

    // --- Stimulus snapshots -------------------------------------------------
    /// Stores (or replaces) the snapshot for (session, condition), with its SHA-256.
    void put_snapshot(SessionId session, std::string_view condition_id, std::span<const std::byte> data,
                      std::string_view format = "exr");
    /// The snapshot, checked against its stored SHA-256 (corrupt if it differs),
    /// or std::nullopt when there is none.
    std::optional<Snapshot> get_snapshot(SessionId session, std::string_view condition_id) const;

    // --- Maintenance --------------------------------------------------------
    /// PRAGMA integrity_check's answer: "ok", or SQLite's list of problems.
    std::string integrity_check() const;
    /// The file's PRAGMA user_version.
    int file_schema_version() const;
    /// For a damaged file (opened read-only with StoreOptions::verify false):
    /// every session and trial row SQLite can still read, each looked up by its
    /// row id (1 … the largest), so that a damaged page loses only the rows on
    /// it. Never throws for damage; counts what it could not read.
    Salvage salvage() const;

    struct Impl;

private:
    friend class Profiles;  // a display-profile file shares the display methods (profiles.h)
    explicit Store(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace atonlab::store
