// The study file's schema, in one place. Each Migration takes a file from
// user_version N-1 to N; a new column or table is a new step appended to the
// list, never an edit of a step that has shipped (files in the field were made
// by it). docs/store.md explains every table for people reading the file.
#include "atonlab/store/schema.h"

#include <array>

#include "display_tables.h"

namespace atonlab::store {
namespace {

// Conventions used by every table:
//  * wall-clock stamps (…_at) are ISO 8601 UTC text with milliseconds, made by
//    SQLite: strftime('%Y-%m-%dT%H:%M:%fZ', 'now'); text order is time order;
//  * durations and stimulus-clock times are REAL seconds (…_s);
//  * …_json columns are JSON text, checked with SQLite's json_valid();
//  * booleans are INTEGER 0/1; ids are INTEGER PRIMARY KEY row ids.
//
// Version 1: the tables shared with the display-profile file
// (display_tables.h) among the study's own, in the order they shipped.
constexpr char protocols_v1[] = R"sql(

-- Protocol files, byte for byte, stored once per distinct text.
CREATE TABLE protocols (
    id       INTEGER PRIMARY KEY,
    sha256   TEXT NOT NULL UNIQUE CHECK (length(sha256) = 64),  -- lowercase hex SHA-256 of text (FIPS 180-4)
    name     TEXT NOT NULL,                      -- the name it was first stored under (usually the file name)
    text     TEXT NOT NULL,
    added_at TEXT NOT NULL
);)sql";

constexpr char rest_v1[] = R"sql(

-- Observers by code only: the file never holds a person's name.
CREATE TABLE observers (
    id       INTEGER PRIMARY KEY,
    code     TEXT NOT NULL UNIQUE
             CHECK (length(code) BETWEEN 1 AND 32 AND code NOT GLOB '*[^A-Za-z0-9_-]*'),
    added_at TEXT NOT NULL
);

-- One run of a protocol by one observer. 'running' until finished; a process
-- that dies leaves 'running' behind, which a later run marks 'crashed' or resumes.
CREATE TABLE sessions (
    id               INTEGER PRIMARY KEY,
    observer_id      INTEGER NOT NULL REFERENCES observers(id),
    protocol_id      INTEGER NOT NULL REFERENCES protocols(id),
    calibration_id   INTEGER REFERENCES calibrations(id),   -- NULL: run without a calibration
    software_version TEXT NOT NULL,
    seed             INTEGER NOT NULL,           -- the uint64 seed's bits, read as a signed 64-bit integer
    started_at       TEXT NOT NULL,
    ended_at         TEXT,
    status           TEXT NOT NULL DEFAULT 'running'
                     CHECK (status IN ('running', 'quit', 'completed', 'crashed')),
    resume_count     INTEGER NOT NULL DEFAULT 0 CHECK (resume_count >= 0),
    CHECK ((status = 'running') = (ended_at IS NULL))
);
CREATE INDEX sessions_by_observer ON sessions (observer_id);
CREATE INDEX sessions_by_protocol ON sessions (protocol_id);

-- One row per answered trial, appended in its own transaction. trial_index runs
-- 0, 1, 2, ... within a session with no gaps (Store::record_trial enforces it).
CREATE TABLE trials (
    id                   INTEGER PRIMARY KEY,
    session_id           INTEGER NOT NULL REFERENCES sessions(id),
    trial_index          INTEGER NOT NULL CHECK (trial_index >= 0),
    block                INTEGER NOT NULL CHECK (block >= 0),
    condition_id         TEXT NOT NULL,
    procedure_id         TEXT NOT NULL,
    level                REAL NOT NULL,          -- the procedure's level, in its own units
    test_on_left         INTEGER CHECK (test_on_left IN (0, 1)),  -- 2AFC only; NULL otherwise
    stimulus_json        TEXT NOT NULL CHECK (json_valid(stimulus_json)),  -- every stimulus parameter
    response             TEXT NOT NULL,          -- "left", "right", "yes", "no", "adjust", "timeout", ...
    response_value       REAL,                   -- method of adjustment: the value set; NULL otherwise
    response_time_s      REAL NOT NULL CHECK (response_time_s >= 0),     -- onset to answer
    onset_time_s         REAL NOT NULL,          -- onset on the runner's clock, since session start
    dropped_frames       INTEGER NOT NULL CHECK (dropped_frames >= 0),
    missed_deadline      INTEGER NOT NULL CHECK (missed_deadline IN (0, 1)),
    procedure_state_json TEXT NOT NULL CHECK (json_valid(procedure_state_json)),  -- after this trial
    recorded_at          TEXT NOT NULL,
    UNIQUE (session_id, trial_index)
);
CREATE INDEX trials_by_condition ON trials (condition_id);

-- Nothing stored is lost: a recorded trial is never changed or deleted.
CREATE TRIGGER trials_append_only_update BEFORE UPDATE ON trials
BEGIN SELECT RAISE(ABORT, 'trials are append-only: a recorded trial cannot be changed'); END;
CREATE TRIGGER trials_append_only_delete BEFORE DELETE ON trials
BEGIN SELECT RAISE(ABORT, 'trials are append-only: a recorded trial cannot be deleted'); END;

-- The stimulus as rendered, one per session and condition: an OpenEXR file's
-- bytes (scene-referred cd/m2, docs/architecture.md "Units and colour"), so a study is one file.
CREATE TABLE snapshots (
    session_id   INTEGER NOT NULL REFERENCES sessions(id),
    condition_id TEXT NOT NULL,
    format       TEXT NOT NULL,                  -- "exr"
    data         BLOB NOT NULL,
    sha256       TEXT NOT NULL CHECK (length(sha256) = 64),  -- of data, checked on every read
    recorded_at  TEXT NOT NULL,
    PRIMARY KEY (session_id, condition_id)
);

-- Every trial with who ran it and under which protocol: the flat table
-- analysis and ad-hoc SQL start from.
CREATE VIEW trial_log AS
SELECT t.session_id, o.code AS observer_code, p.sha256 AS protocol_sha256, s.status AS session_status,
       t.trial_index, t.block, t.condition_id, t.procedure_id, t.level, t.test_on_left, t.response,
       t.response_value, t.response_time_s, t.onset_time_s, t.dropped_frames, t.missed_deadline,
       t.stimulus_json, t.procedure_state_json, t.recorded_at
FROM trials t
JOIN sessions s ON s.id = t.session_id
JOIN observers o ON o.id = s.observer_id
JOIN protocols p ON p.id = s.protocol_id;
)sql";

