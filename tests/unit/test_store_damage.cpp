// Study files that refuse to be damaged (docs/store.md, "Opening"): a file
// that is cut short (to 1 byte, to half), whose header or whose trials pages
// have bytes overwritten, is refused by every open function with one sentence
// naming the file and what is wrong, and is left byte-for-byte as it was; two
// processes creating the same new study file at once both get their session.
// The damage is made here by hand and the verdict is SQLite's own (PRAGMA
// integrity_check through a raw connection agrees that the file is damaged).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "atonlab/store/schema.h"
#include "atonlab/store/store.h"
#include "../support/skip.h"
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

/// A closed study file (no -wal left) with one session of `n` trials whose
/// rows span many pages.
void write_study(const fs::path& path, int n = 400) {
    Store s = Store::create_or_open(path);
    const SessionId id = s.begin_session(make_start());
    for (int i = 0; i < n; ++i) s.record_trial(id, make_trial(i, "damage", 300));
    s.finish_session(id, SessionStatus::completed);
}

void write_bytes(const fs::path& path, std::int64_t offset, const std::string& bytes) {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(offset);
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    ASSERT_TRUE(f.good());
}

void truncate_to(const fs::path& path, std::uintmax_t size) {
    fs::resize_file(path, size);
}

/// Every open function refuses the file with `kind`, naming it, in one line,
/// and its bytes (and the absence of a -wal file) are as before. Returns the
/// create_or_open message.
std::string expect_refused_unchanged(const fs::path& path, StoreErrc kind) {
    const std::string before = file_bytes(path);
    const std::string msg = expect_store_error(kind, [&] { Store::create_or_open(path); });
    expect_store_error(kind, [&] { Store::open_existing(path); });
    expect_store_error(kind, [&] { Store::open_read_only(path); });
    EXPECT_TRUE(contains(msg, path.string())) << msg;
    EXPECT_TRUE(contains(msg, "not changed")) << msg;
    EXPECT_FALSE(contains(msg, "\n")) << msg;
    EXPECT_EQ(file_bytes(path), before) << "the refused file was changed";
    EXPECT_FALSE(fs::exists(path.string() + "-wal") && fs::file_size(path.string() + "-wal") > 0);
    return msg;
}

/// SQLite's own verdict through a raw connection: the file is damaged (an
/// integrity_check other than "ok", or an error reading it).
bool sqlite_finds_damage(const fs::path& path) {
    try {
        RawDb raw(path, SQLITE_OPEN_READONLY);
        return raw.text("PRAGMA integrity_check") != "ok";
    } catch (const std::exception&) {
        return true;
    }
}

std::int64_t page_size_of(const fs::path& path) {
    RawDb raw(path, SQLITE_OPEN_READONLY);
    return raw.integer("PRAGMA page_size");
}

/// The trials table's pages: its root (an interior page once the table spans
/// several), then its leaves where SQLite's dbstat table is compiled in.
std::vector<std::int64_t> trials_pages(const fs::path& path) {
    RawDb raw(path, SQLITE_OPEN_READONLY);
    std::vector<std::int64_t> pages{raw.integer("SELECT rootpage FROM sqlite_schema WHERE name = 'trials'")};
    try {
        const std::string leaves =
            raw.text("SELECT pageno FROM dbstat WHERE name = 'trials' AND pagetype = 'leaf' ORDER BY pageno");
        std::size_t at = 0;
        while (at < leaves.size()) {
            const std::size_t end = leaves.find('\n', at);
            pages.push_back(std::stoll(leaves.substr(at, end - at)));
            if (end == std::string::npos) break;
            at = end + 1;
        }
    } catch (const std::exception&) {
        // No dbstat in this SQLite build: the root page alone.
    }
    return pages;
}

TEST(StoreDamage, FileCutToOneByteIsRefusedNotReinitialised) {
    TempDir dir;
    const fs::path path = dir / "study.db";
    write_study(path, 20);
    truncate_to(path, 1);
    const std::string msg = expect_refused_unchanged(path, StoreErrc::not_a_database);
    EXPECT_TRUE(contains(msg, "1 byte long")) << msg;
    EXPECT_EQ(fs::file_size(path), 1u);
}

