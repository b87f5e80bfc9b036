// The lab's display-profile file end to end, through the binary
// (ATONLAB_BINARY, set by tests/e2e/CMakeLists.txt; docs/calibration.md, "The
// display-profile file"): `calibrate import` names every missing option at
// once and creates nothing; a display imported once into the profile file is
// used by two studies, each holding a copy of the fit it used; study files of
// schema 1 and 2 with their own calibration still run; `calibrate show` prints
// the stored check in its drift table. XDG_DATA_HOME points into the test's
// folder, so the user's own profile file is never read or written.
// Skips where the binary finds no GL 4.5 context (exit status 3).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "../support/child_process.h"
#include "atonlab/store/profiles.h"
#include "atonlab/store/schema.h"
#include "atonlab/store/store.h"
#include "../support/skip.h"
#include "text_contains.h"

#ifndef ATONLAB_BINARY
#error "ATONLAB_BINARY (the atonlab executable) must be defined by the build"
#endif

namespace atonlab {
namespace {

namespace fs = std::filesystem;
using store::Profiles;
using store::Store;
using store::test_support::file_bytes;
using store::test_support::RawDb;
using store::test_support::TempDir;

const fs::path kData = fs::path(ATONLAB_SOURCE_DIR) / "tests/data";

using Result = test::Captured;
using test::atonlab;

using ::atonlab::test::contains;

/// tests/data/run/small_2afc.toml with its display named `display`, written to dir.
fs::path protocol_for(const fs::path& dir, const std::string& display) {
    std::string text = file_bytes(kData / "run/small_2afc.toml");
    const std::string scene_line = "scene = \"small.scene.toml\"";
    text.replace(text.find(scene_line), scene_line.size(),
                 "scene = \"" + (kData / "run/small.scene.toml").string() + "\"");
    const std::string header = "[display]\n";
    text.insert(text.find(header) + header.size(), "name = \"" + display + "\"\nmax_calibration_age_days = 100000\n");
    const fs::path p = dir / (display + ".toml");
    std::ofstream(p) << text;
    return p;
}

const std::vector<std::string> kGeometry = {"--width-px", "320", "--height-px",          "180",
                                            "--width-m",  "0.1", "--viewing-distance-m", "0.9"};

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

class CalibrateProfiles : public ::testing::Test {
protected:
    void SetUp() override { ::setenv("XDG_DATA_HOME", (dir_ / "xdg").c_str(), 1); }
    void TearDown() override { ::unsetenv("XDG_DATA_HOME"); }
    fs::path profiles() const { return dir_ / "profiles.sqlite"; }
    Result run(const fs::path& protocol, const fs::path& db, std::vector<std::string> extra = {}) {
        Result r = atonlab(with({"run", protocol.string(), "--db", db.string(), "--model-observer", "--headless",
                                 "--quiet", "--no-true-pse"},
                                extra),
                           dir_.path());
        if (r.code == 3) skip_ = "no GL 4.5 context: " + r.err;
        return r;
    }
    TempDir dir_;
    std::string skip_;
};

TEST_F(CalibrateProfiles, ImportNamesEveryMissingOptionAtOnceAndCreatesNothing) {
    const Result r = atonlab({"calibrate", "import", (kData / "calibration/grey_ramp.csv").string(), "--display",
                              "booth-2", "--profiles", profiles().string(), "--width-px", "320"},
                             dir_.path());
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_TRUE(contains(r.err, "--height-px")) << r.err;
    EXPECT_TRUE(contains(r.err, "--width-m")) << r.err;
    EXPECT_TRUE(contains(r.err, "--viewing-distance-m")) << r.err;
    EXPECT_TRUE(contains(r.err, "are needed")) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(profiles()));
    // Nothing but the file: the readings file, --display and the four geometry options, in one sentence.
    const Result bare = atonlab({"calibrate", "import", "--profiles", profiles().string()}, dir_.path());
    EXPECT_EQ(bare.code, 2) << bare.err;
    for (const char* what :
         {"the readings file", "--display", "--width-px", "--height-px", "--width-m", "--viewing-distance-m"})
        EXPECT_TRUE(contains(bare.err, what)) << what << ": " << bare.err;
    EXPECT_EQ(std::count(bare.err.begin(), bare.err.end(), '\n'), 1) << bare.err;
    EXPECT_FALSE(fs::exists(profiles()));
    // Without --profiles, --db or ATONLAB_PROFILES: the per-user default, still not created on bad input.
    const Result d =
        atonlab({"calibrate", "import", (kData / "calibration/grey_ramp.csv").string(), "--display", "x"}, dir_.path());
    EXPECT_EQ(d.code, 2) << d.err;
    EXPECT_TRUE(contains(d.err, (dir_ / "xdg/atonlab/profiles.sqlite").string())) << d.err;
    EXPECT_FALSE(fs::exists(dir_ / "xdg/atonlab/profiles.sqlite"));
}

TEST_F(CalibrateProfiles, EightBitLevelsWithTheScaleGivenStoreTheSameFitAsFractions) {
    // grey_ramp.csv's readings at codes 0, 32, ..., 255 written three ways.
    const char* codes[] = {"0", "32", "64", "96", "128", "159", "191", "223", "255"};
    const char* cd[] = {"0.21", "0.74", "2.61", "6.22", "11.9", "19.5", "30.3", "43.4", "59.8"};
    std::ofstream fractions(dir_ / "fractions.csv"), named(dir_ / "named.csv"), plain(dir_ / "plain.csv");
    fractions << "level,channel,cd_m2\n";
    named << "level_8bit,channel,cd_m2\n";
    plain << "level,channel,cd_m2\n";
    for (int i = 0; i < 9; ++i) {
        fractions << fmt::format("{:.17g},grey,{}\n", std::stoi(codes[i]) / 255.0, cd[i]);
        named << codes[i] << ",grey," << cd[i] << "\n";
        plain << codes[i] << ",grey," << cd[i] << "\n";
    }
    fractions.close();
    named.close();
    plain.close();
    std::vector<std::string> fits;
    for (const auto& [file, extra] : {std::pair{"fractions.csv", ""}, {"named.csv", ""}, {"plain.csv", "8bit"}}) {
        SCOPED_TRACE(file);
        std::vector<std::string> args = {"calibrate", "import",     (dir_ / file).string(), "--display",
                                         file,        "--profiles", profiles().string()};
        if (*extra) args = with(args, {"--drive-scale", extra});
        const Result r = atonlab(with(args, kGeometry), dir_.path());
        ASSERT_EQ(r.code, 0) << r.err;
        fits.push_back(Profiles::open_read_only(profiles()).displays().latest_calibration(file)->fit_json);
    }
    EXPECT_EQ(fits[1], fits[0]);
    EXPECT_EQ(fits[2], fits[0]);
    // The plain column without the option: refused, naming the scales.
    const Result r = atonlab(with({"calibrate", "import", (dir_ / "plain.csv").string(), "--display", "x", "--profiles",
                                   profiles().string()},
                                  kGeometry),
                             dir_.path());
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "plain.csv:3: key 'level': the drive level 32 is not a fraction")) << r.err;
    EXPECT_TRUE(contains(r.err, "--drive-scale 8bit or 10bit")) << r.err;
}

