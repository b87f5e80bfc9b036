#pragma once
// The store's only contact with the SQLite C API: a move-only connection, a
// move-only prepared statement, a transaction guard, and the translation of
// SQLite result codes into StoreError. Values always go through bind_*();
// exec() is for fixed scripts (schema DDL, pragmas) that carry no values.
#include <sqlite3.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/store/error.h"

namespace atonlab::store::sql {

/// StoreErrc for an SQLite result code (primary or extended).
StoreErrc kind_of(int sqlite_code) noexcept;
/// "SQLITE_FULL", "SQLITE_IOERR_WRITE"-style name: the primary name, plus the
/// extended number when there is one.
std::string code_name(int sqlite_code);

class Statement;

class Connection {
public:
    /// sqlite3_open_v2 with `flags` (SQLITE_OPEN_*); extended result codes on.
    Connection(std::filesystem::path path, int flags);
    // Not movable: cached statements point back at their connection.
    Connection(Connection&&) = delete;
    Connection& operator=(Connection&&) = delete;
    Connection(const Connection&) = delete;
    Connection& operator=(const Connection&) = delete;
    ~Connection();

    sqlite3* get() const noexcept { return db_; }
    const std::filesystem::path& path() const noexcept { return path_; }

    /// Throws StoreError "PATH: could not DOING: SQLITE MESSAGE (CODE)" for `rc`.
    [[noreturn]] void fail(int rc, std::string_view doing) const;
    /// Runs a fixed SQL script with no bound values (DDL, pragmas).
    void exec(const char* sql, std::string_view doing);
    /// Runs a statement returning one integer (a pragma's value).
    std::int64_t query_int(const char* sql, std::string_view doing);
    /// Runs a statement returning one text value.
    std::string query_text(const char* sql, std::string_view doing);

    /// Lowers SQLite's run-time limits (sqlite3_limit) to what atonlab's own
    /// records need (docs/store.md, "Limits"); `max_value_bytes` is the
    /// longest text or blob (SQLITE_LIMIT_LENGTH).
    void limit_to_atonlab(std::int64_t max_value_bytes);
    /// The longest text or blob this connection reads or writes (SQLITE_LIMIT_LENGTH).
    std::int64_t max_value_bytes() const noexcept;

    /// A statement compiled once per connection and kept (SQLITE_PREPARE_PERSISTENT).
    /// Use it through a Use guard so it is always reset.
    Statement& cached(const char* sql);

private:
    std::filesystem::path path_;
    sqlite3* db_ = nullptr;
    // Keyed by the SQL text's address: every cached statement is a string literal.
    std::map<const char*, std::unique_ptr<Statement>> cache_;
};

class Statement {
public:
    Statement(Connection& connection, std::string_view sql, bool persistent = false);
    Statement(Statement&&) noexcept;
    Statement& operator=(Statement&&) = delete;
    Statement(const Statement&) = delete;
    Statement& operator=(const Statement&) = delete;
    ~Statement();

    // Parameters are 1-based, as in SQLite.
    void bind(int i, std::int64_t value);
    void bind(int i, int value) { bind(i, static_cast<std::int64_t>(value)); }
    void bind(int i, double value);
    void bind(int i, std::string_view text);  ///< copied (SQLITE_TRANSIENT)
    void bind_blob(int i, std::span<const std::byte> data);
    void bind_null(int i);
    template <class T>
    void bind(int i, const std::optional<T>& value) {
        if (value) {
            bind(i, *value);
        } else {
            bind_null(i);
        }
    }

    /// Steps once: true when a row is ready, false when done. Throws on error,
    /// naming `doing`.
    bool step(std::string_view doing);
    /// Steps a statement that returns no rows.
    void run(std::string_view doing);
    /// Resets the statement and clears its bindings (ends its read, too).
    void reset() noexcept;

    bool is_null(int col) const;
    std::int64_t int64(int col) const;
    int int32(int col) const;
    double real(int col) const;
    std::string text(int col) const;
    std::optional<std::string> optional_text(int col) const;
    std::vector<std::byte> blob(int col) const;

private:
    void check_bind(int rc, int i);
    Connection* connection_;
    sqlite3_stmt* stmt_ = nullptr;
};

/// Resets a statement when the scope ends, so no statement is left mid-step
/// holding a read snapshot open (that would pin the WAL and block checkpoints).
class Use {
public:
    explicit Use(Statement& s) noexcept : s_(s) {}
    ~Use() { s_.reset(); }
    Use(const Use&) = delete;
    Use& operator=(const Use&) = delete;
    Statement* operator->() noexcept { return &s_; }
    Statement& operator*() noexcept { return s_; }

private:
    Statement& s_;
};

/// BEGIN on construction, ROLLBACK on destruction unless commit() ran. A write
/// transaction is IMMEDIATE: it takes the write lock at BEGIN (waiting up to the
/// busy timeout), so it can never fail half-way for lack of a lock.
class Transaction {
public:
    enum class Kind { read, write };
    Transaction(Connection& connection, Kind kind, std::string_view doing);
    Transaction(const Transaction&) = delete;
    Transaction& operator=(const Transaction&) = delete;
    ~Transaction();
    /// COMMIT: with synchronous=FULL the WAL is fsynced before this returns.
    void commit();

private:
    Connection& connection_;
    std::string doing_;
    bool open_ = false;
};

}  // namespace atonlab::store::sql