TEST(StoreDamage, FileCutToHalfIsRefused) {
    TempDir dir;
    const fs::path path = dir / "study.db";
    write_study(path);
    const auto size = fs::file_size(path);
    ASSERT_GT(size, 16u * 4096u) << "the study should span many pages";
    truncate_to(path, size / 2);
    ASSERT_TRUE(sqlite_finds_damage(path));
    const std::string msg = expect_refused_unchanged(path, StoreErrc::corrupt);
    EXPECT_TRUE(contains(msg, "cut short")) << msg;
}

// Not damage: a process killed in a WAL checkpoint. The checkpoint writes the
// -wal's pages into the file in page order, page 1 (the header with the new,
// larger page count) first, so the file is shorter than its header says until
// SQLite completes the checkpoint from the -wal on the next open. (Seen once in
// GL.run.KilledRepeatedly..., which kills a session at random moments.) The
// state is made here exactly: a writer killed with its frames in the -wal,
// then the -wal's newest page 1 copied over the file's, as the checkpoint's
// first write would.
TEST(StoreDamage, AFileShorterThanItsHeaderWithTheRestInItsWalOpens) {
    TempDir dir;
    const fs::path path = dir / "study.db";
    write_study(path, 20);
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        try {
            Store s = Store::open_existing(path);
            const SessionId id = s.begin_session(make_start("killed", 7));
            for (int i = 0; i < 400; ++i) s.record_trial(id, make_trial(i, "in-wal", 300));
            // A commit that writes page 1 (the header, with the grown page
            // count), as a freelist change does: the schema version rewritten.
            RawDb raw(path);
            const long long version = raw.integer("PRAGMA user_version");
            if (!raw.exec("PRAGMA user_version = " + std::to_string(version)).empty()) _exit(2);
            _exit(0);  // both still open: no close, no checkpoint, the new pages stay in the -wal
        } catch (const std::exception& e) {
            std::fprintf(stderr, "writer: %s\n", e.what());
        }
        _exit(1);
    }
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);

    // The -wal (sqlite.org/walformat.html): a 32-byte header (page size at
    // bytes 8-11, the salts at 16-23), then frames of a 24-byte header (page
    // number at 0-3, the salts at 8-15) and a page. Frames whose salts are not
    // the header's are left from before the -wal last restarted.
    const std::string wal = file_bytes(path.string() + "-wal");
    ASSERT_GT(wal.size(), 32u);
    const auto be32_of = [](const std::string& bytes, std::size_t at) {
        return (std::uint32_t{static_cast<unsigned char>(bytes[at])} << 24) |
               (std::uint32_t{static_cast<unsigned char>(bytes[at + 1])} << 16) |
               (std::uint32_t{static_cast<unsigned char>(bytes[at + 2])} << 8) |
               std::uint32_t{static_cast<unsigned char>(bytes[at + 3])};
    };
    const auto be32 = [&](std::size_t at) { return be32_of(wal, at); };
    const std::size_t page = be32(8);
    std::string page1;
    for (std::size_t at = 32; at + 24 + page <= wal.size(); at += 24 + page)
        if (be32(at) == 1 && be32(at + 8) == be32(16) && be32(at + 12) == be32(20)) page1 = wal.substr(at + 24, page);
    ASSERT_EQ(page1.size(), page) << "the -wal holds no page 1";
    write_bytes(path, 0, page1);
    const std::uint32_t header_pages = be32_of(page1, 28);
    ASSERT_LT(fs::file_size(path), std::uintmax_t{header_pages} * page) << "the file should be shorter than its header";

    { Store reopened = Store::open_existing(path); }  // not refused; SQLite completes the checkpoint
    RawDb raw(path, SQLITE_OPEN_READONLY);
    EXPECT_EQ(raw.text("PRAGMA integrity_check"), "ok");
    EXPECT_EQ(raw.integer("SELECT count(*) FROM trials"), 420);

    // The same file without its -wal is cut short, and still refused.
    TempDir other;
    const fs::path alone = other / "study.db";
    write_study(alone);
    const auto size = fs::file_size(alone);
    truncate_to(alone, size / 2);
    EXPECT_TRUE(contains(expect_refused_unchanged(alone, StoreErrc::corrupt), "cut short"));
}

