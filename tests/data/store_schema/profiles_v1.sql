-- The schema of an atonlab file at user_version 1, as SQLite stores it
-- (scripts/schema_fixture.sh; tests/data/store_schema/README.md). A released
-- version never changes: do not edit.
CREATE TABLE schema_history (
    version          INTEGER PRIMARY KEY,        -- the user_version this step reached
    description      TEXT NOT NULL,
    software_version TEXT NOT NULL,              -- atonlab version that applied the step
    applied_at       TEXT NOT NULL
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
