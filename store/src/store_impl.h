#pragma once
// Store's private state, shared by the files that implement its parts
// (store.cpp, sessions.cpp, trials.cpp, calibrations.cpp, snapshots.cpp).
#include <fmt/format.h>

#include <memory>
#include <string>
#include <string_view>

#include "atonlab/store/store.h"
#include "sqlite.h"

namespace atonlab::store {

/// SQL for "now" as the store stamps it (see schema.cpp's conventions).
#define ATONLAB_STORE_NOW "strftime('%Y-%m-%dT%H:%M:%fZ', 'now')"

/// The texts a session stores once per hash: the protocol's and the scene's.
enum class StoredText { protocol, scene };

struct Store::Impl {
    std::unique_ptr<sql::Connection> db;
    bool read_only = false;
    /// What messages call the file: "study file" or "display-profile file".
    const char* noun = "study file";

    const std::filesystem::path& path() const { return db->path(); }

    /// Throws StoreErrc::read_only naming `doing` when this Store is a reader.
    void require_writable(std::string_view doing) const;
    /// Throws StoreErrc::invalid_argument: "PATH: cannot DOING: WHY".
    [[noreturn]] void invalid(std::string_view doing, std::string_view why) const;
    /// Throws StoreErrc::not_found: "PATH: cannot DOING: WHAT is not in the file".
    [[noreturn]] void not_found(std::string_view doing, std::string_view what) const;

    /// The session's status, or not_found. Call inside a transaction.
    SessionStatus status_of(SessionId session, std::string_view doing);
    SessionRecord read_session(SessionId session, std::string_view doing);
    std::vector<TrialRecord> read_trials(SessionId session, std::string_view doing);
    /// Checks trial t against the session under the write lock (running, the
    /// next index, JSON that parses) and inserts it. Call inside a write transaction.
    void insert_trial(SessionId session, const TrialRecord& t, const std::string& doing);
    std::string read_protocol_text(SessionId session, std::string_view doing);
    std::optional<std::string> read_scene_text(SessionId session, std::string_view doing);
    /// Stores `text` in the protocols or scenes table once per SHA-256 and
    /// returns its row id. Call inside the write transaction.
    std::int64_t put_text(StoredText kind, std::string_view name, std::string_view text, std::string_view doing);
    ResumePoint read_resume_point(SessionId session, std::string_view doing);
};

/// A sessions row as selected by sessions.cpp (id, observer code, protocol id,
/// name and hash, software version, seed, calibration, started, ended, status,
/// resume count, trial count, displayability JSON, scene hash and name; the
/// last two NULL where no scene is stored).
SessionRecord session_from_row(const sql::Statement& s, const std::filesystem::path& path);
/// A trials row from column `first` on: trial_index, block, condition_id,
/// procedure_id, level, test_on_left, stimulus_json, response, response_value,
/// response_time_s, onset_time_s, dropped_frames, missed_deadline,
/// procedure_state_json, recorded_at.
TrialRecord trial_from_row(const sql::Statement& s, int first);

/// True when `text` is valid JSON by SQLite's own json_valid(), the CHECK the schema uses.
bool json_valid(sql::Connection& db, std::string_view text, std::string_view doing);

}  // namespace atonlab::store
