#pragma once
// The tables a study file and a display-profile file share (docs/store.md):
// schema_history, displays, calibrations, calibration_readings and
// calibration_checks with their indexes and append-only triggers, each written
// once here. schema.cpp's migrations and profile_schema.cpp's are joined from
// these texts, so the two files' tables are the same column for column and one
// set of Store methods reads and writes both. The texts are those of the study
// file's migrations as they shipped (a migration's SQL is never edited): keep
// them byte for byte. The study file's conventions (schema.cpp) hold here.
#include <algorithm>
#include <array>
#include <cstddef>
#include <string_view>

namespace atonlab::store::sql {

/// SQL texts joined at compile time (char arrays with their terminating NUL):
/// one NUL-terminated array, for a Migration's string_view (text()).
template <std::size_t... N>
constexpr std::array<char, (N + ...) - sizeof...(N) + 1> join(const char (&... parts)[N]) {
    std::array<char, (N + ...) - sizeof...(N) + 1> out{};
    std::size_t at = 0;
    ((std::copy_n(parts, N - 1, out.begin() + static_cast<std::ptrdiff_t>(at)), at += N - 1), ...);
    return out;
}

/// The joined text without its NUL.
template <std::size_t N>
constexpr std::string_view text(const std::array<char, N>& joined) {
    return {joined.data(), N - 1};
}

/// Which atonlab built or migrated the file (study file version 1).
inline constexpr char schema_history[] = R"sql(
-- Which atonlab built or migrated this file, step by step.
CREATE TABLE schema_history (
    version          INTEGER PRIMARY KEY,        -- the user_version this step reached
    description      TEXT NOT NULL,
    software_version TEXT NOT NULL,              -- atonlab version that applied the step
    applied_at       TEXT NOT NULL
);)sql";

/// Displays by name (study file version 1).
inline constexpr char displays[] = R"sql(

-- Displays, by the name the lab gives them.
CREATE TABLE displays (
    id   INTEGER PRIMARY KEY,
    name TEXT NOT NULL UNIQUE CHECK (length(name) > 0)
);)sql";

/// Calibrations of a display (study file version 1).
inline constexpr char calibrations[] = R"sql(

-- A display's geometry and fitted model at one date. Never updated: a new
-- calibration is a new row, so every session keeps the one it ran with.
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
CREATE INDEX calibrations_by_display ON calibrations (display_id, measured_at);)sql";

/// The photometer readings behind a calibration (study file version 2).
inline constexpr char calibration_readings[] = R"sql(
-- The photometer readings a calibration was fitted to, in the order they were
-- measured (or listed in the imported file): the evidence behind its fit_json.
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
    source_line     INTEGER CHECK (source_line > 0),            -- line of the readings file; NULL when typed
    CHECK ((code IS NULL) = (bits IS NULL)),
    CHECK ((xyz_x_cd_m2 IS NULL) = (xyz_z_cd_m2 IS NULL)),
    UNIQUE (calibration_id, seq)
);)sql";

/// The readings' instrument transcripts (study file version 3).
inline constexpr char calibration_readings_transcript[] = R"sql(
ALTER TABLE calibration_readings ADD COLUMN transcript TEXT;  -- what the instrument said; NULL when typed or imported
)sql";

/// Checks of a calibration against fresh readings (study file version 2).
inline constexpr char calibration_checks[] = R"sql(

-- A calibration re-measured on a few patches and compared with its model:
-- pass or fail, with every tolerance, value and patch in results_json.
CREATE TABLE calibration_checks (
    id             INTEGER PRIMARY KEY,
    calibration_id INTEGER NOT NULL REFERENCES calibrations(id),
    checked_at     TEXT NOT NULL,                 -- ISO 8601 date (or date-time) of the measurement
    passed         INTEGER NOT NULL CHECK (passed IN (0, 1)),
    results_json   TEXT NOT NULL CHECK (json_valid(results_json)),
    source         TEXT NOT NULL,                 -- "measured", "readings FILE", ...
    recorded_at    TEXT NOT NULL
);
CREATE INDEX calibration_checks_by_calibration ON calibration_checks (calibration_id, checked_at);)sql";

/// Calibrations, readings and checks append-only (study file version 2).
inline constexpr char calibrations_append_only[] = R"sql(

-- Nothing stored is lost: calibrations, their readings and their checks are
-- never changed or deleted (a new calibration is a new row).
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

}  // namespace atonlab::store::sql
