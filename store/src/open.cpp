// Opening, checking, configuring and migrating a study file or a display-profile
// file (see open.h).
#include "open.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>
#include <fstream>
#include <string>
#include <system_error>
#include <thread>

#include "atonlab/store/version.h"
#include "constraints.h"
#include "schema_check.h"

namespace atonlab::store::detail {
namespace {

namespace fs = std::filesystem;

std::string str(const fs::path& p) {
    return p.string();
}

[[noreturn]] void fail(StoreErrc kind, const fs::path& path, const std::string& message) {
    throw StoreError(kind, path, message);
}

// What the messages call the file, its PRAGMA application_id, and what to do
// with a damaged one (salvage reads sessions and trials: studies only).
const char* noun(FileKind kind) {
    return kind == FileKind::study ? "study file" : "display-profile file";
}
int app_id_of(FileKind kind) {
    return kind == FileKind::study ? application_id : profile_application_id;
}
const char* damaged_hint(FileKind kind) {
    return kind == FileKind::study ? "restore it from a backup, or read what is left with atonlab analyze --salvage"
                                   : "restore it from a backup, or measure the displays again into a new profile file";
}

// Checks SQLite would only answer with "unable to open database file".
void check_path(const fs::path& path, Access access, FileKind kind) {
    std::error_code ec;
    if (access == Access::create_or_open) {
        const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
        if (!fs::exists(dir, ec)) {
            fail(StoreErrc::cannot_open, path,
                 fmt::format("{}: cannot create the {}: the directory {} does not exist", str(path), noun(kind),
                             str(dir)));
        }
        if (!fs::is_directory(dir, ec)) {
            fail(StoreErrc::cannot_open, path,
                 fmt::format("{}: cannot create the {}: {} is not a directory", str(path), noun(kind), str(dir)));
        }
    } else if (!fs::exists(path, ec)) {
        fail(StoreErrc::cannot_open, path,
             fmt::format("{}: cannot open the {}: it does not exist", str(path), noun(kind)));
    }
    if (fs::is_directory(path, ec)) {
        fail(StoreErrc::cannot_open, path,
             fmt::format("{}: cannot open the {}: it is a directory", str(path), noun(kind)));
    }
}

// The first look at an existing file, before SQLite sees it: SQLite treats a
// file shorter than its 100-byte header as an empty database and would write a
// new schema over it (a study file truncated to 1 byte would silently become a
// new, empty study). 0 bytes is a new file (or one whose content is still in
// its -wal file, which SQLite reads). The header layout: sqlite.org/fileformat2.html.
void check_header(const fs::path& path, FileKind kind) {
    std::error_code ec;
    const auto size = fs::file_size(path, ec);
    if (ec || size == 0) return;  // absent (created by SQLite) or empty
    if (size < 100) {
        fail(StoreErrc::not_a_database, path,
             fmt::format("{} is not an SQLite database, so not an atonlab {}: it is {} byte{} long, shorter "
                         "than SQLite's 100-byte header (a truncated file?); it was not changed",
                         str(path), noun(kind), size, size == 1 ? "" : "s"));
    }
    std::array<unsigned char, 100> h{};
    std::ifstream in(path, std::ios::binary);
    if (!in.read(reinterpret_cast<char*>(h.data()), static_cast<std::streamsize>(h.size()))) return;  // SQLite will say
    if (std::memcmp(h.data(), "SQLite format 3", 16) != 0) return;  // SQLite's "file is not a database"
    const auto be32 = [&](std::size_t at) {
        return (std::uint32_t{h[at]} << 24) | (std::uint32_t{h[at + 1]} << 16) | (std::uint32_t{h[at + 2]} << 8) |
               std::uint32_t{h[at + 3]};
    };
    // Page size: bytes 16-17, big-endian; the value 1 means 65536.
    const std::uint32_t page = (std::uint32_t{h[16]} << 8 | h[17]) == 1 ? 65536u : (std::uint32_t{h[16]} << 8 | h[17]);
    // The header's page count (bytes 28-31) is valid when the change counter
    // (24-27) equals the version-valid-for number (92-95). Without a -wal file,
    // a file shorter than its own page count was cut short. With one, it may
    // not be: a checkpoint copies the -wal's pages into the file in page order,
    // page 1 (the header, with the new count) first, so a process killed in a
    // checkpoint leaves a file shorter than its header says, and SQLite
    // completes it from the -wal when the file is next opened; a page missing
    // from both is then found by the integrity check (verify).
    std::error_code wal_ec;
    const auto wal_size = fs::file_size(fs::path(path.string() + "-wal"), wal_ec);
    const bool wal_holds_frames = !wal_ec && wal_size > 32;  // more than the -wal file's own 32-byte header
    const std::uint32_t pages = be32(28);
    if (!wal_holds_frames && page >= 512 && pages > 0 && be32(24) == be32(92) &&
        size < static_cast<std::uintmax_t>(pages) * static_cast<std::uintmax_t>(page)) {
        fail(StoreErrc::corrupt, path,
             fmt::format("{} is damaged: it is {} bytes long but its header says {} pages of {} bytes ({} bytes), "
                         "so it was cut short; it was not changed ({})",
                         str(path), size, pages, page, static_cast<std::uintmax_t>(pages) * page, damaged_hint(kind)));
    }
}

// SQLite's own hardening for files that may come from anywhere
// (sqlite.org/security.html, "Untrusted SQLite Database Files"): defensive
// mode (no writable_schema, no journal_mode=OFF, no writes to shadow tables),
// no extensions, no double-quoted string literals, and cell_size_check (a
// malformed b-tree cell is an error when read, not a wrong answer).
// SQLITE_DBCONFIG_TRUSTED_SCHEMA stays on: the schema's CHECKs call
// json_valid(), which SQLite 3.40 (Debian 12) does not mark innocuous, so an
// untrusted schema could not be written; with extensions off, no function a
// file's schema can name has a side effect.
void harden(sql::Connection& db, const StoreOptions& options) {
    for (const auto& [option, value] :
         {std::pair{SQLITE_DBCONFIG_DEFENSIVE, 1}, std::pair{SQLITE_DBCONFIG_ENABLE_LOAD_EXTENSION, 0},
          std::pair{SQLITE_DBCONFIG_DQS_DDL, 0}, std::pair{SQLITE_DBCONFIG_DQS_DML, 0}}) {
        const int rc = sqlite3_db_config(db.get(), option, value, nullptr);
        if (rc != SQLITE_OK) db.fail(rc, fmt::format("set SQLite's defensive option {}", option));
    }
    db.exec("PRAGMA cell_size_check = ON", "turn on cell_size_check");
    db.limit_to_atonlab(options.max_value_bytes);
}

// One line of at most 160 characters, for a sentence quoting SQLite's report
// (its lines joined by "; ", without integrity_check's "*** in database main ***").
std::string one_line(const std::string& text) {
    std::string out;
    std::size_t at = 0;
    while (at <= text.size()) {
        const std::size_t end = std::min(text.find('\n', at), text.size());
        const std::string line = text.substr(at, end - at);
        if (!line.empty() && line.rfind("*** in database", 0) != 0) out += (out.empty() ? "" : "; ") + line;
        at = end + 1;
    }
    if (out.size() > 160) out = out.substr(0, 157) + "...";
    return out;
}

// A value longer than the connection's limit on one text or blob
// (sqlite.h, limit_to_atonlab; docs/store.md, "Limits"), `where` in the file.
[[noreturn]] void fail_too_long(sql::Connection& db, FileKind kind, const std::string& where) {
    fail(StoreErrc::corrupt, db.path(),
         fmt::format("{} holds a text or blob longer than {} bytes, atonlab's limit for one value, which no study "
                     "atonlab writes needs ({}); it was not changed ({})",
                     str(db.path()), db.max_value_bytes(), where, damaged_hint(kind)));
}

// PRAGMA integrity_check, stopped at its first problem: b-tree structure,
// free list, every record's format, NOT NULL constraints, and that every
// index matches its table (quick_check skips that last part); then the
// schema's CHECK and NOT NULL constraints over every row (constraints.h).
// integrity_check's own CHECK evaluation is turned off for it: a read-only
// connection skips it anyway, and the one pass after it names the rows, so a
// reader and a writer refuse the same file with the same sentence. Measured
// at about 1 s for a 100 MB study (docs/store.md, "Opening").
void verify(sql::Connection& db, FileKind kind) {
    std::string report;
    try {
        db.exec("PRAGMA ignore_check_constraints = ON", "check the file's integrity");
        report = db.query_text("PRAGMA integrity_check(1)", "check the file's integrity");
        db.exec("PRAGMA ignore_check_constraints = OFF", "check the file's integrity");
    } catch (const StoreError& e) {
        // A lock or the OS failing is not damage; anything else SQLite says
        // while reading the schema and walking every page is ("database disk
        // image is malformed", "unsupported file format", ...).
        if (e.kind() != StoreErrc::corrupt && e.kind() != StoreErrc::other && e.kind() != StoreErrc::not_a_database)
            throw;
        // A value over the connection's length limit stops SQLite's walk.
        if ((e.sqlite_code() & 0xff) == SQLITE_TOOBIG) fail_too_long(db, kind, "found by SQLite's integrity check");
        report = sqlite3_errmsg(db.get());
    }
    if (report != "ok") {
        fail(StoreErrc::corrupt, db.path(),
             fmt::format("{} is damaged (SQLite's integrity check: {}); it was not changed ({})", str(db.path()),
                         one_line(report), damaged_hint(kind)));
    }
    const std::vector<ConstraintViolation> broken = find_constraint_violations(db, 4);
    for (const ConstraintViolation& v : broken) {
        if (v.constraint.rfind(kLengthLimit, 0) != 0) continue;
        fail_too_long(db, kind,
                      fmt::format("{} of {}", v.row_id != 0 ? fmt::format("row {}", v.row_id) : "a row", v.table));
    }
    if (!broken.empty()) {
        fail(StoreErrc::corrupt, db.path(),
             fmt::format("{} is damaged inside its records ({}); it was not changed ({})", str(db.path()),
                         describe(broken), damaged_hint(kind)));
    }
}

// The file's tables, columns, constraints, indexes, triggers and views
// against those the first `version` steps make (schema_check.h). Cheap: the
// reference is made once per version, and only sqlite_schema is read.
void check_schema(sql::Connection& db, const std::vector<SchemaObject>& schema, std::span<const Migration> steps,
                  int version, FileKind kind) {
    const std::optional<std::string> difference = first_schema_difference(db, schema, steps, version);
    if (!difference) return;
    fail(StoreErrc::schema_altered, db.path(),
         fmt::format("{}'s schema was altered ({}), so it is not the schema atonlab's migrations make for version "
                     "{}; it was not changed ({})",
                     str(db.path()), *difference, version,
                     kind == FileKind::study
                         ? "atonlab neither writes to nor analyses such a file: restore it from a backup, or read "
                           "what it holds with atonlab analyze --salvage"
                         : "restore it from a backup, or measure the displays again into a new profile file"));
}

// PRAGMA journal_mode = WAL needs an exclusive lock on a file not yet in WAL
// mode, and SQLite does not call the busy handler for it when two connections
// both hold a read lock and want it (it would deadlock): one of them gets
// SQLITE_BUSY at once. Two sessions creating the same new study file meet
// exactly this, so the switch is retried here within the busy timeout.
std::string switch_to_wal(sql::Connection& db, int busy_timeout_ms) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(busy_timeout_ms);
    for (int attempt = 0;; ++attempt) {
        try {
            return db.query_text("PRAGMA journal_mode = WAL", "switch to the WAL journal");
        } catch (const StoreError& e) {
            if (e.kind() != StoreErrc::busy || std::chrono::steady_clock::now() >= deadline) throw;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(std::min(1 << std::min(attempt, 6), 50)));
    }
}

// PRAGMA arguments cannot be bound parameters. Every value formatted into one
// here is an integer of the program's own (a schema version, a page count), so
// nothing from outside ever becomes SQL text.
std::string pragma(const char* name, std::int64_t value) {
    return fmt::format("PRAGMA {} = {}", name, value);
}

void migrate(sql::Connection& db, std::span<const Migration> steps, FileKind kind) {
    const int latest = steps.empty() ? 0 : steps.back().to_version;
    sql::Transaction tx(db, sql::Transaction::Kind::write, "start the schema migration");
    // Read again under the write lock: another process may have migrated the
    // file between our first look and now.
    int version = static_cast<int>(db.query_int("PRAGMA user_version", "read the schema version"));
    if (version > latest) {
        fail(StoreErrc::newer_schema, db.path(),
             fmt::format("{} was written by a newer atonlab (schema version {}, this build knows up to {}); "
                         "it was not changed, open it with a newer atonlab",
                         str(db.path()), version, latest));
    }
    // A study from before application_id was stamped gets it with its next writer.
    const bool stamped = db.query_int("PRAGMA application_id", "read the file header") == app_id_of(kind);
    if (version == latest && stamped) return;  // nothing to do; the transaction ends with no change
    for (const Migration& step : steps) {
        if (step.to_version <= version) continue;
        if (step.to_version != version + 1) {
            fail(StoreErrc::other, db.path(),
                 fmt::format("{}: the migration list skips from schema version {} to {} (a bug in atonlab)",
                             str(db.path()), version, step.to_version));
        }
        const std::string doing =
            fmt::format("migrate the schema to version {} ({})", step.to_version, step.description);
        const std::string sql(step.sql);
        db.exec(sql.c_str(), doing);
        sql::Statement history(db,
                               "INSERT INTO schema_history (version, description, software_version, applied_at) "
                               "VALUES (?1, ?2, ?3, strftime('%Y-%m-%dT%H:%M:%fZ', 'now'))");
        history.bind(1, step.to_version);
        history.bind(2, step.description);
        history.bind(3, std::string_view(software_version()));
        history.run(doing);
        db.exec(pragma("user_version", step.to_version).c_str(), doing);
        version = step.to_version;
    }
    db.exec(pragma("application_id", app_id_of(kind)).c_str(), kind == FileKind::study
                                                                   ? "stamp the file as an atonlab study"
                                                                   : "stamp the file as a display-profile file");
    tx.commit();
}

}  // namespace

