#pragma once
// StoreError: every failure of the study store, as one sentence that names the
// study file, what was being done and SQLite's own message, plus a kind that a
// caller can act on (stop the session cleanly on disk_full, tell the user to run
// a newer atonlab on newer_schema, ...). See docs/store.md, "Errors".
#include <filesystem>
#include <stdexcept>
#include <string>

namespace atonlab::store {

enum class StoreErrc {
    cannot_open,       ///< the file or its directory cannot be opened or created
    not_a_database,    ///< the file exists but is not an SQLite database
    not_a_study,       ///< an SQLite database, but not one written by atonlab
    newer_schema,      ///< written by a newer atonlab (user_version above schema_version()); left untouched
    older_schema,      ///< needs a migration, but was opened read-only
    schema_altered,    ///< its tables, indexes, triggers or views are not the ones atonlab's migrations make; left untouched
    read_only,         ///< opened for writing, but the file (or its directory) is write-protected
    disk_full,         ///< SQLITE_FULL: the disk, or the configured size limit, is full
    io_error,          ///< SQLITE_IOERR: the operating system refused a read or write
    busy,              ///< another connection held a lock past the busy timeout
    corrupt,           ///< SQLITE_CORRUPT: the file is damaged
    constraint,        ///< a schema constraint rejected the row (a bug, or a value the store does not validate)
    invalid_argument,  ///< a value handed to the store is wrong (checked before anything is written)
    not_found,         ///< a session, calibration or snapshot that is not in the file
    other,
};

/// What a StoreErrc is called in messages and docs ("disk_full").
const char* to_string(StoreErrc kind) noexcept;

class StoreError : public std::runtime_error {
public:
    /// `message` is the full sentence (what() returns it unchanged).
    StoreError(StoreErrc kind, std::filesystem::path file, const std::string& message, int sqlite_code = 0);

    StoreErrc kind() const noexcept { return kind_; }
    const std::filesystem::path& file() const noexcept { return file_; }
    /// SQLite's extended result code, or 0 when the error did not come from SQLite.
    int sqlite_code() const noexcept { return sqlite_code_; }

private:
    StoreErrc kind_;
    std::filesystem::path file_;
    int sqlite_code_;
};

}  // namespace atonlab::store
