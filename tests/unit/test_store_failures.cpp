// What the store does when the world fails it, and the proof that nothing
// already stored is lost (SQLite's own disk-full and I/O-error tests are the
// model): a full disk (PRAGMA max_page_count), a real write error
// from the OS (RLIMIT_FSIZE), a write-protected file, a file from a newer
// atonlab, a file that is not SQLite, an SQLite file that is not a study, and a
// missing directory.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <fstream>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "atonlab/store/schema.h"
#include "atonlab/store/store.h"
#include "text_contains.h"

namespace atonlab::store {
namespace {

using test_support::expect_same_trial;
using test_support::expect_store_error;
using test_support::file_bytes;
using test_support::make_start;
using test_support::make_trial;
using test_support::RawDb;
using test_support::TempDir;

using ::atonlab::test::contains;

// Every trial 0..n-1 of the file's only session is there, exactly as written,
// and SQLite finds the file sound. Read with a fresh connection after the writer
// is gone, so nothing is served from the writer's cache.
void expect_intact(const std::filesystem::path& path, std::int64_t n, const std::string& tag, std::size_t pad) {
    {
        RawDb raw(path);
        EXPECT_EQ(raw.text("PRAGMA integrity_check"), "ok");
        EXPECT_EQ(raw.text("PRAGMA foreign_key_check"), "");
        EXPECT_EQ(raw.integer("SELECT count(*) FROM trials"), n);
        if (n > 0) {
            EXPECT_EQ(raw.integer("SELECT max(trial_index) FROM trials"), n - 1);
        }
    }
    Store s = Store::open_read_only(path);
    const auto sessions = s.sessions();
    ASSERT_EQ(sessions.size(), 1u);
    const auto trials = s.trials(sessions[0].id);
    ASSERT_EQ(static_cast<std::int64_t>(trials.size()), n);
    for (std::int64_t i = 0; i < n; ++i)
        expect_same_trial(trials[static_cast<std::size_t>(i)], make_trial(i, tag, pad));
}

// --- Disk full ----------------------------------------------------------------

TEST(StoreFailures, DiskFullLosesNothingAlreadyStored) {
    TempDir dir;
    const auto path = dir / "study.db";
    constexpr std::size_t pad = 1500;  // ~2 KB rows: the limit is reached after a few dozen trials
    std::int64_t stored = 0;
    std::string message;
    {
        StoreOptions limited;
        limited.max_size_bytes = 160 * 1024;  // PRAGMA max_page_count: SQLITE_FULL as on a full disk
        Store s = Store::create_or_open(path, limited);
        const SessionId id = s.begin_session(make_start());
        try {
            for (;; ++stored) {
                s.record_trial(id, make_trial(stored, "full", pad));
                ASSERT_LT(stored, 10000) << "the size limit never took effect";
            }
        } catch (const StoreError& e) {
            message = e.what();
            EXPECT_EQ(e.kind(), StoreErrc::disk_full) << message;
            EXPECT_EQ(e.sqlite_code() & 0xff, SQLITE_FULL);
            EXPECT_EQ(e.file(), path);
        }
        ASSERT_GT(stored, 10);
        // The same connection still reads, and still refuses: no half trial appears.
        EXPECT_EQ(s.trial_count(id), stored);
        expect_store_error(StoreErrc::disk_full, [&] { s.record_trial(id, make_trial(stored, "full", pad)); });
        EXPECT_EQ(s.trial_count(id), stored);
    }
    EXPECT_TRUE(contains(message, path.string())) << message;
    EXPECT_TRUE(contains(message, "full")) << message;
    EXPECT_TRUE(contains(message, "record trial " + std::to_string(stored))) << message;
    EXPECT_TRUE(contains(message, "was not stored")) << message;
    expect_intact(path, stored, "full", pad);

    // With room again the session goes on where it stopped.
    {
        Store s = Store::create_or_open(path);
        const SessionId id = s.sessions()[0].id;
        s.record_trial(id, make_trial(stored, "full", pad));
    }
    expect_intact(path, stored + 1, "full", pad);
}

// A real write error from the kernel rather than SQLite's own limit: a child
// process whose files may not grow past a few pages (RLIMIT_FSIZE, so write()
// fails with EFBIG mid-frame) writes until the store refuses. Its WAL may end in
// a torn frame; recovery must ignore it.
TEST(StoreFailures, WriteErrorFromTheOsLosesNothingAlreadyStored) {
    TempDir dir;
    const auto path = dir / "study.db";
    constexpr std::size_t pad = 1500;
    {
        Store s = Store::create_or_open(path);
        s.begin_session(make_start());
    }
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        close(fds[0]);
        std::signal(SIGXFSZ, SIG_IGN);  // else the kernel kills us instead of failing write()
        const rlimit limit{256 * 1024, 256 * 1024};
        setrlimit(RLIMIT_FSIZE, &limit);
        std::string report;
        std::int64_t n = 0;
        try {
            Store s = Store::create_or_open(path);
            const SessionId id = s.sessions().at(0).id;
            for (; n < 100000; ++n) s.record_trial(id, make_trial(n, "fsize", pad));
            report = "no error";
        } catch (const StoreError& e) {
            report = std::string(to_string(e.kind())) + "|" + e.what();
        } catch (const std::exception& e) {
            report = std::string("other|") + e.what();
        }
        report = std::to_string(n) + "|" + report;
        (void)!write(fds[1], report.data(), report.size());
        _exit(0);
    }
    close(fds[1]);
    std::string report;
    char buf[4096];
    for (ssize_t r; (r = read(fds[0], buf, sizeof buf)) > 0;) report.append(buf, static_cast<std::size_t>(r));
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFEXITED(status)) << report;

