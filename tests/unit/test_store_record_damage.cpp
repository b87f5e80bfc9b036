// Damage inside a record, the page structure intact (docs/store.md, "Opening"):
// bytes overwritten inside one trial's stimulus_json, inside a session's
// displayability_json and inside a display-profile file's fit_json. SQLite's
// integrity_check finds it only on a connection that may write (SQLite 3.40,
// Debian 12, does not load CHECK constraints on a read-only one), so a reader
// used to analyse such a file without a word. Every open, read-only or not,
// refuses it with the same sentence naming the row and the constraint; the
// file is left byte for byte; salvage leaves the row out and names it. The
// damaged row is found independently by SQL over a raw connection.
#include <gtest/gtest.h>
#include <iconv.h>

#include <cerrno>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "atonlab/store/json.h"
#include "atonlab/store/profiles.h"
#include "atonlab/store/store.h"
#include "text_contains.h"

namespace atonlab::store {
namespace {

namespace fs = std::filesystem;
using test_support::expect_store_error;
using test_support::file_bytes;
using test_support::make_start;
using test_support::make_trial;
using test_support::RawDb;
using test_support::TempDir;

using ::atonlab::test::contains;

/// Whether `s` is valid UTF-8, by glibc's iconv (not by the code under test).
bool valid_utf8(const std::string& s) {
    iconv_t cd = iconv_open("UTF-32LE", "UTF-8");
    if (cd == reinterpret_cast<iconv_t>(-1)) return false;
    std::string in = s;
    std::vector<char> out(4 * s.size() + 4);
    char* inp = in.data();
    char* outp = out.data();
    std::size_t inleft = in.size(), outleft = out.size();
    const std::size_t r = iconv(cd, &inp, &inleft, &outp, &outleft);
    iconv_close(cd);
    return r != static_cast<std::size_t>(-1) && inleft == 0;
}

/// Overwrites, in the file's bytes, the byte `at` bytes into the one place
/// `marker` occurs, with `byte`. The record keeps its length: no page header,
/// cell pointer or record header changes.
void overwrite_inside(const fs::path& path, const std::string& marker, std::size_t at, char byte) {
    const std::string bytes = file_bytes(path);
    const std::size_t where = bytes.find(marker);
    ASSERT_NE(where, std::string::npos) << marker;
    ASSERT_EQ(bytes.find(marker, where + 1), std::string::npos) << marker << " occurs more than once";
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(where + at));
    f.put(byte);
    ASSERT_TRUE(f.good());
}

/// A closed study file (no -wal) with one session of `n` trials; the session
/// carries `displayability` as its displayability_json when not empty.
void write_study(const fs::path& path, int n, const std::string& displayability = "") {
    Store s = Store::create_or_open(path);
    SessionStart start = make_start();
    start.displayability_json = displayability;
    const SessionId id = s.begin_session(start);
    for (int i = 0; i < n; ++i) s.record_trial(id, make_trial(i, "record"));
    s.finish_session(id, SessionStatus::completed);
}

/// SQLite's own verdicts: a read-write connection's integrity_check sees the
/// broken CHECK; `query` (SQL over the raw file) gives the damaged row's id.
std::int64_t damaged_row(const fs::path& path, const std::string& expected_report, const std::string& query) {
    RawDb raw(path);
    EXPECT_EQ(raw.text("PRAGMA integrity_check"), expected_report);
    return raw.integer(query);
}

/// Read-only and read-write opens refuse the file with one and the same
/// sentence; its bytes are as before. Returns the sentence.
template <class Open>
std::string expect_refused_alike(const fs::path& path, Open read_only, Open read_write, Open existing) {
    const std::string before = file_bytes(path);
    const std::string ro = expect_store_error(StoreErrc::corrupt, [&] { read_only(path); });
    const std::string rw = expect_store_error(StoreErrc::corrupt, [&] { read_write(path); });
    const std::string ex = expect_store_error(StoreErrc::corrupt, [&] { existing(path); });
    EXPECT_EQ(ro, rw) << "a reader and a writer say the same";
    EXPECT_EQ(ro, ex);
    EXPECT_TRUE(contains(ro, path.string())) << ro;
    EXPECT_TRUE(contains(ro, "is damaged")) << ro;
    EXPECT_TRUE(contains(ro, "not changed")) << ro;
    EXPECT_FALSE(contains(ro, "\n")) << ro;
    EXPECT_TRUE(valid_utf8(ro)) << ro;
    EXPECT_EQ(file_bytes(path), before) << "the refused file was changed";
    return ro;
}

const auto study_ro = [](const fs::path& p) { Store::open_read_only(p); };
const auto study_rw = [](const fs::path& p) { Store::create_or_open(p); };
const auto study_ex = [](const fs::path& p) { Store::open_existing(p); };

TEST(StoreRecordDamage, StimulusJsonOverwrittenInsideOneTrialIsRefusedByReadersAndWritersAlike) {
    TempDir dir;
    const fs::path path = dir / "study.db";
    write_study(path, 20);
    // Trial 7's JSON {"i":7,"tag":"record",...}: its first quote becomes 0xB0.
    overwrite_inside(path, "{\"i\":7,\"tag\"", 1, '\xb0');
    const std::int64_t row = damaged_row(path, "CHECK constraint failed in trials",
                                         "SELECT id FROM trials WHERE NOT json_valid(stimulus_json)");
    const std::string msg = expect_refused_alike(path, +study_ro, +study_rw, +study_ex);
    EXPECT_TRUE(contains(msg, "row " + std::to_string(row) + " of trials breaks CHECK (json_valid(stimulus_json))"))
        << msg;
    EXPECT_TRUE(contains(msg, "atonlab analyze --salvage")) << msg;
}

TEST(StoreRecordDamage, SalvageLeavesTheDamagedTrialOutAndNamesIt) {
    TempDir dir;
    const fs::path path = dir / "study.db";
    write_study(path, 20);
    overwrite_inside(path, "{\"i\":7,\"tag\"", 1, '\xb0');
    const std::int64_t row = damaged_row(path, "CHECK constraint failed in trials",
                                         "SELECT id FROM trials WHERE NOT json_valid(stimulus_json)");
    const std::string before = file_bytes(path);
    StoreOptions salvage;
    salvage.verify = false;
    const Salvage got = Store::open_read_only(path, salvage).salvage();
    ASSERT_EQ(got.sessions.size(), 1u);
    EXPECT_EQ(got.trials.size(), 19u);
    EXPECT_EQ(got.unreadable_trials, 1);
    ASSERT_EQ(got.skipped.size(), 1u);
    EXPECT_EQ(got.skipped[0].table, "trials");
    EXPECT_EQ(got.skipped[0].row_id, row);
    EXPECT_EQ(got.skipped[0].why, "breaks CHECK (json_valid(stimulus_json))");
    for (const SalvagedTrial& t : got.trials) {
        EXPECT_NE(t.trial.trial_index, 7);
        test_support::expect_same_trial(t.trial, make_trial(t.trial.trial_index, "record"));
    }
    EXPECT_EQ(file_bytes(path), before);
}

TEST(StoreRecordDamage, DisplayabilityJsonOverwrittenIsRefusedInValidUtf8AndSalvageNamesTheSession) {
    TempDir dir;
    const fs::path path = dir / "study.db";
    write_study(path, 5, R"({"doc":"what the display showed"})");
    // "doc" loses its closing quote to 0xB0: {"doc\xb0:"what ...
    overwrite_inside(path, "{\"doc\":\"what", 5, '\xb0');
    const std::int64_t row = damaged_row(path, "CHECK constraint failed in sessions",
                                         "SELECT id FROM sessions WHERE NOT json_valid(displayability_json)");
    const std::string msg = expect_refused_alike(path, +study_ro, +study_rw, +study_ex);
    EXPECT_TRUE(contains(msg, "row " + std::to_string(row) +
                                  " of sessions breaks CHECK (displayability_json IS NULL OR "
                                  "json_valid(displayability_json))"))
        << msg;

    StoreOptions salvage;
    salvage.verify = false;
    const Salvage got = Store::open_read_only(path, salvage).salvage();
    EXPECT_TRUE(got.sessions.empty());
    ASSERT_EQ(got.skipped.size(), 1u);
    EXPECT_EQ(got.skipped[0].table, "sessions");
    EXPECT_EQ(got.skipped[0].row_id, row);
}

// What analyze said of such a session before the open refused it: the JSON
// parser's reason quotes the bytes it last read, raw. Now escaped.
TEST(StoreRecordDamage, AJsonErrorQuotingBytesThatAreNotUtf8IsValidUtf8) {
    const std::string damaged = "{\"doc\xb0:\"what the display showed\"}";
    const std::string msg = expect_store_error(StoreErrc::invalid_argument,
                                               [&] { parse_json(damaged, "displayability_json of session 1"); });
    EXPECT_TRUE(valid_utf8(msg)) << msg;
    EXPECT_TRUE(contains(msg, "doc\\xB0")) << msg;
    EXPECT_TRUE(contains(msg, "displayability_json of session 1 is not valid JSON (at byte")) << msg;
}

TEST(StoreRecordDamage, ADisplayProfileFileWithAFitOverwrittenIsRefusedByReadersAndWritersAlike) {
    TempDir dir;
    const fs::path path = dir / "profiles.db";
    {
        Calibration c;
        c.display_name = "lab-lcd";
        c.width_px = 1920;
        c.height_px = 1080;
        c.width_m = 0.598;
        c.height_m = 0.3364;
        c.viewing_distance_m = 0.9;
        c.fit_json = R"({"model":"gog","black_cd_m2":0.2})";
        c.source = "measured";
        c.measured_at = "2024-05-01";
        Profiles::create_or_open(path).displays().put_calibration(c);
    }
    overwrite_inside(path, "{\"model\":\"gog\"", 1, '\xb0');
    const std::int64_t row = damaged_row(path, "CHECK constraint failed in calibrations",
                                         "SELECT id FROM calibrations WHERE NOT json_valid(fit_json)");
    const auto ro = [](const fs::path& p) { Profiles::open_read_only(p); };
    const auto rw = [](const fs::path& p) { Profiles::create_or_open(p); };
    const auto ex = [](const fs::path& p) { Profiles::open_existing(p); };
    const std::string msg = expect_refused_alike(path, +ro, +rw, +ex);
    EXPECT_TRUE(contains(msg, "row " + std::to_string(row) + " of calibrations breaks CHECK (json_valid(fit_json))"))
        << msg;
    EXPECT_TRUE(contains(msg, "new profile file")) << msg;  // the hint for a display-profile file
}

TEST(StoreRecordDamage, AnUndamagedFileOpensEveryWay) {
    TempDir dir;
    const fs::path path = dir / "study.db";
    write_study(path, 20, R"({"doc":"what the display showed"})");
    EXPECT_EQ(Store::open_read_only(path).trials(SessionId{1}).size(), 20u);
    EXPECT_EQ(Store::open_existing(path).trials(SessionId{1}).size(), 20u);
}

}  // namespace
}  // namespace atonlab::store
