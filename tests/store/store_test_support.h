#pragma once
// Shared by tests/unit/test_store*.cpp: a temporary directory, a raw SQLite
// connection that looks at a study file without going through the store (so
// the tests compare against SQLite itself and the values they put in, not the
// store's own reading), and a deterministic trial payload.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include "atonlab/store/store.h"

namespace atonlab::store::test_support {

/// A fresh directory under $TMPDIR (or /tmp), removed with everything in it.
class TempDir {
public:
    TempDir() {
        const char* base = std::getenv("TMPDIR");
        std::string pattern = std::string(base && *base ? base : "/tmp") + "/atonlab-store-XXXXXX";
        if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
        path_ = pattern;
    }
    ~TempDir() {
        std::error_code ec;
        // Tests chmod files read-only; make them removable again first.
        for (const auto& e : std::filesystem::recursive_directory_iterator(path_, ec)) {
            std::filesystem::permissions(e.path(), std::filesystem::perms::owner_all,
                                         std::filesystem::perm_options::add, ec);
        }
        std::filesystem::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::filesystem::path& path() const { return path_; }
    std::filesystem::path operator/(const char* name) const { return path_ / name; }

private:
    std::filesystem::path path_;
};

/// A plain sqlite3 connection, independent of the store's code.
class RawDb {
public:
    explicit RawDb(const std::filesystem::path& path, int flags = SQLITE_OPEN_READWRITE) {
        if (sqlite3_open_v2(path.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
            std::string msg = sqlite3_errmsg(db_);
            sqlite3_close_v2(db_);
            throw std::runtime_error("raw open failed: " + msg);
        }
        sqlite3_busy_timeout(db_, 5000);
    }
    ~RawDb() { sqlite3_close_v2(db_); }
    RawDb(const RawDb&) = delete;
    RawDb& operator=(const RawDb&) = delete;
    sqlite3* get() const { return db_; }

    /// Runs `sql`; returns "" on success, else SQLite's message.
    std::string exec(const std::string& sql) {
        if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr) == SQLITE_OK) return {};
        return sqlite3_errmsg(db_);
    }
    /// The first column of the first row as text (rows joined by '\n' when several).
    std::string text(const std::string& sql) {
        sqlite3_stmt* s = nullptr;
        if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &s, nullptr) != SQLITE_OK) {
            throw std::runtime_error("raw prepare failed: " + std::string(sqlite3_errmsg(db_)));
        }
        std::string out;
        int rc = 0;
        while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
            if (!out.empty()) out += '\n';
            const unsigned char* p = sqlite3_column_text(s, 0);
            out += p ? reinterpret_cast<const char*>(p) : "NULL";
        }
        sqlite3_finalize(s);
        if (rc != SQLITE_DONE) throw std::runtime_error("raw step failed: " + std::string(sqlite3_errmsg(db_)));
        return out;
    }
    long long integer(const std::string& sql) { return std::stoll(text(sql)); }

private:
    sqlite3* db_ = nullptr;
};

inline std::string file_bytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Trial `i` of a test session: every field a function of i (and `tag`), so a
/// reader can check each stored trial against what was written without
/// trusting the store. `pad` bytes of filler make the rows span pages.
inline TrialRecord make_trial(std::int64_t i, const std::string& tag = "t", std::size_t pad = 0) {
    TrialRecord t;
    t.trial_index = i;
    t.block = static_cast<int>(i / 10);
    t.condition_id = "cond-" + std::to_string(i % 3);
    t.procedure_id = "staircase-" + std::to_string(i % 2);
    t.level = 0.25 * static_cast<double>(i) - 3.0;
    if (i % 3 != 2) t.test_on_left = (i % 2 == 0);
    t.stimulus_json = "{\"i\":" + std::to_string(i) + ",\"tag\":\"" + tag +
                      "\",\"intensity_cd\":" + std::to_string(100 + i) + ",\"pad\":\"" + std::string(pad, 'x') + "\"}";
    t.response = i % 2 == 0 ? "left" : "right";
    if (i % 5 == 0) t.response_value = 1.0 / static_cast<double>(i + 1);
    t.response_time_s = 0.5 + 0.001 * static_cast<double>(i);
    t.onset_time_s = 2.0 * static_cast<double>(i) + 0.125;
    t.dropped_frames = static_cast<int>(i % 4);
    t.missed_deadline = i % 7 == 0;
    t.procedure_state_json = "{\"reversals\":" + std::to_string(i / 4) + ",\"tag\":\"" + tag + "\"}";
    return t;
}

/// Field-by-field comparison of a stored trial with the one written.
inline void expect_same_trial(const TrialRecord& stored, const TrialRecord& written) {
    SCOPED_TRACE("trial " + std::to_string(written.trial_index));
    EXPECT_EQ(stored.trial_index, written.trial_index);
    EXPECT_EQ(stored.block, written.block);
    EXPECT_EQ(stored.condition_id, written.condition_id);
    EXPECT_EQ(stored.procedure_id, written.procedure_id);
    EXPECT_EQ(stored.level, written.level);  // REAL round-trips a double exactly
    EXPECT_EQ(stored.test_on_left, written.test_on_left);
    EXPECT_EQ(stored.stimulus_json, written.stimulus_json);
    EXPECT_EQ(stored.response, written.response);
    EXPECT_EQ(stored.response_value, written.response_value);
    EXPECT_EQ(stored.response_time_s, written.response_time_s);
    EXPECT_EQ(stored.onset_time_s, written.onset_time_s);
    EXPECT_EQ(stored.dropped_frames, written.dropped_frames);
    EXPECT_EQ(stored.missed_deadline, written.missed_deadline);
    EXPECT_EQ(stored.procedure_state_json, written.procedure_state_json);
    EXPECT_FALSE(stored.recorded_at.empty());
}

inline SessionStart make_start(const std::string& observer = "OBS-01", std::uint64_t seed = 42) {
    SessionStart s;
    s.observer_code = observer;
    s.protocol_name = "test-protocol.toml";
    s.protocol_text = "[[block]]\nname = \"glare\"\n";
    s.seed = seed;
    return s;
}

/// Runs `kind` check: the callable throws StoreError of `kind`; returns its message.
template <class F>
std::string expect_store_error(StoreErrc kind, F&& f) {
    try {
        f();
    } catch (const StoreError& e) {
        EXPECT_EQ(to_string(e.kind()), std::string(to_string(kind))) << e.what();
        return e.what();
    }
    ADD_FAILURE() << "expected a StoreError of kind " << to_string(kind);
    return {};
}

}  // namespace atonlab::store::test_support