TEST(StoreDamage, FileCutInsideItsHeaderIsRefused) {
    TempDir dir;
    const fs::path path = dir / "study.db";
    write_study(path, 5);
    truncate_to(path, 60);
    const std::string msg = expect_refused_unchanged(path, StoreErrc::not_a_database);
    EXPECT_TRUE(contains(msg, "60 bytes long")) << msg;
}

// The fields of the 100-byte header that SQLite checks (sqlite.org/fileformat2.html
// §1.3): the magic string, the page size, the read/write versions, the payload
// fractions. Each overwritten with bytes drawn from a seeded generator until
// they differ from the file's own.
TEST(StoreDamage, HeaderBytesOverwrittenAreRefused) {
    struct Field {
        std::int64_t offset;
        std::size_t length;
    };
    const std::vector<Field> fields{{0, 16}, {16, 2}, {18, 2}, {21, 3}, {44, 4}};
    std::mt19937 rng(20240611);
    for (const Field& f : fields) {
        SCOPED_TRACE("header bytes " + std::to_string(f.offset) + ".." + std::to_string(f.offset + f.length - 1));
        TempDir dir;
        const fs::path path = dir / "study.db";
        write_study(path, 30);
        const std::string original = file_bytes(path).substr(static_cast<std::size_t>(f.offset), f.length);
        std::string garbage = original;
        while (garbage == original || (f.offset == 16 && (garbage == std::string("\x00\x01", 2)))) {
            for (char& c : garbage) c = static_cast<char>(rng() & 0xff);
        }
        write_bytes(path, f.offset, garbage);
        ASSERT_TRUE(sqlite_finds_damage(path));
        std::string kind_ok;
        const std::string before = file_bytes(path);
        try {
            Store::create_or_open(path);
            ADD_FAILURE() << "a file with a damaged header was opened";
        } catch (const StoreError& e) {
            EXPECT_TRUE(e.kind() == StoreErrc::not_a_database || e.kind() == StoreErrc::corrupt) << e.what();
            EXPECT_TRUE(contains(e.what(), path.string())) << e.what();
            EXPECT_TRUE(contains(e.what(), "not changed")) << e.what();
        }
        EXPECT_THROW(Store::open_read_only(path), StoreError);
        EXPECT_EQ(file_bytes(path), before);
    }
}

// Bytes overwritten in the trials table's pages: the root page's header and
// cell pointers, and (with dbstat) a few of its leaves', 12 bytes at a seeded
// offset in the page's first 16 (the b-tree page header and the first cell
// pointers: structure, never free space or a value's text).
TEST(StoreDamage, TrialsPagesOverwrittenAreRefused) {
    TempDir base;
    const fs::path pristine = base / "pristine.db";
    write_study(pristine);
    const std::int64_t page = page_size_of(pristine);
    std::vector<std::int64_t> pages = trials_pages(pristine);
    ASSERT_FALSE(pages.empty());
    if (pages.size() > 4) pages = {pages[0], pages[1], pages[pages.size() / 2], pages.back()};
    std::mt19937 rng(7);
    for (const std::int64_t p : pages) {
        SCOPED_TRACE("page " + std::to_string(p));
        TempDir dir;
        const fs::path path = dir / "study.db";
        fs::copy_file(pristine, path);
        std::string garbage(12, '\0');
        for (char& c : garbage) c = static_cast<char>(rng() & 0xff);
        const std::int64_t offset = (p - 1) * page + static_cast<std::int64_t>(rng() % 4);
        write_bytes(path, offset, garbage);
        ASSERT_TRUE(sqlite_finds_damage(path)) << "the damage should be visible to SQLite itself";
        const std::string msg = expect_refused_unchanged(path, StoreErrc::corrupt);
        EXPECT_TRUE(contains(msg, "is damaged")) << msg;
        EXPECT_TRUE(contains(msg, "--salvage")) << msg;
    }
}

TEST(StoreDamage, UndamagedFileOpensAndAnUnstampedStudyIsStillAStudy) {
    TempDir dir;
    const fs::path path = dir / "study.db";
    write_study(path, 10);
    {
        // A study written before application_id was stamped: same tables, id 0.
        RawDb raw(path);
        ASSERT_EQ(raw.exec("PRAGMA application_id = 0"), "");
    }
    {
        Store s = Store::open_read_only(path);
        EXPECT_EQ(s.trials(SessionId{1}).size(), 10u);
    }
    { Store s = Store::create_or_open(path); }
    RawDb raw(path, SQLITE_OPEN_READONLY);
    EXPECT_EQ(raw.integer("PRAGMA application_id"), application_id) << "the next writer stamps it";
}

