-- The schema of an atonlab file at user_version 4, as SQLite stores it
-- (scripts/schema_fixture.sh; tests/data/store_schema/README.md). A released
-- version never changes: do not edit.
CREATE TABLE schema_history (
    version          INTEGER PRIMARY KEY,        -- the user_version this step reached
    description      TEXT NOT NULL,
    software_version TEXT NOT NULL,              -- atonlab version that applied the step
    applied_at       TEXT NOT NULL
);
CREATE TABLE protocols (
    id       INTEGER PRIMARY KEY,
    sha256   TEXT NOT NULL UNIQUE CHECK (length(sha256) = 64),  -- lowercase hex SHA-256 of text (FIPS 180-4)
    name     TEXT NOT NULL,                      -- the name it was first stored under (usually the file name)
    text     TEXT NOT NULL,
    added_at TEXT NOT NULL
);
CREATE TABLE displays (
    id   INTEGER PRIMARY KEY,
    name TEXT NOT NULL UNIQUE CHECK (length(name) > 0)
);
CREATE TABLE calibrations (
    id                 INTEGER PRIMARY KEY,
    display_id         INTEGER NOT NULL REFERENCES displays(id),
    width_px           INTEGER NOT NULL CHECK (width_px > 0),
    height_px          INTEGER NOT NULL CHECK (height_px > 0),
    width_m            REAL NOT NULL CHECK (width_m > 0),
    height_m           REAL NOT NULL CHECK (height_m > 0),
    viewing_distance_m REAL NOT NULL CHECK (viewing_distance_m > 0),
    fit_json           TEXT NOT NULL CHECK (json_valid(fit_json)),  -- the display model's parameters
    source             TEXT NOT NULL,            -- "measured", "imported FILE", ...
    measured_at        TEXT NOT NULL,            -- ISO 8601 date (or date-time) of the measurement
    recorded_at        TEXT NOT NULL
);
CREATE INDEX calibrations_by_display ON calibrations (display_id, measured_at);
CREATE TABLE observers (
    id       INTEGER PRIMARY KEY,
    code     TEXT NOT NULL UNIQUE
             CHECK (length(code) BETWEEN 1 AND 32 AND code NOT GLOB '*[^A-Za-z0-9_-]*'),
    added_at TEXT NOT NULL
);
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
    resume_count     INTEGER NOT NULL DEFAULT 0 CHECK (resume_count >= 0), displayability_json TEXT
    CHECK (displayability_json IS NULL OR json_valid(displayability_json)),
    CHECK ((status = 'running') = (ended_at IS NULL))
);
CREATE INDEX sessions_by_observer ON sessions (observer_id);
CREATE INDEX sessions_by_protocol ON sessions (protocol_id);
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
CREATE TRIGGER trials_append_only_update BEFORE UPDATE ON trials
BEGIN SELECT RAISE(ABORT, 'trials are append-only: a recorded trial cannot be changed'); END;
CREATE TRIGGER trials_append_only_delete BEFORE DELETE ON trials
BEGIN SELECT RAISE(ABORT, 'trials are append-only: a recorded trial cannot be deleted'); END;
CREATE TABLE snapshots (
    session_id   INTEGER NOT NULL REFERENCES sessions(id),
    condition_id TEXT NOT NULL,
    format       TEXT NOT NULL,                  -- "exr"
    data         BLOB NOT NULL,
    sha256       TEXT NOT NULL CHECK (length(sha256) = 64),  -- of data, checked on every read
    recorded_at  TEXT NOT NULL,
    PRIMARY KEY (session_id, condition_id)
);
CREATE VIEW trial_log AS
SELECT t.session_id, o.code AS observer_code, p.sha256 AS protocol_sha256, s.status AS session_status,
       t.trial_index, t.block, t.condition_id, t.procedure_id, t.level, t.test_on_left, t.response,
       t.response_value, t.response_time_s, t.onset_time_s, t.dropped_frames, t.missed_deadline,
       t.stimulus_json, t.procedure_state_json, t.recorded_at