    const auto bar = report.find('|');
    ASSERT_NE(bar, std::string::npos) << report;
    const std::int64_t stored = std::stoll(report.substr(0, bar));
    const std::string rest = report.substr(bar + 1);
    EXPECT_TRUE(rest.starts_with("io_error|") || rest.starts_with("disk_full|")) << rest;
    EXPECT_TRUE(contains(rest, path.string())) << rest;
    EXPECT_GT(stored, 5) << rest;
    std::printf("  child stored %lld trials, then: %s\n", static_cast<long long>(stored), rest.c_str());
    expect_intact(path, stored, "fsize", pad);
}

// --- A write-protected file ----------------------------------------------------

// Runs `checks` in a child process that cannot override file permissions (root
// can: as root the child becomes "nobody"), and returns what it wrote to `out`.
template <class F>
std::string run_unprivileged(F&& checks) {
    int fds[2];
    if (pipe(fds) != 0) return "pipe failed";
    const pid_t pid = fork();
    if (pid < 0) return "fork failed";
    if (pid == 0) {
        close(fds[0]);
        std::string out;
        if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0)) {
            out = "FAIL cannot drop root privileges\n";
        } else {
            try {
                checks(out);
            } catch (const std::exception& e) {
                out += std::string("FAIL unexpected exception: ") + e.what() + "\n";
            }
        }
        (void)!write(fds[1], out.data(), out.size());
        _exit(0);
    }
    close(fds[1]);
    std::string out;
    char buf[4096];
    for (ssize_t r; (r = read(fds[0], buf, sizeof buf)) > 0;) out.append(buf, static_cast<std::size_t>(r));
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    if (!WIFEXITED(status)) out += "FAIL the child did not exit normally\n";
    return out;
}

TEST(StoreFailures, WriteProtectedFileRefusesWritersAndServesReaders) {
    TempDir dir;
    const auto path = dir / "study.db";
    {
        Store s = Store::create_or_open(path);
        const SessionId id = s.begin_session(make_start());
        for (int i = 0; i < 5; ++i) s.record_trial(id, make_trial(i));
    }
    ASSERT_FALSE(std::filesystem::exists(path.string() + "-wal"));  // checkpointed on close
    ASSERT_EQ(chmod(path.c_str(), 0444), 0);
    ASSERT_EQ(chmod(dir.path().c_str(), 0777), 0);  // a reader may create -wal/-shm, as in a lab's shared folder
    const std::string before = file_bytes(path);

    const std::string out = run_unprivileged([&](std::string& log) {
        try {
            Store::create_or_open(path);
            log += "FAIL create_or_open of a 0444 file succeeded\n";
        } catch (const StoreError& e) {
            log += std::string("writer: ") + to_string(e.kind()) + ": " + e.what() + "\n";
        }
        Store r = Store::open_read_only(path);
        const auto sessions = r.sessions();
        const auto trials = r.trials(sessions.at(0).id);
        log +=
            "reader: " + std::to_string(trials.size()) + " trials, last stimulus " + trials.back().stimulus_json + "\n";
        try {
            r.record_trial(sessions.at(0).id, make_trial(5));
            log += "FAIL a read-only store recorded a trial\n";
        } catch (const StoreError& e) {
            log += std::string("record: ") + to_string(e.kind()) + "\n";
        }
    });
    EXPECT_FALSE(contains(out, "FAIL")) << out;
    EXPECT_TRUE(contains(out, "writer: read_only: " + path.string())) << out;
    EXPECT_TRUE(contains(out, "write-protected")) << out;
    EXPECT_TRUE(contains(out, "reader: 5 trials, last stimulus " + make_trial(4).stimulus_json)) << out;
    EXPECT_TRUE(contains(out, "record: read_only")) << out;
    std::printf("%s", out.c_str());
    EXPECT_EQ(file_bytes(path), before);
}