std::unique_ptr<sql::Connection> open_study(const fs::path& path, Access access, const StoreOptions& options,
                                            std::span<const Migration> steps) {
    return open_file(path, access, options, steps, FileKind::study);
}

std::unique_ptr<sql::Connection> open_file(const fs::path& path, Access access, const StoreOptions& options,
                                           std::span<const Migration> steps, FileKind kind) {
    check_path(path, access, kind);
    check_header(path, kind);
    const int flags = access == Access::read_only       ? SQLITE_OPEN_READONLY
                      : access == Access::open_existing ? SQLITE_OPEN_READWRITE
                                                        : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE;
    auto db = std::make_unique<sql::Connection>(path, flags);
    harden(*db, options);

    // SQLITE_OPEN_READWRITE silently falls back to read-only on a write-protected file.
    if (access != Access::read_only && sqlite3_db_readonly(db->get(), "main") == 1) {
        fail(StoreErrc::read_only, path,
             fmt::format("{}: cannot open the {} for writing: the file is write-protected "
                         "(it can still be opened read-only)",
                         str(path), noun(kind)));
    }
    sqlite3_busy_timeout(db->get(), options.busy_timeout_ms);
    db->exec("PRAGMA foreign_keys = ON", "turn on foreign keys");

    // First read of the file: a non-database fails here, before anything is
    // written. One read transaction, so that a file another process is creating
    // at this moment is seen whole (stamped, with its tables) or not at all.
    std::int64_t app_id = 0;
    int version = 0;
    std::int64_t objects = 0;
    bool study_tables = false;
    std::vector<SchemaObject> schema;
    try {
        sql::Transaction look(*db, sql::Transaction::Kind::read, "read the file header");
        app_id = db->query_int("PRAGMA application_id", "read the file header");
        version = static_cast<int>(db->query_int("PRAGMA user_version", "read the schema version"));
        objects = db->query_int("SELECT count(*) FROM sqlite_schema", "list the file's tables");
        study_tables = db->query_int(
                           "SELECT count(*) FROM sqlite_schema WHERE type = 'table' AND name IN "
                           "('schema_history', 'sessions', 'trials')",
                           "look for the study's tables") == 3;
        schema = read_schema(*db);  // with the version it belongs to
        look.commit();
    } catch (const StoreError& e) {
        if (e.kind() == StoreErrc::not_a_database) {
            fail(StoreErrc::not_a_database, path,
                 fmt::format("{} is not an SQLite database, so not an atonlab {} (SQLite: {}); it was not "
                             "changed",
                             str(path), noun(kind), sqlite3_errstr(e.sqlite_code())));
        }
        // A lock, the OS or permissions failing is not damage; SQLite's
        // "malformed" or "unsupported file format" is.
        if (e.kind() != StoreErrc::corrupt && e.kind() != StoreErrc::other) throw;
        fail(StoreErrc::corrupt, path,
             fmt::format("{} is damaged: SQLite cannot read its header or schema ({}, {}); it was not changed ({})",
                         str(path), sqlite3_errstr(e.sqlite_code()), sql::code_name(e.sqlite_code()),
                         damaged_hint(kind)));
    }
    const int latest = steps.empty() ? 0 : steps.back().to_version;
    const bool empty = app_id == 0 && version == 0 && objects == 0;
    if (app_id != app_id_of(kind)) {
        // The other kind of atonlab file: say which option takes it.
        if (app_id == app_id_of(FileKind::study) || app_id == app_id_of(FileKind::profiles)) {
            const bool is_study = app_id == app_id_of(FileKind::study);
            fail(StoreErrc::not_a_study, path,
                 fmt::format("{} is an atonlab {}, not a {} ({}); it was not changed", str(path),
                             is_study ? "study file" : "display-profile file", noun(kind),
                             is_study ? "a study file is given with --db"
                                      : "a display-profile file is given with "
                                        "--profiles"));
        }
        // A study written before application_id was stamped would carry no id but
        // the study's own tables and a schema version: still a study.
        const bool unstamped_study = kind == FileKind::study && app_id == 0 && version >= 1 && study_tables;
        if (!empty && !unstamped_study) {
            fail(StoreErrc::not_a_study, path,
                 fmt::format("{} is an SQLite database but not an atonlab {} (application_id {}, "
                             "{} schema objects); it was not changed",
                             str(path), noun(kind), app_id, objects));
        }
        if (empty && access == Access::read_only) {
            fail(StoreErrc::not_a_study, path,
                 fmt::format("{} is an empty database, not yet an atonlab {}", str(path), noun(kind)));
        }
    }
    if (version > latest) {
        fail(StoreErrc::newer_schema, path,
             fmt::format("{} was written by a newer atonlab (schema version {}, this build knows up to {}); "
                         "it was not changed, open it with a newer atonlab",
                         str(path), version, latest));
    }

    if (!empty && options.verify) {
        // The schema first: the constraint scan evaluates the file's own CHECK texts.
        check_schema(*db, schema, steps, version, kind);
        verify(*db, kind);
    }

    if (access == Access::read_only) {
        if (version < latest) {
            fail(StoreErrc::older_schema, path,
                 fmt::format("{} has schema version {}, older than this build's {}; open it once for writing "
                             "to migrate it",
                             str(path), version, latest));
        }
        db->exec("PRAGMA query_only = ON", "make the connection query-only");
        return db;
    }

    // A committed trial must survive a killed process and a power cut: WAL with
    // synchronous=FULL fsyncs the WAL on every commit (NORMAL would only survive
    // the former). Costs one fsync per trial, far below one trial's duration.
    const std::string mode = switch_to_wal(*db, options.busy_timeout_ms);
    if (mode != "wal") {
        fail(StoreErrc::other, path,
             fmt::format("{}: cannot switch to the WAL journal (SQLite kept \"{}\"; WAL needs a local file "
                         "system that supports shared memory)",
                         str(path), mode));
    }
    if (options.durable) {
        db->exec("PRAGMA synchronous = FULL", "set synchronous = FULL");
    } else {
        db->exec("PRAGMA synchronous = OFF", "set synchronous = OFF");
    }
    if (options.max_size_bytes > 0) {
        const std::int64_t page = db->query_int("PRAGMA page_size", "read the page size");
        db->exec(pragma("max_page_count", std::max<std::int64_t>(1, options.max_size_bytes / page)).c_str(),
                 "limit the file size");
    }
    migrate(*db, steps, kind);
    return db;
}

void migrate_file(const fs::path& path, std::span<const Migration> steps) {
    open_study(path, Access::create_or_open, StoreOptions{}, steps);
}

}  // namespace atonlab::store::detail