TEST(StoreDamage, SalvageReadsWhatIsLeftOfADamagedFile) {
    TempDir dir;
    const fs::path path = dir / "study.db";
    const int n = 400;
    write_study(path, n);
    const std::vector<std::int64_t> pages = trials_pages(path);
    if (pages.size() < 3) ATONLAB_SKIP_MISSING_TOOL() << "no dbstat in this SQLite build: the leaves cannot be found";
    // One leaf's structure overwritten: the rows on the other leaves stay readable.
    const std::int64_t page = page_size_of(path);
    write_bytes(path, (pages[2] - 1) * page, std::string(12, '\xee'));
    expect_store_error(StoreErrc::corrupt, [&] { Store::open_read_only(path); });
    const std::string before = file_bytes(path);

    StoreOptions salvage;
    salvage.verify = false;
    Store s = Store::open_read_only(path, salvage);
    const Salvage got = s.salvage();
    ASSERT_EQ(got.sessions.size(), 1u);
    EXPECT_GT(got.trials.size(), 0u);
    EXPECT_LT(got.trials.size(), static_cast<std::size_t>(n));
    EXPECT_GT(got.unreadable_trials, 0);
    EXPECT_EQ(static_cast<std::int64_t>(got.trials.size()) + got.unreadable_trials, n)
        << "every row id is either read or counted unreadable";
    for (const SalvagedTrial& t : got.trials) {
        EXPECT_EQ(t.session, SessionId{1});
        test_support::expect_same_trial(t.trial, make_trial(t.trial.trial_index, "damage", 300));
    }
    EXPECT_EQ(file_bytes(path), before);
}

// --- Two writers creating one new file ------------------------------------------

// Two processes released together open a study file that does not exist yet,
// each begins a session and stores three trials: both succeed, 20 rounds of 20.
// (Before the WAL switch was retried, one often failed with "could not switch
// to the WAL journal: database is locked".)
TEST(StoreConcurrency, TwoProcessesCreatingOneNewFileBothGetTheirSession) {
    for (int round = 0; round < 20; ++round) {
        SCOPED_TRACE("round " + std::to_string(round));
        TempDir dir;
        const fs::path path = dir / "new.db";
        int go[2];
        ASSERT_EQ(pipe(go), 0);
        std::vector<pid_t> children;
        for (int c = 0; c < 2; ++c) {
            const pid_t pid = fork();
            ASSERT_GE(pid, 0);
            if (pid == 0) {
                close(go[1]);
                char byte = 0;
                if (read(go[0], &byte, 1) != 1) _exit(3);
                try {
                    Store s = Store::create_or_open(path);
                    const SessionId id = s.begin_session(make_start("P" + std::to_string(c), 100 + c));
                    for (int i = 0; i < 3; ++i) s.record_trial(id, make_trial(i, "c" + std::to_string(c)));
                    s.finish_session(id, SessionStatus::completed);
                } catch (const std::exception& e) {
                    std::fprintf(stderr, "child %d: %s\n", c, e.what());
                    _exit(1);
                }
                _exit(0);
            }
            children.push_back(pid);
        }
        close(go[0]);
        const char release[2] = {1, 1};
        ASSERT_EQ(write(go[1], release, 2), 2);  // both children wake at once
        close(go[1]);
        for (const pid_t pid : children) {
            int status = 0;
            ASSERT_EQ(waitpid(pid, &status, 0), pid);
            ASSERT_TRUE(WIFEXITED(status));
            EXPECT_EQ(WEXITSTATUS(status), 0) << "a writer failed (its message is on stderr above)";
        }
        RawDb raw(path, SQLITE_OPEN_READONLY);
        EXPECT_EQ(raw.text("PRAGMA integrity_check"), "ok");
        EXPECT_EQ(raw.integer("SELECT count(*) FROM sessions"), 2);
        EXPECT_EQ(raw.integer("SELECT count(*) FROM trials"), 6);
        EXPECT_EQ(raw.integer("SELECT count(*) FROM schema_history"), schema_version());
    }
}

}  // namespace
}  // namespace atonlab::store
