#pragma once
// The study file's schema as an ordered list of migrations (PRAGMA user_version
// counts the ones applied). The SQL itself lives in store/src/schema.cpp; the
// display-profile file's, in store/src/profile_schema.cpp.
#include <filesystem>
#include <span>
#include <string_view>

namespace atonlab::store {

/// One step of the schema's history: the SQL that takes a file from
/// `to_version - 1` to `to_version`. Steps are DDL (and, for later steps, data
/// rewrites) with no values from outside the program, so they are run as scripts.
struct Migration {
    int to_version = 0;
    std::string_view description;
    std::string_view sql;
};

/// The store's own migrations, in order, to_version 1, 2, ...
std::span<const Migration> schema_migrations() noexcept;

/// The schema version this code writes: the last migration's to_version.
int schema_version() noexcept;

/// PRAGMA application_id of every atonlab study file: 'ATON' as a big-endian int.
inline constexpr int application_id = 0x41544F4E;

/// The display-profile file's migrations (profiles.h; SQL in
/// store/src/profile_schema.cpp), in order, to_version 1, 2, ...
std::span<const Migration> profile_migrations() noexcept;

/// The display-profile schema version this code writes.
int profile_schema_version() noexcept;

/// PRAGMA application_id of every display-profile file: 'ATPF' as a big-endian int.
inline constexpr int profile_application_id = 0x41545046;

namespace detail {
/// Opens `path` (creating it if missing) and applies `steps` above the file's
/// user_version in one IMMEDIATE transaction: all of them or none. Throws
/// StoreError on a newer file or a failing step (the file is left as it was).
/// Store::create_or_open does this with schema_migrations(); tests call it
/// directly with their own lists to check the engine.
void migrate_file(const std::filesystem::path& path, std::span<const Migration> steps);
}  // namespace detail

}  // namespace atonlab::store