// --- A file from a newer atonlab -------------------------------------------------

TEST(StoreFailures, NewerSchemaIsRefusedAndLeftUntouched) {
    TempDir dir;
    const auto path = dir / "study.db";
    {
        Store s = Store::create_or_open(path);
        s.record_trial(s.begin_session(make_start()), make_trial(0));
    }
    {
        RawDb raw(path);  // what a newer atonlab would have left
        ASSERT_EQ(raw.exec("PRAGMA user_version = " + std::to_string(schema_version() + 1)), "");
    }
    ASSERT_FALSE(std::filesystem::exists(path.string() + "-wal"));
    const std::string before = file_bytes(path);

    const std::string msg = expect_store_error(StoreErrc::newer_schema, [&] { Store::create_or_open(path); });
    EXPECT_TRUE(contains(msg, path.string())) << msg;
    EXPECT_TRUE(contains(msg, "schema version " + std::to_string(schema_version() + 1))) << msg;
    EXPECT_TRUE(contains(msg, "not changed")) << msg;
    expect_store_error(StoreErrc::newer_schema, [&] { Store::open_existing(path); });
    expect_store_error(StoreErrc::newer_schema, [&] { Store::open_read_only(path); });
    EXPECT_EQ(file_bytes(path), before);
    RawDb raw(path, SQLITE_OPEN_READONLY);
    EXPECT_EQ(raw.integer("PRAGMA user_version"), schema_version() + 1);
}

// --- Not a study file --------------------------------------------------------------

TEST(StoreFailures, GarbageFileIsRefusedAndLeftUntouched) {
    TempDir dir;
    const auto path = dir / "notes.db";
    {
        std::ofstream out(path, std::ios::binary);
        for (int i = 0; i < 200; ++i) out << "observer P07 said the left light looked brighter. ";
    }
    const std::string before = file_bytes(path);
    const std::string msg = expect_store_error(StoreErrc::not_a_database, [&] { Store::create_or_open(path); });
    EXPECT_TRUE(contains(msg, path.string() + " is not an SQLite database")) << msg;
    EXPECT_TRUE(contains(msg, "file is not a database")) << msg;  // SQLite's own words
    expect_store_error(StoreErrc::not_a_database, [&] { Store::open_read_only(path); });
    EXPECT_EQ(file_bytes(path), before);
    EXPECT_FALSE(std::filesystem::exists(path.string() + "-wal"));
}

TEST(StoreFailures, OtherSqliteDatabaseIsRefusedAndLeftUntouched) {
    TempDir dir;
    const auto path = dir / "other.db";
    {
        RawDb raw(path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
        ASSERT_EQ(raw.exec("CREATE TABLE recipes (name TEXT); INSERT INTO recipes VALUES ('bread');"), "");
    }
    const std::string before = file_bytes(path);
    const std::string msg = expect_store_error(StoreErrc::not_a_study, [&] { Store::create_or_open(path); });
    EXPECT_TRUE(contains(msg, "not an atonlab study file")) << msg;
    EXPECT_EQ(file_bytes(path), before);
}

TEST(StoreFailures, EmptyFileBecomesAStudy) {
    TempDir dir;
    const auto path = dir / "empty.db";
    { std::ofstream touch(path); }
    expect_store_error(StoreErrc::not_a_study, [&] { Store::open_read_only(path); });
    Store s = Store::create_or_open(path);
    EXPECT_EQ(s.file_schema_version(), schema_version());
}

// --- Paths ---------------------------------------------------------------------------

TEST(StoreFailures, MissingDirectoryOrFileIsAClearError) {
    TempDir dir;
    const auto missing_dir = dir.path() / "no-such-dir";
    const auto path = missing_dir / "study.db";
    const std::string msg = expect_store_error(StoreErrc::cannot_open, [&] { Store::create_or_open(path); });
    EXPECT_TRUE(contains(msg, path.string())) << msg;
    EXPECT_TRUE(contains(msg, "the directory " + missing_dir.string() + " does not exist")) << msg;
    EXPECT_FALSE(std::filesystem::exists(missing_dir));

    const auto absent = dir / "absent.db";
    const std::string msg2 = expect_store_error(StoreErrc::cannot_open, [&] { Store::open_existing(absent); });
    EXPECT_TRUE(contains(msg2, "does not exist")) << msg2;
    expect_store_error(StoreErrc::cannot_open, [&] { Store::open_read_only(absent); });
    EXPECT_FALSE(std::filesystem::exists(absent));  // a typo never creates an empty study

    expect_store_error(StoreErrc::cannot_open, [&] { Store::create_or_open(dir.path()); });  // a directory
}

}  // namespace
}  // namespace atonlab::store