TEST_F(CalibrateProfiles, OneImportServesTwoStudiesEachHoldingACopy) {
    Result r = atonlab(with({"calibrate", "import", (kData / "calibration/grey_ramp.csv").string(), "--display",
                             "booth-2", "--profiles", profiles().string(), "--date", "2024-05-01"},
                            kGeometry),
                       dir_.path());
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string fit = Profiles::open_read_only(profiles()).displays().latest_calibration("booth-2")->fit_json;
    const fs::path protocol = protocol_for(dir_.path(), "booth-2");
    for (const char* name : {"a.db", "b.db"}) {
        SCOPED_TRACE(name);
        r = run(protocol, dir_ / name, {"--profiles", profiles().string()});
        if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
        ASSERT_EQ(r.code, 0) << r.err;
        EXPECT_FALSE(contains(r.err, "has no calibration")) << r.err;
        const Store s = Store::open_read_only(dir_ / name);
        const auto session = s.session(store::SessionId{1});
        ASSERT_TRUE(session.calibration.has_value());
        const store::Calibration c = s.calibration(*session.calibration);
        EXPECT_EQ(c.fit_json, fit);
        EXPECT_EQ(c.measured_at, "2024-05-01");
        EXPECT_TRUE(contains(c.source, "copied from the display-profile file")) << c.source;
        EXPECT_EQ(s.calibration_readings(c.id).size(), 10u);  // grey_ramp.csv's readings travel with it
    }
    // The same through ATONLAB_PROFILES, a second session: no second copy.
    ::setenv("ATONLAB_PROFILES", profiles().c_str(), 1);
    r = run(protocol, dir_ / "a.db");
    ::unsetenv("ATONLAB_PROFILES");
    ASSERT_EQ(r.code, 0) << r.err;
    const Store a = Store::open_read_only(dir_ / "a.db");
    EXPECT_EQ(a.session(store::SessionId{2}).calibration, a.session(store::SessionId{1}).calibration);
    EXPECT_EQ(a.calibrations("booth-2").size(), 1u);
    // A profile file that does not exist, named by the user: exit 2, no study file.
    r = run(protocol, dir_ / "c.db", {"--profiles", (dir_ / "none.sqlite").string()});
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "c.db"));
}

