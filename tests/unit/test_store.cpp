// The study store's API: schema and pragmas, round trips of every record,
// the rules record_trial enforces, sessions' life cycle, a reader beside a
// writer, calibrations, snapshots, SHA-256 and the migration engine.
// Failure paths (disk full, read-only, ...) are in test_store_failures.cpp, the
// SIGKILL test in test_store_crash.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "atonlab/store/json.h"
#include "atonlab/store/schema.h"
#include "atonlab/store/sha256.h"
#include "atonlab/store/store.h"
#include "atonlab/store/version.h"

namespace atonlab::store {
namespace {

using test_support::expect_same_trial;
using test_support::expect_store_error;
using test_support::make_start;
using test_support::make_trial;
using test_support::RawDb;
using test_support::TempDir;

// --- SHA-256 -----------------------------------------------------------------

TEST(StoreSha256, FipsExamples) {
    // FIPS 180-2 Appendix B examples.
    EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
              "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
    EXPECT_EQ(sha256_hex(std::string(1000000, 'a')),
              "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(StoreSha256, PaddingBoundaries) {
    // Lengths either side of the one- and two-block padding limits (55/56, 63/64,
    // 119/120), bytes (i*7+3) mod 251; digests from Python's hashlib.
    const std::pair<std::size_t, const char*> cases[] = {
        {55, "1deace58c745f3ecadde68a5923f494c3703fa73f0306483ccb898a5826e8d70"},
        {56, "06dbe23685750e4d3881ded95047abaf93fa8f9c5d3501dc57c717a72ff1398e"},
        {63, "47fb38b12335c9298d09280515c0666489a189d1554bb0ac1a0740806ce9d8b6"},
        {64, "dfa798724b1a8014994f363e5da7474ed26ce3757fb29e07aa47ad5a9352d37b"},
        {65, "dd2eab5a5507d7717c63ce953d9ac61752c21e664425ad1227054722a0d97f69"},
        {119, "c6e0f435df5d7d265baacca31e0602c00aa22fa6d3819aed664649294c743756"},
        {120, "17eb8960823a644bde3065620bb9d45931fe8993fd8eb692a17aff0fd725db6a"},
        {1000, "a9425c416f534025a4e2422bd14adba4ec3d4a68d10c3329be8df612964d2b6e"},
    };
    for (const auto& [n, hex] : cases) {
        std::vector<std::byte> data(n);
        for (std::size_t i = 0; i < n; ++i) data[i] = static_cast<std::byte>((i * 7 + 3) % 251);
        EXPECT_EQ(sha256_hex(data), hex) << "length " << n;
    }
}

// --- Schema and pragmas ------------------------------------------------------

TEST(Store, NewFileHasSchemaWalAndVersion) {
    TempDir dir;
    const auto path = dir / "study.db";
    {
        Store s = Store::create_or_open(path);
        EXPECT_FALSE(s.read_only());
        EXPECT_EQ(s.integrity_check(), "ok");
    }
    RawDb raw(path);
    EXPECT_EQ(raw.text("PRAGMA journal_mode"), "wal");  // persistent in the file
    EXPECT_EQ(raw.integer("PRAGMA user_version"), schema_version());
    EXPECT_EQ(raw.integer("PRAGMA application_id"), 0x41544F4E);
    EXPECT_EQ(raw.text("SELECT group_concat(name, ',') FROM (SELECT name FROM sqlite_schema WHERE type = 'table' "
                       "ORDER BY name)"),
              "calibration_checks,calibration_readings,calibrations,displays,observers,protocols,scenes,"
              "schema_history,sessions,snapshots,trials");
    EXPECT_EQ(raw.text("SELECT software_version FROM schema_history WHERE version = 1"), software_version());
    EXPECT_EQ(raw.text("PRAGMA integrity_check"), "ok");
    EXPECT_EQ(raw.text("PRAGMA foreign_key_check"), "");
}

TEST(Store, ReopeningAnUpToDateFileChangesNothing) {
    TempDir dir;
    const auto path = dir / "study.db";
    { Store::create_or_open(path); }
    const std::string before = test_support::file_bytes(path);
    {
        Store s = Store::create_or_open(path);
        EXPECT_EQ(s.file_schema_version(), schema_version());
    }
    EXPECT_EQ(test_support::file_bytes(path), before);
}

// --- Round trips -------------------------------------------------------------

TEST(Store, SessionAndTrialsRoundTrip) {
    TempDir dir;
    const auto path = dir / "study.db";
    Store s = Store::create_or_open(path);
    SessionStart start = make_start("P07", 0xF00DF00DF00DF00Dull);  // above 2^63: stored as its bits
    start.protocol_text = "abc";                                    // SHA-256 known from FIPS 180-2
    const SessionId id = s.begin_session(start);

    std::vector<TrialRecord> written;
    for (int i = 0; i < 12; ++i) {
        written.push_back(make_trial(i));
        s.record_trial(id, written.back());
    }
    const auto stored = s.trials(id);
    ASSERT_EQ(stored.size(), written.size());
    for (std::size_t i = 0; i < stored.size(); ++i) expect_same_trial(stored[i], written[i]);
    EXPECT_EQ(s.trial_count(id), 12);

    const SessionRecord r = s.session(id);
    EXPECT_EQ(r.id, id);
    EXPECT_EQ(r.observer_code, "P07");
    EXPECT_EQ(r.protocol_name, "test-protocol.toml");
    EXPECT_EQ(r.protocol_sha256, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    EXPECT_EQ(r.seed, 0xF00DF00DF00DF00Dull);
    EXPECT_EQ(r.software_version, software_version());
    EXPECT_EQ(r.status, SessionStatus::running);
    EXPECT_FALSE(r.ended_at.has_value());
    EXPECT_EQ(r.trial_count, 12);
    EXPECT_EQ(s.protocol_text(id), "abc");

    // The same rows as SQLite itself sees them (not through the store's reader).
    RawDb raw(path, SQLITE_OPEN_READONLY);
    EXPECT_EQ(raw.text("SELECT stimulus_json FROM trials WHERE trial_index = 7"), written[7].stimulus_json);
    EXPECT_EQ(raw.text("SELECT test_on_left FROM trials WHERE trial_index = 2"), "NULL");
    EXPECT_EQ(raw.text("SELECT test_on_left FROM trials WHERE trial_index = 4"), "1");
    EXPECT_EQ(raw.text("SELECT observer_code FROM trial_log WHERE trial_index = 3"), "P07");
    EXPECT_EQ(raw.integer("SELECT seed FROM sessions"), static_cast<long long>(0xF00DF00DF00DF00Dull));
}

TEST(Store, ProtocolTextIsStoredOncePerHash) {
    TempDir dir;
    Store s = Store::create_or_open(dir / "study.db");
    const SessionId a = s.begin_session(make_start("A1"));
    const SessionId b = s.begin_session(make_start("B2"));
    SessionStart other = make_start("A1");
    other.protocol_text += "# edited\n";
    const SessionId c = s.begin_session(other);
    EXPECT_EQ(s.session(a).protocol_id, s.session(b).protocol_id);
    EXPECT_NE(s.session(a).protocol_id, s.session(c).protocol_id);
    RawDb raw(dir / "study.db");
    EXPECT_EQ(raw.integer("SELECT count(*) FROM protocols"), 2);
    EXPECT_EQ(raw.integer("SELECT count(*) FROM observers"), 2);
    EXPECT_EQ(raw.text("SELECT sha256 FROM protocols WHERE id = " + std::to_string(s.session(c).protocol_id)),
              sha256_hex(other.protocol_text));
}

TEST(Store, SceneTextIsStoredOncePerHashBesideTheProtocol) {
    TempDir dir;
    Store s = Store::create_or_open(dir / "study.db");
    SessionStart a = make_start("A1");
    a.scene_text = "abc";  // SHA-256 known from FIPS 180-2
    a.scene_name = "night.scene.toml";
    const SessionId ia = s.begin_session(a);
    SessionStart b = make_start("B2");
    b.scene_text = "abc";
    b.scene_name = "renamed.scene.toml";
    const SessionId ib = s.begin_session(b);
    SessionStart edited = make_start("C3");
    edited.scene_text = "abd";  // one byte changed
    const SessionId ic = s.begin_session(edited);
    const SessionId none = s.begin_session(make_start("D4"));

    EXPECT_EQ(s.session(ia).scene_sha256, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    EXPECT_EQ(s.scene_text(ia), "abc");
    EXPECT_EQ(s.session(ia).scene_name, "night.scene.toml");
    // The same text is one row, under the name it was first stored with.
    EXPECT_EQ(s.session(ib).scene_sha256, s.session(ia).scene_sha256);
    EXPECT_EQ(s.session(ib).scene_name, "night.scene.toml");
    // A changed text has a changed hash: what a resumed session is checked against.
    ASSERT_TRUE(s.session(ic).scene_sha256);
    EXPECT_NE(s.session(ic).scene_sha256, s.session(ia).scene_sha256);
    EXPECT_EQ(*s.session(ic).scene_sha256, sha256_hex(edited.scene_text));
    EXPECT_EQ(s.scene_text(ic), "abd");
    // Begun without one: none stored, and the list of sessions agrees.
    EXPECT_FALSE(s.session(none).scene_sha256);
    EXPECT_FALSE(s.scene_text(none));
    EXPECT_EQ(s.sessions().at(2).scene_sha256, s.session(ic).scene_sha256);
    RawDb raw(dir / "study.db");
    EXPECT_EQ(raw.integer("SELECT count(*) FROM scenes"), 2);
    EXPECT_EQ(raw.text("SELECT sha256 FROM scenes WHERE text = 'abd'"), sha256_hex("abd"));
    EXPECT_EQ(raw.text("SELECT scene_id FROM sessions WHERE id = " + std::to_string(none.value)), "NULL");
}

TEST(StoreMigrations, AVersionFiveFileKeepsItsSessionsWhichHoldNoScene) {
    TempDir dir;
    const auto path = dir / "study.db";
    // A file as version 5 made it, filled through SQLite itself.
    detail::migrate_file(path, schema_migrations().first(5));
    {
        RawDb raw(path);
        ASSERT_EQ(raw.exec("INSERT INTO observers (code, added_at) VALUES ('P1', '2024-01-01T00:00:00.000Z');"
                           "INSERT INTO protocols (sha256, name, text, added_at) VALUES ('" +
                           sha256_hex("proto") +
                           "', 'p.toml', 'proto', '2024-01-01T00:00:00.000Z');"
                           "INSERT INTO sessions (observer_id, protocol_id, software_version, seed, started_at) "
                           "VALUES (1, 1, '0.1.0', 9, '2024-01-01T00:00:00.000Z');"),
                  "");
        ASSERT_EQ(raw.integer("PRAGMA user_version"), 5);
    }
    expect_store_error(StoreErrc::older_schema, [&] { Store::open_read_only(path); });
    Store s = Store::create_or_open(path);  // a writer migrates it
    EXPECT_EQ(s.file_schema_version(), schema_version());
    const SessionRecord r = s.session(SessionId{1});
    EXPECT_EQ(r.observer_code, "P1");
    EXPECT_EQ(s.protocol_text(r.id), "proto");
    EXPECT_FALSE(r.scene_sha256);
    EXPECT_EQ(r.scene_name, "");
    EXPECT_FALSE(s.scene_text(r.id));
}

// --- What record_trial refuses ------------------------------------------------

TEST(Store, RecordTrialRefusesBadTrialsAndWritesNothing) {
    TempDir dir;
    Store s = Store::create_or_open(dir / "study.db");
    const SessionId id = s.begin_session(make_start());
    s.record_trial(id, make_trial(0));
    s.record_trial(id, make_trial(1));

    expect_store_error(StoreErrc::invalid_argument, [&] { s.record_trial(id, make_trial(1)); });  // duplicate
    expect_store_error(StoreErrc::invalid_argument, [&] { s.record_trial(id, make_trial(3)); });  // gap
    const std::string msg = expect_store_error(StoreErrc::invalid_argument, [&] { s.record_trial(id, make_trial(5)); });
    EXPECT_NE(msg.find("next trial index is 2"), std::string::npos) << msg;
    EXPECT_NE(msg.find("study.db"), std::string::npos) << msg;

    TrialRecord t = make_trial(2);
    t.stimulus_json = "{not json";
    expect_store_error(StoreErrc::invalid_argument, [&] { s.record_trial(id, t); });
    t = make_trial(2);
    t.procedure_state_json = "";
    expect_store_error(StoreErrc::invalid_argument, [&] { s.record_trial(id, t); });
    t = make_trial(2);
    t.level = std::numeric_limits<double>::quiet_NaN();  // SQLite would store NULL
    expect_store_error(StoreErrc::invalid_argument, [&] { s.record_trial(id, t); });
    t = make_trial(2);
    t.response_time_s = -0.1;
    expect_store_error(StoreErrc::invalid_argument, [&] { s.record_trial(id, t); });
    t = make_trial(2);
    t.response.clear();
    expect_store_error(StoreErrc::invalid_argument, [&] { s.record_trial(id, t); });
    expect_store_error(StoreErrc::not_found, [&] { s.record_trial(SessionId{99}, make_trial(0)); });

    EXPECT_EQ(s.trial_count(id), 2);
    s.record_trial(id, make_trial(2));  // still accepts the right next trial
    EXPECT_EQ(s.trial_count(id), 3);
}

TEST(Store, ObserverIsACodeNotAName) {
    TempDir dir;
    Store s = Store::create_or_open(dir / "study.db");
    expect_store_error(StoreErrc::invalid_argument, [&] { s.begin_session(make_start("Jane Doe")); });
    expect_store_error(StoreErrc::invalid_argument, [&] { s.begin_session(make_start("")); });
    expect_store_error(StoreErrc::invalid_argument, [&] { s.begin_session(make_start(std::string(33, 'x'))); });
    EXPECT_NO_THROW(s.begin_session(make_start("S-001_b")));
    // The schema holds the same rule for anyone writing the file by other means.
    RawDb raw(dir / "study.db");
    EXPECT_NE(raw.exec("INSERT INTO observers (code, added_at) VALUES ('Jane Doe', 'x')"), "");
}

TEST(Store, RecordedTrialsAreAppendOnlyInTheSchema) {
    TempDir dir;
    {
        Store s = Store::create_or_open(dir / "study.db");
        s.record_trial(s.begin_session(make_start()), make_trial(0));
    }
    RawDb raw(dir / "study.db");
    EXPECT_NE(raw.exec("DELETE FROM trials").find("append-only"), std::string::npos);
    EXPECT_NE(raw.exec("UPDATE trials SET response = 'right'").find("append-only"), std::string::npos);
    EXPECT_EQ(raw.text("SELECT response FROM trials"), "left");
}

// --- Session life cycle -------------------------------------------------------

TEST(Store, FinishResumeAndResumePoint) {
    TempDir dir;
    Store s = Store::create_or_open(dir / "study.db");
    const SessionId id = s.begin_session(make_start());
    for (int i = 0; i < 4; ++i) s.record_trial(id, make_trial(i));

    s.finish_session(id, SessionStatus::quit);
    EXPECT_EQ(s.session(id).status, SessionStatus::quit);
    EXPECT_TRUE(s.session(id).ended_at.has_value());
    expect_store_error(StoreErrc::invalid_argument, [&] { s.record_trial(id, make_trial(4)); });
    expect_store_error(StoreErrc::invalid_argument, [&] { s.finish_session(id, SessionStatus::completed); });
    expect_store_error(StoreErrc::invalid_argument, [&] { s.finish_session(id, SessionStatus::running); });

    const ResumePoint rp = s.resume_session(id);
    EXPECT_EQ(rp.session.status, SessionStatus::running);
    EXPECT_EQ(rp.session.resume_count, 1);
    EXPECT_FALSE(rp.session.ended_at.has_value());
    EXPECT_EQ(rp.protocol_text, make_start().protocol_text);
    ASSERT_EQ(rp.next_trial_index, 4);
    ASSERT_EQ(rp.trials.size(), 4u);
    for (int i = 0; i < 4; ++i) expect_same_trial(rp.trials[static_cast<std::size_t>(i)], make_trial(i));

    s.record_trial(id, make_trial(4));
    s.finish_session(id, SessionStatus::completed);
    expect_store_error(StoreErrc::invalid_argument, [&] { s.resume_session(id); });
    const ResumePoint done = s.resume_point(id);  // reading is always allowed
    EXPECT_EQ(done.next_trial_index, 5);
    EXPECT_EQ(done.session.status, SessionStatus::completed);
    expect_store_error(StoreErrc::not_found, [&] { s.resume_point(SessionId{42}); });
    expect_store_error(StoreErrc::not_found, [&] { s.trials(SessionId{42}); });

    const auto all = s.sessions();
    ASSERT_EQ(all.size(), 1u);
    EXPECT_EQ(all[0].trial_count, 5);
    EXPECT_GE(*all[0].ended_at, all[0].started_at);  // ISO 8601 text orders like time
}

TEST(Store, StopSessionAppendsItsRecordAndAResumeKeepsTheHistory) {
    TempDir dir;
    Store s = Store::create_or_open(dir / "study.db");
    const SessionId id = s.begin_session(make_start());
    s.record_trial(id, make_trial(0));
    EXPECT_FALSE(s.session(id).stop_json.has_value()) << "NULL until the runner stops it";

    // Not a JSON object: refused, nothing written (the session still runs).
    expect_store_error(StoreErrc::invalid_argument, [&] { s.stop_session(id, "[1, 2]"); });
    expect_store_error(StoreErrc::invalid_argument, [&] { s.stop_session(id, "{\"reason\": "); });
    EXPECT_EQ(s.session(id).status, SessionStatus::running);
    EXPECT_FALSE(s.session(id).stop_json.has_value());

    s.stop_session(id, R"({"reason":"missed_in_a_row","trials_stored":1})");
    SessionRecord r = s.session(id);
    EXPECT_EQ(r.status, SessionStatus::quit);
    EXPECT_TRUE(r.ended_at.has_value());
    ASSERT_TRUE(r.stop_json.has_value());
    nlohmann::json stops = parse_json(*r.stop_json);
    ASSERT_TRUE(stops.is_array());
    ASSERT_EQ(stops.size(), 1u);
    EXPECT_EQ(stops[0].at("reason"), "missed_in_a_row");
    EXPECT_EQ(stops[0].at("trials_stored"), 1);
    EXPECT_GE(stops[0].at("stopped_at").get<std::string>(), r.started_at);
    // Only a running session can be stopped.
    expect_store_error(StoreErrc::invalid_argument, [&] { s.stop_session(id, R"({"reason":"x"})"); });

    // Resumed: the record stays; a second stop is appended after the first.
    s.resume_session(id);
    EXPECT_EQ(parse_json(*s.session(id).stop_json).size(), 1u);
    s.record_trial(id, make_trial(1));
    s.stop_session(id, R"({"reason":"missed_per_session","trials_stored":2})");
    stops = parse_json(*s.session(id).stop_json);
    ASSERT_EQ(stops.size(), 2u);
    EXPECT_EQ(stops[0].at("reason"), "missed_in_a_row");
    EXPECT_EQ(stops[1].at("reason"), "missed_per_session");
    // ... and it is still there once the session completes.
    s.resume_session(id);
    s.finish_session(id, SessionStatus::completed);
    EXPECT_EQ(parse_json(*s.session(id).stop_json).size(), 2u);
    EXPECT_EQ(s.integrity_check(), "ok");
}

// --- A reader beside a writer ------------------------------------------------

TEST(Store, ReaderSeesCommittedTrialsWhileWriterRuns) {
    TempDir dir;
    const auto path = dir / "study.db";
    Store writer = Store::create_or_open(path);
    const SessionId id = writer.begin_session(make_start());
    writer.record_trial(id, make_trial(0));

    Store reader = Store::open_read_only(path);
    EXPECT_TRUE(reader.read_only());
    EXPECT_EQ(reader.trial_count(id), 1);
    for (int i = 1; i <= 5; ++i) {
        writer.record_trial(id, make_trial(i));
        EXPECT_EQ(reader.trial_count(id), i + 1);  // committed means visible to another connection
    }
    expect_same_trial(reader.trials(id).back(), make_trial(5));
    expect_store_error(StoreErrc::read_only, [&] { reader.record_trial(id, make_trial(6)); });
    expect_store_error(StoreErrc::read_only, [&] { reader.begin_session(make_start()); });
    expect_store_error(StoreErrc::read_only, [&] { reader.finish_session(id, SessionStatus::quit); });

    // WAL: a reader holding a read transaction open does not block the writer,
    // and keeps its own snapshot until it ends.
    RawDb raw(path, SQLITE_OPEN_READONLY);
    ASSERT_EQ(raw.exec("BEGIN"), "");
    EXPECT_EQ(raw.integer("SELECT count(*) FROM trials"), 6);
    writer.record_trial(id, make_trial(6));
    EXPECT_EQ(raw.integer("SELECT count(*) FROM trials"), 6);
    ASSERT_EQ(raw.exec("COMMIT"), "");
    EXPECT_EQ(raw.integer("SELECT count(*) FROM trials"), 7);
    EXPECT_EQ(reader.trial_count(id), 7);
}

// --- Calibrations -------------------------------------------------------------

Calibration make_calibration(const std::string& display, const std::string& date, double gamma) {
    Calibration c;
    c.display_name = display;
    c.width_px = 1920;
    c.height_px = 1080;
    c.width_m = 0.598;
    c.height_m = 0.336;
    c.viewing_distance_m = 0.9;
    c.fit_json = "{\"model\":\"gog\",\"gamma\":" + std::to_string(gamma) + "}";
    c.source = "measured";
    c.measured_at = date;
    return c;
}

TEST(Store, LatestCalibrationIsByMeasurementDate) {
    TempDir dir;
    Store s = Store::create_or_open(dir / "study.db");
    EXPECT_FALSE(s.latest_calibration("lab-1").has_value());
    const CalibrationId newest = s.put_calibration(make_calibration("lab-1", "2024-06-01", 2.2));
    s.put_calibration(make_calibration("lab-1", "2024-01-15", 2.4));  // stored later, measured earlier
    s.put_calibration(make_calibration("lab-2", "2025-01-01", 1.8));
    const auto latest = s.latest_calibration("lab-1");
    ASSERT_TRUE(latest.has_value());
    EXPECT_EQ(latest->id, newest);
    EXPECT_EQ(latest->measured_at, "2024-06-01");
    EXPECT_EQ(latest->fit_json, make_calibration("", "", 2.2).fit_json);
    EXPECT_EQ(latest->width_px, 1920);
    EXPECT_EQ(latest->viewing_distance_m, 0.9);
    EXPECT_EQ(s.calibration(newest).display_name, "lab-1");

    SessionStart start = make_start();
    start.calibration = newest;
    EXPECT_EQ(s.session(s.begin_session(start)).calibration, newest);
    start.calibration = CalibrationId{999};
    expect_store_error(StoreErrc::not_found, [&] { s.begin_session(start); });

    expect_store_error(StoreErrc::invalid_argument,
                       [&] { s.put_calibration(make_calibration("lab-1", "June 2024", 2.2)); });
    Calibration bad = make_calibration("lab-1", "2024-06-02", 2.2);
    bad.fit_json = "gamma=2.2";
    expect_store_error(StoreErrc::invalid_argument, [&] { s.put_calibration(bad); });
    bad = make_calibration("lab-1", "2024-06-02", 2.2);
    bad.viewing_distance_m = 0.0;
    expect_store_error(StoreErrc::invalid_argument, [&] { s.put_calibration(bad); });
}

// --- Snapshots ----------------------------------------------------------------

TEST(Store, SnapshotsRoundTripAndAreChecked) {
    TempDir dir;
    const auto path = dir / "study.db";
    Store s = Store::create_or_open(path);
    const SessionId id = s.begin_session(make_start());
    std::vector<std::byte> exr(300000);  // bigger than a page, so it spans overflow pages
    for (std::size_t i = 0; i < exr.size(); ++i) exr[i] = static_cast<std::byte>((i * 2654435761u) >> 24);

    EXPECT_FALSE(s.get_snapshot(id, "glare").has_value());
    s.put_snapshot(id, "glare", exr);
    auto got = s.get_snapshot(id, "glare");
    ASSERT_TRUE(got.has_value());
    EXPECT_EQ(got->data, exr);
    EXPECT_EQ(got->format, "exr");
    EXPECT_EQ(got->sha256, sha256_hex(exr));

    exr[12345] ^= std::byte{0xff};
    s.put_snapshot(id, "glare", exr);  // replaces
    EXPECT_EQ(s.get_snapshot(id, "glare")->data, exr);
    expect_store_error(StoreErrc::not_found, [&] { s.put_snapshot(SessionId{77}, "glare", exr); });

    // Damage the stored bytes behind the store's back: the checksum catches it.
    RawDb raw(path);
    ASSERT_EQ(raw.exec("UPDATE snapshots SET data = zeroblob(10)"), "");
    expect_store_error(StoreErrc::corrupt, [&] { s.get_snapshot(id, "glare"); });
}

// --- The migration engine ----------------------------------------------------

// A second schema step, as a later atonlab would add one.
constexpr std::string_view add_notes_sql = "ALTER TABLE sessions ADD COLUMN notes TEXT NOT NULL DEFAULT '';";

TEST(StoreMigrations, OlderFileIsMigratedKeepingItsData) {
    TempDir dir;
    const auto path = dir / "study.db";
    {
        Store s = Store::create_or_open(path);
        const SessionId id = s.begin_session(make_start());
        for (int i = 0; i < 3; ++i) s.record_trial(id, make_trial(i));
    }
    // This build's steps, then one more (the file is at this build's version).
    const int n = schema_version();
    std::vector<Migration> steps(schema_migrations().begin(), schema_migrations().end());
    steps.push_back(Migration{n + 1, "session notes", add_notes_sql});
    detail::migrate_file(path, steps);

    RawDb raw(path);
    EXPECT_EQ(raw.integer("PRAGMA user_version"), n + 1);
    EXPECT_EQ(raw.integer("SELECT count(*) FROM sessions WHERE notes = ''"), 1);
    EXPECT_EQ(raw.integer("SELECT count(*) FROM schema_history"), n + 1);
    EXPECT_EQ(raw.text("SELECT stimulus_json FROM trials WHERE trial_index = 2"), make_trial(2).stimulus_json);
    EXPECT_EQ(raw.text("PRAGMA integrity_check"), "ok");
}

TEST(StoreMigrations, FailingStepLeavesTheFileAsItWas) {
    TempDir dir;
    const auto path = dir / "study.db";
    {
        Store s = Store::create_or_open(path);
        s.record_trial(s.begin_session(make_start()), make_trial(0));
    }
    const std::string before = test_support::file_bytes(path);
    // Step N+1 succeeds, step N+2 fails: neither may remain.
    const int n = schema_version();
    std::vector<Migration> steps(schema_migrations().begin(), schema_migrations().end());
    steps.push_back(Migration{n + 1, "session notes", add_notes_sql});
    steps.push_back(Migration{n + 2, "broken", "ALTER TABLE no_such_table ADD COLUMN x;"});
    const std::string msg = expect_store_error(StoreErrc::other, [&] { detail::migrate_file(path, steps); });
    EXPECT_NE(msg.find("migrate the schema to version " + std::to_string(n + 2)), std::string::npos) << msg;
    EXPECT_NE(msg.find("no_such_table"), std::string::npos) << msg;
    EXPECT_EQ(test_support::file_bytes(path), before);
    RawDb raw(path);
    EXPECT_EQ(raw.integer("PRAGMA user_version"), n);
    EXPECT_EQ(raw.integer("SELECT count(*) FROM pragma_table_info('sessions') WHERE name = 'notes'"), 0);
}

TEST(StoreMigrations, ReadOnlyOpenOfAnOlderFileAsksForAWriter) {
    TempDir dir;
    const auto path = dir / "study.db";
    // A file of the version before this build's, as that version made it (a
    // file whose user_version was lowered by hand no longer holds the schema
    // of its version, and is refused as schema_altered: test_store_schema_check.cpp).
    detail::migrate_file(path, schema_migrations().first(schema_migrations().size() - 1));
    expect_store_error(StoreErrc::older_schema, [&] { Store::open_read_only(path); });
}

}  // namespace
// --- The tidy view of the overrides ----------------------------------------------------

TEST(Store, TrialSettingsGivesEachOverrideTypedAndUnquoted) {
    TempDir dir;
    const auto path = dir / "study.db";
    {
        Store s = Store::create_or_open(path);
        const SessionId id = s.begin_session(make_start("P01", 1));
        TrialRecord t = make_trial(0);
        t.stimulus_json =
            R"({"frames":[{"role":"test","overrides":["tonemap.operator=\"perceptual\"","eye.adaptation_cd_m2=0.03",)"
            R"("output.dither=true","eye.glare='none'"]},{"role":"reference","overrides":["light.a.intensity_cd=2"]}]})";
        s.record_trial(id, t);
    }
    RawDb raw(path);
    EXPECT_EQ(raw.text("SELECT group_concat(frame_role || ' ' || key || ' ' || value || ' ' || typeof(value), '; ') "
                       "FROM trial_settings"),
              "test tonemap.operator perceptual text; test eye.adaptation_cd_m2 0.03 real; "
              "test output.dither 1 integer; test eye.glare none text; reference light.a.intensity_cd 2 integer");
    EXPECT_EQ(raw.text("SELECT toml_value FROM trial_settings WHERE key = 'tonemap.operator'"), "\"perceptual\"");
}

}  // namespace atonlab::store
