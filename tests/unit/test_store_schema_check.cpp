// The schema a study file holds, checked at every open (docs/store.md,
// "Opening"): a table, column, constraint, index, trigger or view changed by
// hand is refused by every open function with one sentence naming the first
// difference, and the file is left byte for byte as it was; salvage still
// reads it. A file written by each released schema version (the fixtures in
// tests/data/store_schema/, one per version: the schema as it shipped) opens
// and, migrated, holds exactly the schema of a new file. And SQLite's limits:
// a value longer than the limit on one text or blob is refused at the open.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "atonlab/store/profiles.h"
#include "atonlab/store/schema.h"
#include "atonlab/store/store.h"
#include "text_contains.h"

namespace atonlab::store {
namespace {

namespace fs = std::filesystem;
using ::atonlab::test::contains;
using test_support::expect_store_error;
using test_support::file_bytes;
using test_support::make_start;
using test_support::make_trial;
using test_support::RawDb;
using test_support::TempDir;

const fs::path kFixtures = fs::path(ATONLAB_SOURCE_DIR) / "tests/data/store_schema";

std::string read_text(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

fs::path study_fixture(int version) {
    return kFixtures / ("study_v" + std::to_string(version) + ".sql");
}

/// A file holding exactly the fixture's schema, marked as `version` of `app_id`.
void make_from_fixture(const fs::path& path, const fs::path& fixture, int version, int app_id) {
    const std::string text = read_text(fixture);
    ASSERT_FALSE(text.empty()) << fixture;
    RawDb raw(path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
    ASSERT_EQ(raw.exec(text), "") << fixture;
    ASSERT_EQ(raw.exec("PRAGMA user_version = " + std::to_string(version) +
                       "; PRAGMA application_id = " + std::to_string(app_id)),
              "");
}

/// sqlite_schema as SQLite itself holds it, every object by type and name.
std::string schema_of(const fs::path& path) {
    RawDb raw(path, SQLITE_OPEN_READONLY);
    return raw.text(
        "SELECT type || ' ' || name || ' ON ' || tbl_name || ': ' || coalesce(sql, '') FROM sqlite_schema "
        "ORDER BY type, name");
}

struct Alteration {
    std::string name;
    std::string says;  ///< a substring of the refusal
    std::string sql;
};

/// tests/data/store_schema/alterations.txt: the alterations the issue lists,
/// shared with the GL and Python tests.
std::vector<Alteration> alterations() {
    std::vector<Alteration> out;
    std::istringstream in(read_text(kFixtures / "alterations.txt"));
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line[0] == '#') continue;
        const auto a = line.find('|');
        const auto b = line.find('|', a + 1);
        out.push_back({line.substr(0, a), line.substr(a + 1, b - a - 1), line.substr(b + 1)});
    }
    return out;
}

/// A closed current study: one session of 5 trials.
void write_study(const fs::path& path) {
    Store s = Store::create_or_open(path);
    const SessionId id = s.begin_session(make_start());
    for (int i = 0; i < 5; ++i) s.record_trial(id, make_trial(i));
    s.finish_session(id, SessionStatus::completed);
}

/// Every open function refuses the file as schema_altered with one sentence
/// naming it and `says`, and its bytes are as before. Returns the sentence.
std::string expect_altered(const fs::path& path, const std::string& says) {
    const std::string before = file_bytes(path);
    const std::string msg = expect_store_error(StoreErrc::schema_altered, [&] { Store::create_or_open(path); });
    EXPECT_EQ(expect_store_error(StoreErrc::schema_altered, [&] { Store::open_existing(path); }), msg);
    EXPECT_EQ(expect_store_error(StoreErrc::schema_altered, [&] { Store::open_read_only(path); }), msg);
    EXPECT_TRUE(contains(msg, path.string() + "'s schema was altered (" + says)) << msg;
    EXPECT_TRUE(contains(msg, "it was not changed")) << msg;
    EXPECT_TRUE(contains(msg, "atonlab analyze --salvage")) << msg;
    EXPECT_FALSE(contains(msg, "\n")) << msg;
    EXPECT_EQ(file_bytes(path), before) << "the refused file was changed";
    EXPECT_FALSE(fs::exists(path.string() + "-wal") && fs::file_size(path.string() + "-wal") > 0);
    return msg;
}

// --- The released versions ----------------------------------------------------

TEST(StoreSchemaFixtures, EveryReleasedVersionHasItsFixture) {
    // A new migration ships with its fixture: scripts/schema_fixture.sh NEW.db
    // > tests/data/store_schema/study_vN.sql (tests/data/store_schema/README.md).
    for (int v = 1; v <= schema_version(); ++v) EXPECT_TRUE(fs::exists(study_fixture(v))) << study_fixture(v);
    for (int v = 1; v <= profile_schema_version(); ++v)
        EXPECT_TRUE(fs::exists(kFixtures / ("profiles_v" + std::to_string(v) + ".sql"))) << v;
}

TEST(StoreSchemaFixtures, TheMigrationsStillMakeEachReleasedSchema) {
    // A shipped step edited would make files that no longer match the ones in the field.
    TempDir dir;
    const auto steps = schema_migrations();
    for (int v = 1; v <= schema_version(); ++v) {
        SCOPED_TRACE("version " + std::to_string(v));
        const fs::path migrated = dir.path() / ("migrated-" + std::to_string(v) + ".db");
        const fs::path fixture = dir.path() / ("fixture-" + std::to_string(v) + ".db");
        detail::migrate_file(migrated, steps.first(static_cast<std::size_t>(v)));
        make_from_fixture(fixture, study_fixture(v), v, application_id);
        EXPECT_EQ(schema_of(migrated), schema_of(fixture));
    }
    const fs::path profiles = dir.path() / "profiles.db";
    const fs::path fixture = dir.path() / "profiles-fixture.db";
    { Profiles::create_or_open(profiles); }
    make_from_fixture(fixture, kFixtures / "profiles_v1.sql", 1, profile_application_id);
    EXPECT_EQ(schema_of(profiles), schema_of(fixture));
}

TEST(StoreSchemaFixtures, AFileOfEachVersionPassesAndMigratedHoldsTheSchemaOfANewFile) {
    TempDir dir;
    const fs::path fresh = dir.path() / "fresh.db";
    write_study(fresh);
    for (int v = 1; v <= schema_version(); ++v) {
        SCOPED_TRACE("version " + std::to_string(v));
        const fs::path p = dir.path() / ("v" + std::to_string(v) + ".db");
        make_from_fixture(p, study_fixture(v), v, application_id);
        if (v < schema_version()) {
            expect_store_error(StoreErrc::older_schema, [&] { Store::open_read_only(p); });
        } else {
            EXPECT_NO_THROW(Store::open_read_only(p));
        }
        {
            Store s = Store::create_or_open(p);  // checked at version v, then migrated
            EXPECT_EQ(s.file_schema_version(), schema_version());
            const SessionId id = s.begin_session(make_start());
            s.record_trial(id, make_trial(0));
        }
        EXPECT_EQ(schema_of(p), schema_of(fresh));
        EXPECT_NO_THROW(Store::open_read_only(p));
    }
    // A study from before the application_id stamp (version 1, id 0) too.
    const fs::path unstamped = dir.path() / "unstamped.db";
    make_from_fixture(unstamped, study_fixture(1), 1, 0);
    { Store::create_or_open(unstamped); }
    EXPECT_EQ(schema_of(unstamped), schema_of(fresh));
}

// --- Alterations ---------------------------------------------------------------

TEST(StoreSchemaCheck, EachAlterationIsRefusedByEveryOpenAndSalvageStillReadsTheFile) {
    TempDir dir;
    const fs::path good = dir.path() / "good.db";
    write_study(good);
    const std::vector<Alteration> all = alterations();
    ASSERT_EQ(all.size(), 6u);
    for (const Alteration& a : all) {
        SCOPED_TRACE(a.name);
        const fs::path p = dir.path() / (a.name + ".db");
        fs::copy_file(good, p);
        {
            RawDb raw(p);
            ASSERT_EQ(raw.exec(a.sql), "");
        }
        expect_altered(p, a.says);
        StoreOptions salvage;
        salvage.verify = false;
        const Salvage got = Store::open_read_only(p, salvage).salvage();
        EXPECT_EQ(got.trials.size(), 5u);
        EXPECT_EQ(got.sessions.size(), 1u);
    }
}

TEST(StoreSchemaCheck, EveryKindOfDifferenceIsNamed) {
    const std::vector<Alteration> more = {
        {"not null removed", "column condition_id of table trials differs (its NOT NULL)",
         "PRAGMA writable_schema = ON; UPDATE sqlite_schema SET sql = replace(sql, 'condition_id         TEXT NOT "
         "NULL,', 'condition_id         TEXT,') WHERE name = 'trials';"},
        {"type changed", "column response_time_s of table trials differs (its type)",
         "PRAGMA writable_schema = ON; UPDATE sqlite_schema SET sql = replace(sql, 'response_time_s      REAL', "
         "'response_time_s      TEXT') WHERE name = 'trials';"},
        {"default changed", "column status of table sessions differs (its default)",
         "PRAGMA writable_schema = ON; UPDATE sqlite_schema SET sql = replace(sql, 'DEFAULT ''running''', "
         "'DEFAULT ''quit''') WHERE name = 'sessions';"},
        {"check added", "a CHECK (added_at <> '') was added to table observers",
         "PRAGMA writable_schema = ON; UPDATE sqlite_schema SET sql = replace(sql, 'added_at TEXT NOT NULL', "
         "'added_at TEXT NOT NULL CHECK (added_at <> '''')') WHERE name = 'observers';"},
        {"foreign key changed", "the foreign keys (REFERENCES) of table sessions differ",
         "PRAGMA writable_schema = ON; UPDATE sqlite_schema SET sql = replace(sql, 'REFERENCES observers(id)', "
         "'REFERENCES protocols(id)') WHERE name = 'sessions';"},
        {"space inside a string",
         "the CHECK (length(code) BETWEEN 1 AND 32 AND code NOT GLOB '*[^A-Za-z0-9_-]*') of table observers differs: "
         "the file has CHECK (length(code) BETWEEN 1 AND 32 AND code NOT GLOB '* [^",
         "PRAGMA writable_schema = ON; UPDATE sqlite_schema SET sql = replace(sql, '''*[^A-Za-z0-9_-]*''', "
         "'''* [^A-Za-z0-9_-]*''') WHERE name = 'observers';"},
        {"unique removed", "the definition of table observers differs (the file has",
         "PRAGMA writable_schema = ON; UPDATE sqlite_schema SET sql = replace(sql, 'NOT NULL UNIQUE', 'NOT NULL') "
         "WHERE name = 'observers'; DELETE FROM sqlite_schema WHERE name = 'sqlite_autoindex_observers_1';"},
        {"table added", "a table notes was added", "CREATE TABLE notes (text TEXT);"},
        {"index added", "an index trials_by_level was added", "CREATE INDEX trials_by_level ON trials (level);"},
        {"trigger dropped", "a trigger trials_append_only_delete is missing",
         "DROP TRIGGER trials_append_only_delete;"},
        {"index changed", "index trials_by_condition differs",
         "DROP INDEX trials_by_condition; CREATE INDEX trials_by_condition ON trials (condition_id, level);"},
        {"view became a table", "trial_settings is a table in the file, a view in atonlab's schema",
         "DROP VIEW trial_settings; CREATE TABLE trial_settings (x);"},
    };
    TempDir dir;
    const fs::path good = dir.path() / "good.db";
    write_study(good);
    for (const Alteration& a : more) {
        SCOPED_TRACE(a.name);
        const fs::path p = dir.path() / "altered.db";
        fs::remove(p);
        fs::copy_file(good, p);
        {
            RawDb raw(p);
            ASSERT_EQ(raw.exec(a.sql), "");
            ASSERT_NE(schema_of(p), schema_of(good));  // SQLite holds the change
        }
        expect_altered(p, a.says);
    }
}

TEST(StoreSchemaCheck, SalvageJudgesTheRowsOfAnAlteredFileByAtonlabsConstraints) {
    // A weakened CHECK let in a trial atonlab never writes (response_time_s < 0).
    TempDir dir;
    const fs::path p = dir.path() / "weakened.db";
    write_study(p);
    {
        RawDb raw(p);
        ASSERT_EQ(raw.exec("PRAGMA writable_schema = ON; UPDATE sqlite_schema SET sql = replace(sql, "
                           "'CHECK (response_time_s >= 0)', 'CHECK (response_time_s >= -100)') WHERE name = 'trials';"),
                  "");
    }
    {
        RawDb raw(p);  // a fresh connection holds the weakened CHECK
        ASSERT_EQ(raw.exec("INSERT INTO trials (session_id, trial_index, block, condition_id, procedure_id, level, "
                           "stimulus_json, response, response_time_s, onset_time_s, dropped_frames, missed_deadline, "
                           "procedure_state_json, recorded_at) SELECT session_id, 5, block, condition_id, procedure_id, "
                           "level, stimulus_json, response, -1, onset_time_s, dropped_frames, missed_deadline, "
                           "procedure_state_json, recorded_at FROM trials WHERE trial_index = 0"),
                  "");
        ASSERT_EQ(raw.integer("SELECT count(*) FROM trials"), 6);
    }
    expect_altered(p, "the CHECK (response_time_s >= 0) of table trials differs");
    StoreOptions salvage;
    salvage.verify = false;
    const Salvage got = Store::open_read_only(p, salvage).salvage();
    EXPECT_EQ(got.trials.size(), 5u);
    ASSERT_EQ(got.skipped.size(), 1u);
    EXPECT_EQ(got.skipped[0].table, "trials");
    EXPECT_EQ(got.skipped[0].row_id, 6);
    EXPECT_EQ(got.skipped[0].why, "breaks CHECK (response_time_s >= 0)");
}

TEST(StoreSchemaCheck, ALayoutOnlyChangeIsNotAnAlteration) {
    // White space and comments: the same statement, as SQLite reads it.
    TempDir dir;
    const fs::path p = dir.path() / "relaid.db";
    write_study(p);
    {
        RawDb raw(p);
        ASSERT_EQ(raw.exec("PRAGMA writable_schema = ON; UPDATE sqlite_schema SET sql = replace(replace(sql, '    ', "
                           "char(9)), 'CREATE TABLE trials (', 'CREATE TABLE trials ( /* laid out again */') WHERE "
                           "name = 'trials';"),
                  "");
    }
    EXPECT_NE(schema_of(p).find("laid out again"), std::string::npos);
    EXPECT_NO_THROW(Store::open_read_only(p));
    Store s = Store::create_or_open(p);
    EXPECT_EQ(s.trials(SessionId{1}).size(), 5u);
}

TEST(StoreSchemaCheck, AnAlteredFileOfAnOlderVersionIsRefusedNotMigrated) {
    TempDir dir;
    const fs::path p = dir.path() / "v5.db";
    make_from_fixture(p, study_fixture(5), 5, application_id);
    {
        RawDb raw(p);
        ASSERT_EQ(raw.exec("DROP INDEX trials_by_condition;"), "");
    }
    const std::string msg = expect_altered(p, "an index trials_by_condition is missing");
    EXPECT_TRUE(contains(msg, "for version 5")) << msg;
    RawDb raw(p, SQLITE_OPEN_READONLY);
    EXPECT_EQ(raw.integer("PRAGMA user_version"), 5);
}

TEST(StoreSchemaCheck, AnAlteredDisplayProfileFileIsRefusedAndAnUnalteredOneOpens) {
    TempDir dir;
    const fs::path p = dir.path() / "profiles.db";
    { Profiles::create_or_open(p); }
    EXPECT_NO_THROW(Profiles::open_existing(p));
    EXPECT_NO_THROW(Profiles::open_read_only(p));
    {
        RawDb raw(p);
        ASSERT_EQ(raw.exec("DROP TRIGGER calibrations_append_only_delete;"), "");
    }
    const std::string before = file_bytes(p);
    for (const auto& open : {+[](const fs::path& f) { Profiles::create_or_open(f); },
                             +[](const fs::path& f) { Profiles::open_existing(f); },
                             +[](const fs::path& f) { Profiles::open_read_only(f); }}) {
        const std::string msg = expect_store_error(StoreErrc::schema_altered, [&] { open(p); });
        EXPECT_TRUE(contains(msg, "a trigger calibrations_append_only_delete is missing")) << msg;
        EXPECT_TRUE(contains(msg, "new profile file")) << msg;
    }
    EXPECT_EQ(file_bytes(p), before);
}

// --- Limits ---------------------------------------------------------------------

TEST(StoreLimits, AValueLongerThanTheLimitIsRefusedAtTheOpenWithASentence) {
    TempDir dir;
    const fs::path good = dir.path() / "good.db";
    write_study(good);
    StoreOptions small;
    small.max_value_bytes = 4096;
    EXPECT_NO_THROW(Store::open_read_only(good, small));  // nothing in it is that long
    struct Case {
        const char* name;
        const char* sql;  // made through a raw connection at SQLite's own limits
        const char* says;
    };
    const Case cases[] = {
        // A text that a NOT NULL reads: SQLite refuses to load it.
        {"text", "UPDATE protocols SET text = printf('%.*c', 5000, 'x')", "(a row of protocols)"},
        // A blob in a column nothing else reads: its length, from the record header.
        {"blob", "UPDATE sessions SET calibration_id = zeroblob(5000)", "(row 1 of sessions)"},
        // A text in a nullable column no CHECK reads (trials are append-only: a
        // new row); SQLite's integrity check, which reads it, stops at it.
        {"nullable text",
         "INSERT INTO trials (session_id, trial_index, block, condition_id, procedure_id, level, stimulus_json, "
         "response, response_value, response_time_s, onset_time_s, dropped_frames, missed_deadline, "
         "procedure_state_json, recorded_at) SELECT session_id, 5, block, condition_id, procedure_id, level, "
         "stimulus_json, response, printf('%.*c', 5000, 'x'), response_time_s, onset_time_s, dropped_frames, "
         "missed_deadline, procedure_state_json, recorded_at FROM trials WHERE trial_index = 0",
         "(found by SQLite's integrity check)"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const fs::path p = dir.path() / (std::string(c.name) + ".db");
        fs::copy_file(good, p);
        {
            RawDb raw(p);
            ASSERT_EQ(raw.exec(c.sql), "");
        }
        const std::string before = file_bytes(p);
        for (bool read_only : {true, false}) {
            const std::string msg = expect_store_error(StoreErrc::corrupt, [&] {
                read_only ? Store::open_read_only(p, small) : Store::open_existing(p, small);
            });
            EXPECT_TRUE(contains(msg, p.string() + " holds a text or blob longer than 4096 bytes, atonlab's limit for "
                                                   "one value"))
                << msg;
            EXPECT_TRUE(contains(msg, c.says)) << msg;
            EXPECT_TRUE(contains(msg, "it was not changed")) << msg;
        }
        EXPECT_EQ(file_bytes(p), before);
        EXPECT_NO_THROW(Store::open_read_only(p));  // under the default limit it is an ordinary study
    }
}

TEST(StoreLimits, AWriterCannotStoreAValueOverTheLimit) {
    TempDir dir;
    const fs::path p = dir.path() / "study.db";
    StoreOptions small;
    small.max_value_bytes = 4096;
    Store s = Store::create_or_open(p, small);
    const SessionId id = s.begin_session(make_start());
    const std::vector<std::byte> big(5000, std::byte{1});
    try {
        s.put_snapshot(id, "c", big);
        ADD_FAILURE() << "a 5000-byte snapshot was stored under a 4096-byte limit";
    } catch (const StoreError& e) {
        EXPECT_TRUE(contains(e.what(), "longer than 4096 bytes, atonlab's limit for one text or blob")) << e.what();
    }
    EXPECT_FALSE(s.get_snapshot(id, "c").has_value());
}

}  // namespace
}  // namespace atonlab::store