constexpr auto schema_v1 = sql::join(sql::schema_history, protocols_v1, sql::displays, sql::calibrations, rest_v1);

// Version 2: the photometer readings behind a calibration and the checks of a
// calibration against fresh readings (docs/calibration.md). Calibrations
// become append-only in the file itself, as they always were by convention.
constexpr auto schema_v2 = sql::join(sql::calibration_readings, sql::calibration_checks, sql::calibrations_append_only);

// Version 3: the raw transcript of an instrument's readings of each patch
// (`calibrate measure --instrument`), kept with the readings as evidence.
constexpr std::string_view schema_v3 = sql::calibration_readings_transcript;

// Version 4: what the display showed of each condition's stimuli, worked out
// before the first trial (docs/running.md, "Displayability"), and whether the
// session ran with --allow-undisplayable. NULL for sessions from before.
constexpr std::string_view schema_v4 = R"sql(
ALTER TABLE sessions ADD COLUMN displayability_json TEXT
    CHECK (displayability_json IS NULL OR json_valid(displayability_json));
)sql";

// Version 5: a tidy view of the overrides each trial's frames set (docs/store.md):
// one row per trial, frame and override, the value typed and without its TOML
// quotes (a number as a number, a string's contents, true / false as 1 / 0),
// the text as the protocol wrote it kept beside it.
constexpr std::string_view schema_v5 = R"sql(
CREATE VIEW trial_settings AS
SELECT t.session_id, t.trial_index, t.condition_id, f.key AS frame,
       coalesce(json_extract(f.value, '$.role'), 'both') AS frame_role,
       substr(o.value, 1, instr(o.value, '=') - 1) AS key,
       CASE
         WHEN json_valid(substr(o.value, instr(o.value, '=') + 1))
           THEN json_extract(substr(o.value, instr(o.value, '=') + 1), '$')
         WHEN substr(o.value, instr(o.value, '=') + 1) GLOB '''*'''
           THEN substr(o.value, instr(o.value, '=') + 2, length(o.value) - instr(o.value, '=') - 2)
         ELSE substr(o.value, instr(o.value, '=') + 1)
       END AS value,
       substr(o.value, instr(o.value, '=') + 1) AS toml_value
FROM trials t, json_each(t.stimulus_json, '$.frames') f, json_each(f.value, '$.overrides') o
WHERE instr(o.value, '=') > 0;
)sql";

// Version 6: the scene file a session rendered, byte for byte, stored once per
// distinct text like the protocol's, so that the colour, rhythm and spectrum
// of what was shown can be read from the study file alone (docs/store.md).
// NULL for sessions from before.
constexpr std::string_view schema_v6 = R"sql(
CREATE TABLE scenes (
    id       INTEGER PRIMARY KEY,
    sha256   TEXT NOT NULL UNIQUE CHECK (length(sha256) = 64),  -- lowercase hex SHA-256 of text (FIPS 180-4)
    name     TEXT NOT NULL,                      -- the name it was first stored under (the protocol's `scene`)
    text     TEXT NOT NULL,
    added_at TEXT NOT NULL
);
ALTER TABLE sessions ADD COLUMN scene_id INTEGER REFERENCES scenes(id);
)sql";

// Version 7: what the session was besides its trials. simulation_json: a
// simulated session's observer, its true values per condition and its design
// (`atonlab simulate`, docs/simulate.md); stop_json: why a session stopped
// before its end when the runner stopped it (docs/running.md). NULL otherwise.
constexpr std::string_view schema_v7 = R"sql(
ALTER TABLE sessions ADD COLUMN simulation_json TEXT
    CHECK (simulation_json IS NULL OR json_valid(simulation_json));
ALTER TABLE sessions ADD COLUMN stop_json TEXT
    CHECK (stop_json IS NULL OR json_valid(stop_json));
)sql";

constexpr std::array<Migration, 7> migrations = {
    Migration{1, "protocols, displays, calibrations, observers, sessions, trials, snapshots", sql::text(schema_v1)},
    Migration{2, "calibration readings and checks; calibrations append-only", sql::text(schema_v2)},
    Migration{3, "instrument transcripts of calibration readings", schema_v3},
    Migration{4, "sessions.displayability_json", schema_v4},
    Migration{5, "view trial_settings: each trial's overrides, typed and unquoted", schema_v5},
    Migration{6, "scenes; sessions.scene_id", schema_v6},
    Migration{7, "sessions.simulation_json, sessions.stop_json", schema_v7},
};

}  // namespace

std::span<const Migration> schema_migrations() noexcept {
    return migrations;
}

int schema_version() noexcept {
    return migrations.back().to_version;
}

}  // namespace atonlab::store
