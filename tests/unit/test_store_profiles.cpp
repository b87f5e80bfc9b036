// The display-profile file (atonlab/store/profiles.h, docs/store.md "The
// display-profile file"): its own application_id and schema version, the
// display methods on it, and each kind of file refused where the other is
// expected, unchanged. Values are checked through a raw SQLite connection.
#include <gtest/gtest.h>

#include "../store/store_test_support.h"
#include "atonlab/store/profiles.h"
#include "atonlab/store/schema.h"

namespace atonlab::store {
namespace {

using test_support::expect_store_error;
using test_support::file_bytes;
using test_support::RawDb;
using test_support::TempDir;

Calibration calibration(const std::string& display, const std::string& date) {
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

TEST(StoreProfiles, NewFileHasItsOwnIdAndSchemaAndHoldsCalibrationsAndChecks) {
    TempDir dir;
    const auto path = dir / "profiles.sqlite";
    {
        Profiles p = Profiles::create_or_open(path);
        Store& s = p.displays();
        CalibrationReading r;
        r.patch = "white";
        r.channel = "grey";
        r.level = 1.0;
        r.drive_r = r.drive_g = r.drive_b = 1.0;
        r.luminance_cd_m2 = 120.5;
        const CalibrationId a = s.put_calibration(calibration("lab-lcd", "2024-05-01"), std::vector{r});
        s.put_calibration(calibration("booth-2", "2024-05-02"));
        CalibrationCheck k;
        k.calibration = a;
        k.checked_at = "2024-06-01";
        k.passed = false;
        k.results_json = R"({"failed":["peak_percent"]})";
        k.source = "measured";
        s.put_calibration_check(k);
        EXPECT_EQ(s.display_names(), (std::vector<std::string>{"booth-2", "lab-lcd"}));
        EXPECT_EQ(s.file_schema_version(), profile_schema_version());
    }
    RawDb raw(path);
    EXPECT_EQ(raw.integer("PRAGMA application_id"), 0x41545046);  // 'ATPF'
    EXPECT_EQ(raw.integer("PRAGMA user_version"), 1);
    EXPECT_EQ(raw.text("SELECT group_concat(name, ',') FROM displays ORDER BY id"), "lab-lcd,booth-2");
    EXPECT_EQ(raw.text("SELECT luminance_cd_m2 FROM calibration_readings"), "120.5");
    EXPECT_EQ(raw.text("SELECT checked_at || ' ' || passed FROM calibration_checks"), "2024-06-01 0");
    EXPECT_EQ(raw.integer("SELECT count(*) FROM sqlite_schema WHERE name IN ('sessions', 'trials')"), 0);
    // Append-only, as in a study file.
    EXPECT_NE(raw.exec("UPDATE calibrations SET width_px = 1"), "");
    // Read back read-only.
    const Profiles ro = Profiles::open_read_only(path);
    const auto latest = ro.displays().latest_calibration("lab-lcd");
    ASSERT_TRUE(latest.has_value());
    EXPECT_EQ(latest->measured_at, "2024-05-01");
    EXPECT_EQ(ro.displays().calibration_readings(latest->id).at(0).luminance_cd_m2, 120.5);
    EXPECT_FALSE(ro.displays().latest_calibration_check(latest->id)->passed);
}

TEST(StoreProfiles, EachKindIsRefusedWhereTheOtherIsExpectedUnchanged) {
    TempDir dir;
    const auto study = dir / "study.db";
    const auto profiles = dir / "profiles.sqlite";
    { Store::create_or_open(study).put_calibration(calibration("lab-lcd", "2024-05-01")); }
    { Profiles::create_or_open(profiles).displays().put_calibration(calibration("lab-lcd", "2024-05-01")); }
    const std::string study_bytes = file_bytes(study), profile_bytes = file_bytes(profiles);

    std::string msg = expect_store_error(StoreErrc::not_a_study, [&] { Profiles::create_or_open(study); });
    EXPECT_NE(msg.find("is an atonlab study file, not a display-profile file"), std::string::npos) << msg;
    EXPECT_NE(msg.find("--db"), std::string::npos) << msg;
    msg = expect_store_error(StoreErrc::not_a_study, [&] { Store::create_or_open(profiles); });
    EXPECT_NE(msg.find("is an atonlab display-profile file, not a study file"), std::string::npos) << msg;
    EXPECT_NE(msg.find("--profiles"), std::string::npos) << msg;
    expect_store_error(StoreErrc::not_a_study, [&] { Store::open_read_only(profiles); });
    expect_store_error(StoreErrc::not_a_study, [&] { Profiles::open_read_only(study); });
    EXPECT_EQ(file_bytes(study), study_bytes);
    EXPECT_EQ(file_bytes(profiles), profile_bytes);

    // A missing file: named as a display-profile file.
    msg = expect_store_error(StoreErrc::cannot_open, [&] { Profiles::open_existing(dir / "none.sqlite"); });
    EXPECT_NE(msg.find("cannot open the display-profile file: it does not exist"), std::string::npos) << msg;
    // An SQLite file of someone else's: not a display-profile file.
    const auto foreign = dir / "foreign.sqlite";
    {
        RawDb raw(foreign, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
        ASSERT_EQ(raw.exec("CREATE TABLE t (x)"), "");
    }
    msg = expect_store_error(StoreErrc::not_a_study, [&] { Profiles::create_or_open(foreign); });
    EXPECT_NE(msg.find("not an atonlab display-profile file"), std::string::npos) << msg;
}

TEST(StoreProfiles, NewerProfileFileIsRefusedUntouched) {
    TempDir dir;
    const auto path = dir / "profiles.sqlite";
    { Profiles::create_or_open(path); }
    {
        RawDb raw(path);
        ASSERT_EQ(raw.exec("PRAGMA user_version = 99"), "");
    }
    const std::string before = file_bytes(path);
    const std::string msg = expect_store_error(StoreErrc::newer_schema, [&] { Profiles::create_or_open(path); });
    EXPECT_NE(msg.find("schema version 99"), std::string::npos) << msg;
    EXPECT_EQ(file_bytes(path), before);
}

}  // namespace
}  // namespace atonlab::store
