#pragma once
// Opening a study file: checks that name the problem before SQLite's generic
// "unable to open database file", the connection's pragmas, and the migration
// engine. Used by Store's factories and by detail::migrate_file.
#include <filesystem>
#include <memory>
#include <span>

#include "atonlab/store/schema.h"
#include "atonlab/store/store.h"
#include "sqlite.h"

namespace atonlab::store::detail {

enum class Access { create_or_open, open_existing, read_only };

/// The two kinds of atonlab SQLite file: a study (schema.h) and a lab's
/// display-profile file (profiles.h). Each has its own application_id and its
/// own migrations; one is refused where the other is expected.
enum class FileKind { study, profiles };

/// A connection to `path` with busy_timeout and foreign keys set, the file
/// checked to be an atonlab study no newer than `steps`, and, for writers,
/// WAL + synchronous=FULL and the schema migrated to `steps.back()`.
std::unique_ptr<sql::Connection> open_study(const std::filesystem::path& path, Access access,
                                            const StoreOptions& options, std::span<const Migration> steps);
/// As open_study, for either kind of file (messages name the kind).
std::unique_ptr<sql::Connection> open_file(const std::filesystem::path& path, Access access,
                                           const StoreOptions& options, std::span<const Migration> steps,
                                           FileKind kind);

}  // namespace atonlab::store::detail
