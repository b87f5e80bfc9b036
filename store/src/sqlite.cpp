// The SQLite C API behind RAII owners; see sqlite.h.
#include "sqlite.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <utility>

namespace atonlab::store::sql {
namespace {

// SQLITE_TRANSIENT is the C-style cast ((sqlite3_destructor_type)-1): it tells
// SQLite to copy bound text/blobs before bind returns, so a statement never
// points at a caller's buffer. The cast lives in SQLite's macro; silence
// -Wold-style-cast for exactly this one expression.
sqlite3_destructor_type transient() noexcept {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wold-style-cast"
    return SQLITE_TRANSIENT;
#pragma GCC diagnostic pop
}

const char* primary_name(int primary) noexcept {
    switch (primary) {
        case SQLITE_OK:
            return "SQLITE_OK";
        case SQLITE_ERROR:
            return "SQLITE_ERROR";
        case SQLITE_INTERNAL:
            return "SQLITE_INTERNAL";
        case SQLITE_PERM:
            return "SQLITE_PERM";
        case SQLITE_ABORT:
            return "SQLITE_ABORT";
        case SQLITE_BUSY:
            return "SQLITE_BUSY";
        case SQLITE_LOCKED:
            return "SQLITE_LOCKED";
        case SQLITE_NOMEM:
            return "SQLITE_NOMEM";
        case SQLITE_READONLY:
            return "SQLITE_READONLY";
        case SQLITE_INTERRUPT:
            return "SQLITE_INTERRUPT";
        case SQLITE_IOERR:
            return "SQLITE_IOERR";
        case SQLITE_CORRUPT:
            return "SQLITE_CORRUPT";
        case SQLITE_NOTFOUND:
            return "SQLITE_NOTFOUND";
        case SQLITE_FULL:
            return "SQLITE_FULL";
        case SQLITE_CANTOPEN:
            return "SQLITE_CANTOPEN";
        case SQLITE_PROTOCOL:
            return "SQLITE_PROTOCOL";
        case SQLITE_SCHEMA:
            return "SQLITE_SCHEMA";
        case SQLITE_TOOBIG:
            return "SQLITE_TOOBIG";
        case SQLITE_CONSTRAINT:
            return "SQLITE_CONSTRAINT";
        case SQLITE_MISMATCH:
            return "SQLITE_MISMATCH";
        case SQLITE_MISUSE:
            return "SQLITE_MISUSE";
        case SQLITE_NOLFS:
            return "SQLITE_NOLFS";
        case SQLITE_AUTH:
            return "SQLITE_AUTH";
        case SQLITE_RANGE:
            return "SQLITE_RANGE";
        case SQLITE_NOTADB:
            return "SQLITE_NOTADB";
        default:
            return "SQLITE_?";
    }
}

// Names of the extended codes a study file meets in practice (I/O and lock
// failures, constraints); others are shown as their primary name and number.
const char* extended_name(int code) noexcept {
    switch (code) {
        case SQLITE_IOERR_READ:
            return "SQLITE_IOERR_READ";
        case SQLITE_IOERR_SHORT_READ:
            return "SQLITE_IOERR_SHORT_READ";
        case SQLITE_IOERR_WRITE:
            return "SQLITE_IOERR_WRITE";
        case SQLITE_IOERR_FSYNC:
            return "SQLITE_IOERR_FSYNC";
        case SQLITE_IOERR_DIR_FSYNC:
            return "SQLITE_IOERR_DIR_FSYNC";
        case SQLITE_IOERR_TRUNCATE:
            return "SQLITE_IOERR_TRUNCATE";
        case SQLITE_IOERR_FSTAT:
            return "SQLITE_IOERR_FSTAT";
        case SQLITE_IOERR_LOCK:
            return "SQLITE_IOERR_LOCK";
        case SQLITE_IOERR_SHMOPEN:
            return "SQLITE_IOERR_SHMOPEN";
        case SQLITE_IOERR_SHMSIZE:
            return "SQLITE_IOERR_SHMSIZE";
        case SQLITE_IOERR_SHMMAP:
            return "SQLITE_IOERR_SHMMAP";
        case SQLITE_BUSY_RECOVERY:
            return "SQLITE_BUSY_RECOVERY";
        case SQLITE_BUSY_SNAPSHOT:
            return "SQLITE_BUSY_SNAPSHOT";
        case SQLITE_CANTOPEN_ISDIR:
            return "SQLITE_CANTOPEN_ISDIR";
        case SQLITE_READONLY_RECOVERY:
            return "SQLITE_READONLY_RECOVERY";
        case SQLITE_READONLY_CANTLOCK:
            return "SQLITE_READONLY_CANTLOCK";
        case SQLITE_READONLY_DBMOVED:
            return "SQLITE_READONLY_DBMOVED";
        case SQLITE_CONSTRAINT_CHECK:
            return "SQLITE_CONSTRAINT_CHECK";
        case SQLITE_CONSTRAINT_FOREIGNKEY:
            return "SQLITE_CONSTRAINT_FOREIGNKEY";
        case SQLITE_CONSTRAINT_NOTNULL:
            return "SQLITE_CONSTRAINT_NOTNULL";
        case SQLITE_CONSTRAINT_PRIMARYKEY:
            return "SQLITE_CONSTRAINT_PRIMARYKEY";
        case SQLITE_CONSTRAINT_TRIGGER:
            return "SQLITE_CONSTRAINT_TRIGGER";
        case SQLITE_CONSTRAINT_UNIQUE:
            return "SQLITE_CONSTRAINT_UNIQUE";
        default:
            return nullptr;
    }
}

}  // namespace

StoreErrc kind_of(int sqlite_code) noexcept {
    switch (sqlite_code & 0xff) {
        case SQLITE_FULL:
            return StoreErrc::disk_full;
        case SQLITE_IOERR:
            return StoreErrc::io_error;
        case SQLITE_READONLY:
        case SQLITE_PERM:
            return StoreErrc::read_only;
        case SQLITE_BUSY:
        case SQLITE_LOCKED:
            return StoreErrc::busy;
        case SQLITE_CORRUPT:
            return StoreErrc::corrupt;
        case SQLITE_NOTADB:
            return StoreErrc::not_a_database;
        case SQLITE_CANTOPEN:
            return StoreErrc::cannot_open;
        case SQLITE_CONSTRAINT:
            return StoreErrc::constraint;
        default:
            return StoreErrc::other;
    }
}

std::string code_name(int sqlite_code) {
    const int primary = sqlite_code & 0xff;
    if (primary == sqlite_code) return primary_name(primary);
    if (const char* name = extended_name(sqlite_code)) return name;
    return fmt::format("{}, extended code {}", primary_name(primary), sqlite_code);
}

// --- Connection --------------------------------------------------------------

Connection::Connection(std::filesystem::path path, int flags) : path_(std::move(path)) {
    const int rc = sqlite3_open_v2(path_.c_str(), &db_, flags, nullptr);
    if (rc != SQLITE_OK) {
        // sqlite3_open_v2 allocates a handle even on failure, to carry the message.
        const std::string message = db_ ? sqlite3_errmsg(db_) : sqlite3_errstr(rc);
        const int code = db_ ? sqlite3_extended_errcode(db_) : rc;
        sqlite3_close_v2(db_);
        db_ = nullptr;
        throw StoreError(
            kind_of(code), path_,
            fmt::format("{}: could not open the study file: {} ({})", path_.string(), message, code_name(code)), code);
    }
    sqlite3_extended_result_codes(db_, 1);
}

Connection::~Connection() {
    cache_.clear();  // statements first: sqlite3_close_v2 would otherwise defer the close
    sqlite3_close_v2(db_);
}

void Connection::fail(int rc, std::string_view doing) const {
    // The connection's last error, when it has one for this failure, is more
    // specific than the bare code ("CHECK constraint failed: ..." vs "constraint failed").
    int code = rc;
    std::string message = sqlite3_errstr(rc);
    if (db_ && (sqlite3_errcode(db_) & 0xff) == (rc & 0xff)) {
        code = sqlite3_extended_errcode(db_);
        message = sqlite3_errmsg(db_);
    }
    // A value over limit_to_atonlab's length: say what the limit is.
    if ((code & 0xff) == SQLITE_TOOBIG && db_ && message == "string or blob too big")
        message += fmt::format(" (longer than {} bytes, atonlab's limit for one text or blob)", max_value_bytes());
    throw StoreError(kind_of(code), path_,
                     fmt::format("{}: could not {}: {} ({})", path_.string(), doing, message, code_name(code)), code);
}

void Connection::limit_to_atonlab(std::int64_t max_value_bytes) {
    // What atonlab's own records need, with a wide margin (docs/store.md,
    // "Limits", says how each was chosen); SQLite's defaults are far larger
    // (sqlite.org/limits.html), sized for any application. A file from
    // elsewhere then cannot make a statement allocate or recurse far beyond a
    // real study's needs: a longer value, a deeper expression, more columns
    // is an error (SQLITE_TOOBIG, SQLITE_ERROR) instead of memory and stack.
    const int length = static_cast<int>(std::clamp<std::int64_t>(max_value_bytes, 1, std::numeric_limits<int>::max()));
    constexpr int kSqlLengthBytes = 1 << 20;  // the longest statement atonlab prepares: a few kB
    constexpr int kExprDepth = 100;           // atonlab's deepest expression: about 10
    constexpr int kColumns = 100;             // the widest table or result: 19 (view trial_log)
    constexpr int kVariables = 100;           // the highest parameter atonlab binds: ?15
    constexpr int kTriggerDepth = 10;         // atonlab's triggers only RAISE: depth 1
    constexpr int kLikePatternBytes = 1000;   // atonlab's LIKE and GLOB patterns: under 30 bytes
    constexpr int kCompoundSelect = 10;       // atonlab writes no UNION
    constexpr int kVdbeOps = 1'000'000;       // atonlab's longest statement: well under 10,000 operations
    for (const auto& [id, value] : {std::pair{SQLITE_LIMIT_LENGTH, length}, std::pair{SQLITE_LIMIT_SQL_LENGTH, kSqlLengthBytes},
                                    std::pair{SQLITE_LIMIT_EXPR_DEPTH, kExprDepth}, std::pair{SQLITE_LIMIT_COLUMN, kColumns},
                                    std::pair{SQLITE_LIMIT_VARIABLE_NUMBER, kVariables},
                                    std::pair{SQLITE_LIMIT_TRIGGER_DEPTH, kTriggerDepth},
                                    std::pair{SQLITE_LIMIT_LIKE_PATTERN_LENGTH, kLikePatternBytes},
                                    std::pair{SQLITE_LIMIT_COMPOUND_SELECT, kCompoundSelect},
                                    std::pair{SQLITE_LIMIT_VDBE_OP, kVdbeOps},
                                    std::pair{SQLITE_LIMIT_ATTACHED, 0}, std::pair{SQLITE_LIMIT_WORKER_THREADS, 0}}) {
        sqlite3_limit(db_, id, value);  // returns the previous value; SQLite only ever lowers a limit here
    }
}

std::int64_t Connection::max_value_bytes() const noexcept {
    return sqlite3_limit(db_, SQLITE_LIMIT_LENGTH, -1);
}

void Connection::exec(const char* sql, std::string_view doing) {
    const int rc = sqlite3_exec(db_, sql, nullptr, nullptr, nullptr);
    if (rc != SQLITE_OK) fail(rc, doing);
}

std::int64_t Connection::query_int(const char* sql, std::string_view doing) {
    Statement s(*this, sql);
    if (!s.step(doing)) fail(SQLITE_ERROR, doing);
    return s.int64(0);
}

std::string Connection::query_text(const char* sql, std::string_view doing) {
    Statement s(*this, sql);
    std::string out;
    // integrity_check answers with one row per problem; join them.
    while (s.step(doing)) {
        if (!out.empty()) out += '\n';
        out += s.text(0);
    }
    return out;
}

Statement& Connection::cached(const char* sql) {
    auto it = cache_.find(sql);
    if (it == cache_.end()) {
        it = cache_.emplace(sql, std::make_unique<Statement>(*this, sql, true)).first;
    }
    return *it->second;
}

// --- Statement ---------------------------------------------------------------

Statement::Statement(Connection& connection, std::string_view sql, bool persistent) : connection_(&connection) {
    const unsigned flags = persistent ? SQLITE_PREPARE_PERSISTENT : 0u;
    const int rc =
        sqlite3_prepare_v3(connection.get(), sql.data(), static_cast<int>(sql.size()), flags, &stmt_, nullptr);
    if (rc != SQLITE_OK) connection.fail(rc, fmt::format("prepare the statement \"{}\"", sql));
}

Statement::Statement(Statement&& other) noexcept
    : connection_(other.connection_), stmt_(std::exchange(other.stmt_, nullptr)) {}

Statement::~Statement() {
    sqlite3_finalize(stmt_);
}

void Statement::check_bind(int rc, int i) {
    if (rc != SQLITE_OK) connection_->fail(rc, fmt::format("bind parameter {} of \"{}\"", i, sqlite3_sql(stmt_)));
}

void Statement::bind(int i, std::int64_t value) {
    check_bind(sqlite3_bind_int64(stmt_, i, value), i);
}

void Statement::bind(int i, double value) {
    check_bind(sqlite3_bind_double(stmt_, i, value), i);
}

void Statement::bind(int i, std::string_view text) {
    check_bind(sqlite3_bind_text64(stmt_, i, text.data(), text.size(), transient(), SQLITE_UTF8), i);
}

void Statement::bind_blob(int i, std::span<const std::byte> data) {
    // A zero-length blob bound from a null pointer would be NULL; bind an empty blob instead.
    if (data.empty()) {
        check_bind(sqlite3_bind_zeroblob(stmt_, i, 0), i);
    } else {
        check_bind(sqlite3_bind_blob64(stmt_, i, data.data(), data.size(), transient()), i);
    }
}

void Statement::bind_null(int i) {
    check_bind(sqlite3_bind_null(stmt_, i), i);
}

bool Statement::step(std::string_view doing) {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    connection_->fail(rc, doing);
}

void Statement::run(std::string_view doing) {
    while (step(doing)) {
    }
}

void Statement::reset() noexcept {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
}

bool Statement::is_null(int col) const {
    return sqlite3_column_type(stmt_, col) == SQLITE_NULL;
}

std::int64_t Statement::int64(int col) const {
    return sqlite3_column_int64(stmt_, col);
}

int Statement::int32(int col) const {
    return sqlite3_column_int(stmt_, col);
}

double Statement::real(int col) const {
    return sqlite3_column_double(stmt_, col);
}

std::string Statement::text(int col) const {
    const unsigned char* p = sqlite3_column_text(stmt_, col);
    const int n = sqlite3_column_bytes(stmt_, col);
    if (!p) return {};
    return {reinterpret_cast<const char*>(p), static_cast<std::size_t>(n)};
}

std::optional<std::string> Statement::optional_text(int col) const {
    if (is_null(col)) return std::nullopt;
    return text(col);
}

std::vector<std::byte> Statement::blob(int col) const {
    const void* p = sqlite3_column_blob(stmt_, col);
    const int n = sqlite3_column_bytes(stmt_, col);
    if (!p || n <= 0) return {};
    const auto* b = static_cast<const std::byte*>(p);
    return {b, b + n};
}

// --- Transaction -------------------------------------------------------------

Transaction::Transaction(Connection& connection, Kind kind, std::string_view doing)
    : connection_(connection), doing_(doing) {
    connection_.exec(kind == Kind::write ? "BEGIN IMMEDIATE" : "BEGIN DEFERRED", doing_);
    open_ = true;
}

Transaction::~Transaction() {
    // SQLite rolls some failures (SQLITE_FULL, SQLITE_IOERR, ...) back by itself;
    // then autocommit is on again and there is nothing to undo.
    if (open_ && sqlite3_get_autocommit(connection_.get()) == 0) {
        sqlite3_exec(connection_.get(), "ROLLBACK", nullptr, nullptr, nullptr);
    }
}

void Transaction::commit() {
    connection_.exec("COMMIT", doing_);
    open_ = false;
}

}  // namespace atonlab::store::sql
