#pragma once
// The file's schema compared with the schema atonlab's own migrations make for
// the file's user_version (docs/store.md, "Opening", step 3). A table, column,
// constraint, index, trigger or view that a user changed by hand (an SQLite
// browser, PRAGMA writable_schema) would hold the file's rows to rules atonlab
// did not write, so such a file is refused before anything reads or writes it.
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/store/schema.h"
#include "sqlite.h"

namespace atonlab::store::detail {

/// One row of sqlite_schema, its SQL normalised (normalise_sql); sql is empty
/// for an object SQLite makes itself (sqlite_autoindex_…).
struct SchemaObject {
    std::string type;  ///< "table", "index", "trigger", "view"
    std::string name;
    std::string tbl_name;
    std::string sql;
};

/// `sql` with its comments removed and every run of white space (comments
/// included) made one space, outside string literals and quoted identifiers;
/// no space at either end. SQLite stores a CREATE statement's text as it was
/// written, so this is the text up to layout: two statements that normalise
/// alike have the same tokens in the same order.
std::string normalise_sql(std::string_view sql);

/// Every row of the connection's sqlite_schema but SQLite's statistics tables
/// (sqlite_stat1, sqlite_stat4: ANALYZE's, which only guide the query planner),
/// in the order SQLite lists them. Call inside a read transaction, so that it
/// matches the user_version read with it.
std::vector<SchemaObject> read_schema(sql::Connection& db);

/// The schema the first `version` steps of `steps` make in a new, empty
/// database: made once per list and version in an in-memory database and kept.
const std::vector<SchemaObject>& reference_schema(std::span<const Migration> steps, int version);

/// The CREATE TABLE text (normalised) of `table` in reference_schema(steps,
/// version), or nullopt when that schema has no such table.
std::optional<std::string> reference_table_sql(std::span<const Migration> steps, int version,
                                               std::string_view table);

/// The first way `file_schema` (read_schema of `db`) differs from the
/// reference for `version`, as a clause ("the CHECK (…) of table observers was
/// removed", "column y was added to table trials", "an index sessions_by_observer
/// is missing", "a trigger x was added"), or nullopt when they are the same.
/// `db` is read again only to say what differs in a table.
std::optional<std::string> first_schema_difference(sql::Connection& db, const std::vector<SchemaObject>& file_schema,
                                                   std::span<const Migration> steps, int version);

}  // namespace atonlab::store::detail