TEST_F(CalibrateProfiles, OldStudyFilesWithTheirOwnCalibrationStillRun) {
    // The profile file holds an older calibration of the display; each study its own, later one.
    Result r = atonlab(with({"calibrate", "import", (kData / "calibration/grey_ramp.csv").string(), "--display",
                             "booth-2", "--profiles", profiles().string(), "--date", "2020-01-01"},
                            kGeometry),
                       dir_.path());
    ASSERT_EQ(r.code, 0) << r.err;
    const fs::path dim = dir_ / "dim.csv";
    std::ofstream(dim) << "level,channel,cd_m2\n0,black,0.05\n0.25,grey,0.6\n0.5,grey,2.6\n0.75,grey,6.4\n1,white,12\n";
    // Schema 2: made by `calibrate import --db` as before.
    const fs::path v2 = dir_ / "v2.db";
    r = atonlab(
        with({"calibrate", "import", dim.string(), "--display", "booth-2", "--db", v2.string(), "--date", "2024-05-01"},
             kGeometry),
        dir_.path());
    ASSERT_EQ(r.code, 0) << r.err;
    const std::string own_fit = Store::open_read_only(v2).latest_calibration("booth-2")->fit_json;
    // Schema 1: the version-1 step alone, its calibration row written through SQLite.
    const fs::path v1 = dir_ / "v1.db";
    store::detail::migrate_file(v1, store::schema_migrations().first(1));
    {
        RawDb raw(v1);
        sqlite3_stmt* s = nullptr;
        ASSERT_EQ(
            sqlite3_prepare_v2(raw.get(), "INSERT INTO displays (id, name) VALUES (1, 'booth-2'); ", -1, &s, nullptr),
            SQLITE_OK);
        ASSERT_EQ(sqlite3_step(s), SQLITE_DONE);
        sqlite3_finalize(s);
        ASSERT_EQ(sqlite3_prepare_v2(raw.get(),
                                     "INSERT INTO calibrations VALUES (1, 1, 320, 180, 0.1, 0.05625, 0.9, ?1, "
                                     "'imported dim.csv', '2024-05-01', '2024-05-01T10:00:00.000Z')",
                                     -1, &s, nullptr),
                  SQLITE_OK);
        sqlite3_bind_text(s, 1, own_fit.c_str(), -1, SQLITE_TRANSIENT);
        ASSERT_EQ(sqlite3_step(s), SQLITE_DONE);
        sqlite3_finalize(s);
        ASSERT_EQ(raw.integer("PRAGMA user_version"), 1);
    }
    const fs::path protocol = protocol_for(dir_.path(), "booth-2");
    for (const fs::path& db : {v1, v2}) {
        SCOPED_TRACE(db.filename().string());
        r = run(protocol, db, {"--profiles", profiles().string()});
        if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
        ASSERT_EQ(r.code, 0) << r.err;
        const Store s = Store::open_read_only(db);
        EXPECT_EQ(s.file_schema_version(), store::schema_version());
        const auto session = s.session(store::SessionId{1});
        ASSERT_TRUE(session.calibration.has_value());
        EXPECT_EQ(session.calibration->value, 1);  // the study's own
        EXPECT_EQ(s.calibration(*session.calibration).fit_json, own_fit);
        EXPECT_EQ(s.calibrations("booth-2").size(), 1u) << "nothing copied from the profile file";
    }
}

TEST_F(CalibrateProfiles, ShowPrintsTheStoredCheckInTheDriftTable) {
    Result r = atonlab(with({"calibrate", "import", (kData / "calibration/grey_ramp.csv").string(), "--display",
                             "booth-2", "--profiles", profiles().string(), "--date", "2024-05-01"},
                            kGeometry),
                       dir_.path());
    ASSERT_EQ(r.code, 0) << r.err;
    const fs::path low = dir_ / "low.txt";
    std::ofstream(low) << "0.1\n1\n2\n3\n4\n";
    r = atonlab({"calibrate", "check", "--display", "booth-2", "--profiles", profiles().string(), "--headless",
                 "--readings", low.string(), "--no-plot", "--date", "2024-06-01"},
                dir_.path());
    if (r.code == 3) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << r.err;
    ASSERT_EQ(r.code, 1) << r.out << r.err;
    r = atonlab({"calibrate", "show", "--display", "booth-2", "--profiles", profiles().string(), "--plot",
                 (dir_ / "drift.svg").string()},
                dir_.path());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "drift: 1 check")) << r.out;
    EXPECT_TRUE(contains(r.out, "2024-06-01")) << r.out;
    EXPECT_TRUE(contains(r.out, "FAILED")) << r.out;
    EXPECT_TRUE(contains(r.out, " 4 (")) << r.out;  // white read 4 cd/m²
    r = atonlab({"calibrate", "list", "--profiles", profiles().string()}, dir_.path());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "display \"booth-2\"")) << r.out;
    EXPECT_TRUE(contains(r.out, "1 check, the latest FAILED on 2024-06-01")) << r.out;
    // A study file is refused as a profile file, unchanged.
    r = atonlab({"calibrate", "list", "--profiles", (dir_ / "none.db").string()}, dir_.path());
    EXPECT_EQ(r.code, 2) << r.err;
}

}  // namespace
}  // namespace atonlab
