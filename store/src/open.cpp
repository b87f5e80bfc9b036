// Opening, checking, configuring and migrating a study file (see open.h).
#include "open.h"

#include <fmt/format.h>

#include <string>
#include <system_error>

#include "atonlab/store/version.h"

namespace atonlab::store::detail {
namespace {

namespace fs = std::filesystem;

std::string str(const fs::path& p) {
    return p.string();
}

[[noreturn]] void fail(StoreErrc kind, const fs::path& path, const std::string& message) {
    throw StoreError(kind, path, message);
}

// Checks SQLite would only answer with "unable to open database file".
void check_path(const fs::path& path, Access access) {
    std::error_code ec;
    if (access == Access::create_or_open) {
        const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
        if (!fs::exists(dir, ec)) {
            fail(StoreErrc::cannot_open, path,
                 fmt::format("{}: cannot create the study file: the directory {} does not exist", str(path), str(dir)));
        }
        if (!fs::is_directory(dir, ec)) {
            fail(StoreErrc::cannot_open, path,
                 fmt::format("{}: cannot create the study file: {} is not a directory", str(path), str(dir)));
        }
    } else if (!fs::exists(path, ec)) {
        fail(StoreErrc::cannot_open, path, fmt::format("{}: cannot open the study file: it does not exist", str(path)));
    }
    if (fs::is_directory(path, ec)) {
        fail(StoreErrc::cannot_open, path, fmt::format("{}: cannot open the study file: it is a directory", str(path)));
    }
}

// PRAGMA arguments cannot be bound parameters. Every value formatted into one
// here is an integer of the program's own (a schema version, a page count), so
// nothing from outside ever becomes SQL text.
std::string pragma(const char* name, std::int64_t value) {
    return fmt::format("PRAGMA {} = {}", name, value);
}

void migrate(sql::Connection& db, std::span<const Migration> steps) {
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
    if (version == latest) return;  // nothing to do; the transaction ends with no change
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
    db.exec(pragma("application_id", application_id).c_str(), "stamp the file as an atonlab study");
    tx.commit();
}

}  // namespace

std::unique_ptr<sql::Connection> open_study(const fs::path& path, Access access, const StoreOptions& options,
                                            std::span<const Migration> steps) {
    check_path(path, access);
    const int flags = access == Access::read_only       ? SQLITE_OPEN_READONLY
                      : access == Access::open_existing ? SQLITE_OPEN_READWRITE
                                                        : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE;
    auto db = std::make_unique<sql::Connection>(path, flags);

    // SQLITE_OPEN_READWRITE silently falls back to read-only on a write-protected file.
    if (access != Access::read_only && sqlite3_db_readonly(db->get(), "main") == 1) {
        fail(StoreErrc::read_only, path,
             fmt::format("{}: cannot open the study file for writing: the file is write-protected "
                         "(it can still be opened read-only)",
                         str(path)));
    }
    sqlite3_busy_timeout(db->get(), options.busy_timeout_ms);
    db->exec("PRAGMA foreign_keys = ON", "turn on foreign keys");

    // First read of the file: a non-database fails here, before anything is written.
    std::int64_t app_id = 0;
    int version = 0;
    try {
        app_id = db->query_int("PRAGMA application_id", "read the file header");
        version = static_cast<int>(db->query_int("PRAGMA user_version", "read the schema version"));
    } catch (const StoreError& e) {
        if (e.kind() != StoreErrc::not_a_database) throw;
        fail(StoreErrc::not_a_database, path,
             fmt::format("{} is not an SQLite database, so not an atonlab study file (SQLite: {}); it was not changed",
                         str(path), sqlite3_errmsg(db->get())));
    }
    const int latest = steps.empty() ? 0 : steps.back().to_version;
    if (app_id != application_id) {
        const std::int64_t objects = db->query_int("SELECT count(*) FROM sqlite_schema", "list the file's tables");
        const bool empty = app_id == 0 && version == 0 && objects == 0;
        if (!empty) {
            fail(StoreErrc::not_a_study, path,
                 fmt::format("{} is an SQLite database but not an atonlab study file (application_id {}, "
                             "{} schema objects); it was not changed",
                             str(path), app_id, objects));
        }
        if (access == Access::read_only) {
            fail(StoreErrc::not_a_study, path,
                 fmt::format("{} is an empty database, not yet an atonlab study file", str(path)));
        }
    }
    if (version > latest) {
        fail(StoreErrc::newer_schema, path,
             fmt::format("{} was written by a newer atonlab (schema version {}, this build knows up to {}); "
                         "it was not changed, open it with a newer atonlab",
                         str(path), version, latest));
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
    const std::string mode = db->query_text("PRAGMA journal_mode = WAL", "switch to the WAL journal");
    if (mode != "wal") {
        fail(StoreErrc::other, path,
             fmt::format("{}: cannot switch to the WAL journal (SQLite kept \"{}\"; WAL needs a local file "
                         "system that supports shared memory)",
                         str(path), mode));
    }
    db->exec("PRAGMA synchronous = FULL", "set synchronous = FULL");
    if (options.max_size_bytes > 0) {
        const std::int64_t page = db->query_int("PRAGMA page_size", "read the page size");
        db->exec(pragma("max_page_count", std::max<std::int64_t>(1, options.max_size_bytes / page)).c_str(),
                 "limit the file size");
    }
    migrate(*db, steps);
    return db;
}

void migrate_file(const fs::path& path, std::span<const Migration> steps) {
    open_study(path, Access::create_or_open, StoreOptions{}, steps);
}

}  // namespace atonlab::store::detail
