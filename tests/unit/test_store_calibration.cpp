// Schema version 2 of the study file: calibration readings and checks
// (docs/store.md, docs/calibration.md). A version-1 file, made with the
// version-1 SQL and filled through raw SQLite, migrates to version 2 keeping
// every row; a newer file is refused untouched; readings and checks round-trip
// (read back through raw SQLite, not only the store); bad readings store
// nothing; calibrations, readings and checks are append-only in the file
// itself. (Reading the JSON columns: test_store_json.cpp.)
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "atonlab/store/schema.h"
#include "atonlab/store/store.h"

namespace atonlab::store {
namespace {

using test_support::expect_store_error;
using test_support::file_bytes;
using test_support::RawDb;
using test_support::TempDir;

Calibration make_calibration(const std::string& display = "lab-lcd", const std::string& date = "2024-05-01") {
    Calibration c;
    c.display_name = display;
    c.width_px = 1920;
    c.height_px = 1080;
    c.width_m = 0.598;
    c.height_m = 0.3364;
    c.viewing_distance_m = 0.9;
    c.fit_json = R"({"model":"gog","black_cd_m2":0.2})";
    c.source = "measured";
    c.measured_at = date;
    return c;
}

CalibrationCheck make_check(CalibrationId id, const std::string& date, bool passed, const std::string& json = "{}",
                            const std::string& source = "measured") {
    CalibrationCheck c;
    c.calibration = id;
    c.checked_at = date;
    c.passed = passed;
    c.results_json = json;
    c.source = source;
    return c;
}

std::vector<CalibrationReading> make_readings() {
    CalibrationReading black;
    black.patch = "black";
    black.channel = "grey";
    black.level = 0.0;
    black.code = 0;
    black.bits = 8;
    black.luminance_cd_m2 = 0.21;
    black.source_line = 3;
    CalibrationReading red;
    red.patch = "red-128";
    red.channel = "red";
    red.level = 128.0 / 255.0;
    red.code = 128;
    red.bits = 8;
    red.drive_r = 128.0 / 255.0;
    red.luminance_cd_m2 = 5.125;
    red.xyz_x_cd_m2 = 9.5;
    red.xyz_z_cd_m2 = 0.75;
    red.transcript =
        "Hit ESC or Q to exit, any other key to take a reading: \n Result is XYZ: 9.500000 5.125000 0.750000";
    CalibrationReading imported;  // an imported reading: a fraction, no code
    imported.patch = "grey 0.5";
    imported.channel = "grey";
    imported.level = 0.5;
    imported.drive_r = imported.drive_g = imported.drive_b = 0.5;
    imported.luminance_cd_m2 = 21.75;
    return {black, red, imported};
}

// --- Migration from version 1 ---------------------------------------------------

TEST(StoreSchemaV2, VersionOneFileMigratesKeepingEveryRow) {
    TempDir dir;
    const auto path = dir / "v1.db";
    // A version-1 study, exactly as a version-1 atonlab made it: the v1 step
    // alone, then rows written through SQLite itself.
    detail::migrate_file(path, schema_migrations().first(1));
    {
        RawDb raw(path);
        ASSERT_EQ(raw.integer("PRAGMA user_version"), 1);
        ASSERT_EQ(raw.exec(R"sql(
            INSERT INTO displays (id, name) VALUES (1, 'lab-lcd');
            INSERT INTO calibrations VALUES (1, 1, 1920, 1080, 0.598, 0.3364, 0.9, '{"model":"nominal"}',
                                             'the [display] table of the scene s.toml (not measured)',
                                             '2023-01-02', '2023-01-02T10:00:00.000Z');
            INSERT INTO observers VALUES (1, 'P07', '2023-01-02T10:00:00.000Z');
            INSERT INTO protocols VALUES (1, printf('%064d', 7), 'p.toml', 'text', '2023-01-02T10:00:00.000Z');
            INSERT INTO sessions (id, observer_id, protocol_id, calibration_id, software_version, seed, started_at)
                VALUES (1, 1, 1, 1, '0.0.9', -5, '2023-01-02T10:00:01.000Z');
            INSERT INTO trials VALUES (1, 1, 0, 0, 'c', 'p', 1.5, 1, '{"a":1}', 'left', NULL, 0.5, 2.0, 0, 0,
                                       '{"s":1}', '2023-01-02T10:00:02.000Z');
            INSERT INTO snapshots VALUES (1, 'c', 'exr', x'0102', printf('%064d', 0), '2023-01-02T10:00:03.000Z');
        )sql"),
                  "");
    }
    {
        Store s = Store::create_or_open(path);
        EXPECT_EQ(s.file_schema_version(), schema_version());  // through every later step (5: trial_settings)
        EXPECT_EQ(s.integrity_check(), "ok");
        const auto cal = s.latest_calibration("lab-lcd");
        ASSERT_TRUE(cal.has_value());
        EXPECT_EQ(cal->fit_json, R"({"model":"nominal"})");
        EXPECT_EQ(cal->measured_at, "2023-01-02");
        EXPECT_EQ(cal->width_m, 0.598);
        EXPECT_TRUE(s.calibration_readings(cal->id).empty());
        EXPECT_FALSE(s.latest_calibration_check(cal->id).has_value());
        const auto sessions = s.sessions();
        ASSERT_EQ(sessions.size(), 1u);
        EXPECT_EQ(sessions[0].observer_code, "P07");
        EXPECT_EQ(sessions[0].calibration, CalibrationId{1});
        EXPECT_EQ(sessions[0].seed, static_cast<std::uint64_t>(-5));
        const auto trials = s.trials(SessionId{1});
        ASSERT_EQ(trials.size(), 1u);
        EXPECT_EQ(trials[0].stimulus_json, R"({"a":1})");
        EXPECT_EQ(trials[0].level, 1.5);
        // The new tables work on the migrated file.
        s.put_calibration_check(make_check(cal->id, "2024-01-01", true));
    }
    RawDb raw(path);
    EXPECT_EQ(raw.integer("PRAGMA user_version"), schema_version());
    EXPECT_EQ(raw.text("SELECT group_concat(version, ',') FROM schema_history"), "1,2,3,4,5,6,7");
    EXPECT_EQ(raw.text("SELECT ifnull(displayability_json, 'null') FROM sessions WHERE id = 1"), "null");
    EXPECT_EQ(raw.integer("SELECT count(*) FROM snapshots WHERE data = x'0102'"), 1);
    EXPECT_EQ(raw.text("SELECT source FROM calibrations WHERE id = 1"),
              "the [display] table of the scene s.toml (not measured)");
    EXPECT_EQ(raw.text("PRAGMA foreign_key_check"), "");
}

TEST(StoreSchemaV2, NewerFileIsRefusedUntouched) {
    TempDir dir;
    const auto path = dir / "newer.db";
    { Store::create_or_open(path).put_calibration(make_calibration()); }
    {
        RawDb raw(path);
        ASSERT_EQ(
            raw.exec("PRAGMA wal_checkpoint(TRUNCATE); PRAGMA user_version = " + std::to_string(schema_version() + 1)),
            "");
    }
    const std::string before = file_bytes(path);
    const std::string msg = expect_store_error(StoreErrc::newer_schema, [&] { Store::create_or_open(path); });
    EXPECT_NE(msg.find("schema version " + std::to_string(schema_version() + 1) + ", this build knows up to " +
                       std::to_string(schema_version())),
              std::string::npos)
        << msg;
    expect_store_error(StoreErrc::newer_schema, [&] { Store::open_read_only(path); });
    EXPECT_EQ(file_bytes(path), before);
}

// --- Readings -------------------------------------------------------------------

TEST(StoreCalibrationReadings, RoundTripInMeasuringOrder) {
    TempDir dir;
    const auto path = dir / "study.db";
    const auto readings = make_readings();
    CalibrationId id;
    {
        Store s = Store::create_or_open(path);
        id = s.put_calibration(make_calibration(), readings);
        EXPECT_EQ(s.calibration_readings(id), readings);
    }
    RawDb raw(path);
    EXPECT_EQ(raw.text("SELECT group_concat(patch, '|') FROM (SELECT patch FROM calibration_readings ORDER BY seq)"),
              "black|red-128|grey 0.5");
    EXPECT_EQ(raw.text("SELECT code || ',' || bits || ',' || luminance_cd_m2 || ',' || xyz_x_cd_m2 || ',' || "
                       "xyz_z_cd_m2 FROM calibration_readings WHERE seq = 1"),
              "128,8,5.125,9.5,0.75");
    EXPECT_EQ(raw.text("SELECT quote(code) || quote(bits) || quote(source_line) FROM calibration_readings "
                       "WHERE seq = 2"),
              "NULLNULLNULL");
    EXPECT_EQ(raw.integer("SELECT source_line FROM calibration_readings WHERE seq = 0"), 3);
    EXPECT_EQ(
        raw.integer("SELECT count(*) FROM calibration_readings WHERE calibration_id = " + std::to_string(id.value)), 3);
    // Version 3: an instrument's transcript, byte for byte; NULL for typed and imported readings.
    EXPECT_EQ(raw.text("SELECT transcript FROM calibration_readings WHERE seq = 1"), *readings[1].transcript);
    EXPECT_EQ(raw.text("SELECT quote(transcript) FROM calibration_readings WHERE seq = 0"), "NULL");
}

TEST(StoreSchemaV3, VersionTwoFileKeepsItsReadingsWithoutTranscripts) {
    TempDir dir;
    const auto path = dir / "v2.db";
    detail::migrate_file(path, schema_migrations().first(2));
    {
        RawDb raw(path);
        ASSERT_EQ(raw.exec(R"sql(
            INSERT INTO displays (id, name) VALUES (1, 'lab-lcd');
            INSERT INTO calibrations VALUES (1, 1, 1920, 1080, 0.598, 0.3364, 0.9, '{"model":"gog"}', 'measured',
                                             '2024-01-02', '2024-01-02T10:00:00.000Z');
            INSERT INTO calibration_readings (calibration_id, seq, patch, channel, level, code, bits, drive_r, drive_g,
                                              drive_b, luminance_cd_m2, source_line)
                VALUES (1, 0, 'black', 'grey', 0, 0, 8, 0, 0, 0, 0.25, 2);
        )sql"),
                  "");
    }
    Store s = Store::create_or_open(path);
    EXPECT_EQ(s.file_schema_version(), schema_version());
    const auto readings = s.calibration_readings(CalibrationId{1});
    ASSERT_EQ(readings.size(), 1u);
    EXPECT_EQ(readings[0].luminance_cd_m2, 0.25);
    EXPECT_EQ(readings[0].source_line, 2);
    EXPECT_FALSE(readings[0].transcript.has_value());
}

TEST(StoreCalibrationReadings, BadReadingStoresNothing) {
    TempDir dir;
    Store s = Store::create_or_open(dir / "study.db");
    struct Case {
        const char* why;
        void (*spoil)(CalibrationReading&);
        const char* expect;
    };
    const Case cases[] = {
        {"negative luminance", [](CalibrationReading& r) { r.luminance_cd_m2 = -1.0; }, "luminance -1"},
        {"unknown channel", [](CalibrationReading& r) { r.channel = "yellow"; }, "channel \"yellow\""},
        {"level above 1", [](CalibrationReading& r) { r.level = 1.5; }, "level 1.5"},
        {"code without bits", [](CalibrationReading& r) { r.bits.reset(); }, "without its bits"},
        {"code too big", [](CalibrationReading& r) { r.code = 256; }, "code 256"},
        {"X without Z", [](CalibrationReading& r) { r.xyz_z_cd_m2.reset(); }, "X without Z"},
        {"empty patch", [](CalibrationReading& r) { r.patch.clear(); }, "no patch name"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.why);
        auto readings = make_readings();
        c.spoil(readings[1]);
        const std::string msg =
            expect_store_error(StoreErrc::invalid_argument, [&] { s.put_calibration(make_calibration(), readings); });
        EXPECT_NE(msg.find("reading 1"), std::string::npos) << msg;
        EXPECT_NE(msg.find(c.expect), std::string::npos) << msg;
    }
    EXPECT_FALSE(s.latest_calibration("lab-lcd").has_value());  // not even the calibration row
    expect_store_error(StoreErrc::not_found, [&] { s.calibration_readings(CalibrationId{99}); });
}

TEST(StoreCalibrationReadings, CalibrationsReadingsAndChecksAreAppendOnly) {
    TempDir dir;
    const auto path = dir / "study.db";
    {
        Store s = Store::create_or_open(path);
        const CalibrationId id = s.put_calibration(make_calibration(), make_readings());
        s.put_calibration_check(make_check(id, "2024-06-01", false));
    }
    RawDb raw(path);
    EXPECT_NE(raw.exec("UPDATE calibrations SET fit_json = '{}'").find("append-only"), std::string::npos);
    EXPECT_NE(raw.exec("DELETE FROM calibrations").find("append-only"), std::string::npos);
    EXPECT_NE(raw.exec("UPDATE calibration_readings SET luminance_cd_m2 = 1").find("append-only"), std::string::npos);
    EXPECT_NE(raw.exec("DELETE FROM calibration_readings").find("append-only"), std::string::npos);
    EXPECT_NE(raw.exec("UPDATE calibration_checks SET passed = 1").find("append-only"), std::string::npos);
    EXPECT_NE(raw.exec("DELETE FROM calibration_checks").find("append-only"), std::string::npos);
    EXPECT_EQ(raw.integer("SELECT count(*) FROM calibration_readings"), 3);
    EXPECT_EQ(raw.integer("SELECT passed FROM calibration_checks"), 0);
}

// --- Checks and the list of a display's calibrations ------------------------------

TEST(StoreCalibrationChecks, LatestByDateThenByRow) {
    TempDir dir;
    Store s = Store::create_or_open(dir / "study.db");
    const CalibrationId old_cal = s.put_calibration(make_calibration("lab-lcd", "2024-01-01"));
    const CalibrationId new_cal = s.put_calibration(make_calibration("lab-lcd", "2024-03-01T09:30:00Z"));
    s.put_calibration(make_calibration("other", "2025-01-01"));
    const auto all = s.calibrations("lab-lcd");
    ASSERT_EQ(all.size(), 2u);
    EXPECT_EQ(all[0].id, new_cal);
    EXPECT_EQ(all[1].id, old_cal);
    EXPECT_TRUE(s.calibrations("nobody").empty());

    EXPECT_FALSE(s.latest_calibration_check(new_cal).has_value());
    const auto a = s.put_calibration_check(make_check(new_cal, "2024-04-02", false, R"({"failed":["peak_percent"]})"));
    const auto b = s.put_calibration_check(make_check(new_cal, "2024-04-01", true));
    const auto latest = s.latest_calibration_check(new_cal);
    ASSERT_TRUE(latest.has_value());
    EXPECT_EQ(latest->id, a);  // the later date, though stored first
    EXPECT_FALSE(latest->passed);
    EXPECT_EQ(latest->results_json, R"({"failed":["peak_percent"]})");
    EXPECT_FALSE(latest->recorded_at.empty());
    const auto checks = s.calibration_checks(new_cal);
    ASSERT_EQ(checks.size(), 2u);
    EXPECT_EQ(checks[1].id, b);
    EXPECT_TRUE(s.calibration_checks(old_cal).empty());

    expect_store_error(StoreErrc::not_found,
                       [&] { s.put_calibration_check(make_check(CalibrationId{42}, "2024-01-01", true)); });
    expect_store_error(StoreErrc::invalid_argument,
                       [&] { s.put_calibration_check(make_check(new_cal, "2024-01-01", true, "{oops")); });
    expect_store_error(StoreErrc::invalid_argument,
                       [&] { s.put_calibration_check(make_check(new_cal, "yesterday", true)); });
}

}  // namespace
}  // namespace atonlab::store