FROM trials t
JOIN sessions s ON s.id = t.session_id
JOIN observers o ON o.id = s.observer_id
JOIN protocols p ON p.id = s.protocol_id;
CREATE TABLE calibration_readings (
    id              INTEGER PRIMARY KEY,
    calibration_id  INTEGER NOT NULL REFERENCES calibrations(id),
    seq             INTEGER NOT NULL CHECK (seq >= 0),          -- 0, 1, 2, ... in measuring order
    patch           TEXT NOT NULL CHECK (length(patch) > 0),   -- "black", "grey-128", "red-064", ...
    channel         TEXT NOT NULL CHECK (channel IN ('red', 'green', 'blue', 'grey', 'other')),
    level           REAL NOT NULL CHECK (level BETWEEN 0 AND 1),  -- drive of the lit channel(s)
    code            INTEGER CHECK (code >= 0),                  -- the integer code value sent; NULL for imports
    bits            INTEGER CHECK (bits BETWEEN 1 AND 16),      -- bits per channel of code
    drive_r         REAL NOT NULL CHECK (drive_r BETWEEN 0 AND 1),  -- the patch's drive levels
    drive_g         REAL NOT NULL CHECK (drive_g BETWEEN 0 AND 1),
    drive_b         REAL NOT NULL CHECK (drive_b BETWEEN 0 AND 1),
    luminance_cd_m2 REAL NOT NULL CHECK (luminance_cd_m2 >= 0), -- the reading: Y, cd/m2
    xyz_x_cd_m2     REAL,                                       -- CIE 1931 X on the same scale as Y; NULL if not read
    xyz_z_cd_m2     REAL,                                       -- CIE 1931 Z likewise
    source_line     INTEGER CHECK (source_line > 0), transcript TEXT,            -- line of the readings file; NULL when typed
    CHECK ((code IS NULL) = (bits IS NULL)),
    CHECK ((xyz_x_cd_m2 IS NULL) = (xyz_z_cd_m2 IS NULL)),
    UNIQUE (calibration_id, seq)
);
CREATE TABLE calibration_checks (
    id             INTEGER PRIMARY KEY,
    calibration_id INTEGER NOT NULL REFERENCES calibrations(id),
    checked_at     TEXT NOT NULL,                 -- ISO 8601 date (or date-time) of the measurement
    passed         INTEGER NOT NULL CHECK (passed IN (0, 1)),
    results_json   TEXT NOT NULL CHECK (json_valid(results_json)),
    source         TEXT NOT NULL,                 -- "measured", "readings FILE", ...
    recorded_at    TEXT NOT NULL
);
CREATE INDEX calibration_checks_by_calibration ON calibration_checks (calibration_id, checked_at);
CREATE TRIGGER calibrations_append_only_update BEFORE UPDATE ON calibrations
BEGIN SELECT RAISE(ABORT, 'calibrations are append-only: a stored calibration cannot be changed'); END;
CREATE TRIGGER calibrations_append_only_delete BEFORE DELETE ON calibrations
BEGIN SELECT RAISE(ABORT, 'calibrations are append-only: a stored calibration cannot be deleted'); END;
CREATE TRIGGER calibration_readings_append_only_update BEFORE UPDATE ON calibration_readings
BEGIN SELECT RAISE(ABORT, 'calibration readings are append-only: a stored reading cannot be changed'); END;
CREATE TRIGGER calibration_readings_append_only_delete BEFORE DELETE ON calibration_readings
BEGIN SELECT RAISE(ABORT, 'calibration readings are append-only: a stored reading cannot be deleted'); END;
CREATE TRIGGER calibration_checks_append_only_update BEFORE UPDATE ON calibration_checks
BEGIN SELECT RAISE(ABORT, 'calibration checks are append-only: a stored check cannot be changed'); END;
CREATE TRIGGER calibration_checks_append_only_delete BEFORE DELETE ON calibration_checks
BEGIN SELECT RAISE(ABORT, 'calibration checks are append-only: a stored check cannot be deleted'); END;
