// The display-profile file's schema (docs/store.md, "The display-profile
// file"): a lab's displays with their calibrations, the readings behind them
// and their checks, shared by every study. Its own file kind (application_id
// 'ATPF') with its own migrations, so that it can evolve apart from the study
// file. Its tables are the study file's tables of the same names, column for
// column, so that one set of Store methods reads and writes both, and a
// session can copy a calibration from one into the other unchanged.
#include <array>

#include "atonlab/store/schema.h"

namespace atonlab::store {
namespace {

// The study file's conventions (schema.cpp) hold here too.
constexpr std::string_view profile_v1 = R"sql(
-- Which atonlab built or migrated this file, step by step.
CREATE TABLE schema_history (
    version          INTEGER PRIMARY KEY,
    description      TEXT NOT NULL,
    software_version TEXT NOT NULL,
    applied_at       TEXT NOT NULL
);

-- Displays, by the name the lab gives them (the protocol's [display] name).
CREATE TABLE displays (
    id   INTEGER PRIMARY KEY,
    name TEXT NOT NULL UNIQUE CHECK (length(name) > 0)
);

-- A display's geometry and fitted model at one date; a new calibration is a new row.
CREATE TABLE calibrations (
    id                 INTEGER PRIMARY KEY,
    display_id         INTEGER NOT NULL REFERENCES displays(id),
    width_px           INTEGER NOT NULL CHECK (width_px > 0),
    height_px          INTEGER NOT NULL CHECK (height_px > 0),
    width_m            REAL NOT NULL CHECK (width_m > 0),
    height_m           REAL NOT NULL CHECK (height_m > 0),
    viewing_distance_m REAL NOT NULL CHECK (viewing_distance_m > 0),
    fit_json           TEXT NOT NULL CHECK (json_valid(fit_json)),
    source             TEXT NOT NULL,
    measured_at        TEXT NOT NULL,
    recorded_at        TEXT NOT NULL
);
CREATE INDEX calibrations_by_display ON calibrations (display_id, measured_at);

-- The photometer readings each calibration was fitted to (as in a study file).
CREATE TABLE calibration_readings (
    id              INTEGER PRIMARY KEY,
    calibration_id  INTEGER NOT NULL REFERENCES calibrations(id),
    seq             INTEGER NOT NULL CHECK (seq >= 0),
    patch           TEXT NOT NULL CHECK (length(patch) > 0),
    channel         TEXT NOT NULL CHECK (channel IN ('red', 'green', 'blue', 'grey', 'other')),
    level           REAL NOT NULL CHECK (level BETWEEN 0 AND 1),
    code            INTEGER CHECK (code >= 0),
    bits            INTEGER CHECK (bits BETWEEN 1 AND 16),
    drive_r         REAL NOT NULL CHECK (drive_r BETWEEN 0 AND 1),
    drive_g         REAL NOT NULL CHECK (drive_g BETWEEN 0 AND 1),
    drive_b         REAL NOT NULL CHECK (drive_b BETWEEN 0 AND 1),
    luminance_cd_m2 REAL NOT NULL CHECK (luminance_cd_m2 >= 0),
    xyz_x_cd_m2     REAL,
    xyz_z_cd_m2     REAL,
    source_line     INTEGER CHECK (source_line > 0),
    transcript      TEXT,  -- what the instrument said; NULL when typed or imported (the study file's version 3)
    CHECK ((code IS NULL) = (bits IS NULL)),
    CHECK ((xyz_x_cd_m2 IS NULL) = (xyz_z_cd_m2 IS NULL)),
    UNIQUE (calibration_id, seq)
);

-- Checks of a calibration against fresh readings: the display's drift over time.
CREATE TABLE calibration_checks (
    id             INTEGER PRIMARY KEY,
    calibration_id INTEGER NOT NULL REFERENCES calibrations(id),
    checked_at     TEXT NOT NULL,
    passed         INTEGER NOT NULL CHECK (passed IN (0, 1)),
    results_json   TEXT NOT NULL CHECK (json_valid(results_json)),
    source         TEXT NOT NULL,
    recorded_at    TEXT NOT NULL
);
CREATE INDEX calibration_checks_by_calibration ON calibration_checks (calibration_id, checked_at);

-- Nothing stored is lost: calibrations, readings and checks are append-only.
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
)sql";

constexpr std::array<Migration, 1> migrations = {
    Migration{1, "displays, calibrations, calibration readings and checks", profile_v1},
};

}  // namespace

std::span<const Migration> profile_migrations() noexcept {
    return migrations;
}

int profile_schema_version() noexcept {
    return migrations.back().to_version;
}

}  // namespace atonlab::store
