#pragma once
// The schema's CHECK and NOT NULL constraints evaluated over the rows a file
// holds, on any connection (docs/store.md, "Opening"). SQLite's
// integrity_check evaluates CHECK constraints only on a connection that may
// write: a read-only connection does not even parse them when it loads the
// schema (measured with SQLite 3.40.1, Debian 12: a trial whose stimulus_json
// was overwritten inside its record gives "CHECK constraint failed in trials"
// read-write and "ok" read-only). This is the one check both kinds of
// connection run, so `analyze` sees what `run` sees.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sqlite.h"

namespace atonlab::store::detail {

/// One row that breaks one of its table's constraints.
struct ConstraintViolation {
    std::string table;
    std::int64_t row_id = 0;
    std::string constraint;  ///< "CHECK (json_valid(stimulus_json))", "NOT NULL (level)", or kLengthLimit's
};

/// Where the string literal, quoted identifier or comment starting at `i` of
/// `sql` ends (one past it), or `i` when none starts there.
std::size_t skip_quoted(std::string_view sql, std::size_t i);

/// The bodies of the CHECK clauses of one CREATE TABLE statement, in order,
/// each without its outer parentheses ("json_valid(stimulus_json)"). String
/// literals, quoted identifiers and comments are skipped, so a column named
/// "checked" or a comment saying CHECK is not taken for one.
std::vector<std::string> check_clauses(std::string_view create_table_sql);

/// How TableConstraints::names starts for a value longer than the
/// connection's limit on one text or blob (sqlite.h, limit_to_atonlab).
inline constexpr std::string_view kLengthLimit = "the length limit on one value";

/// One table's constraints as SQL over one of its rows: `which` is an
/// expression whose value is the index in `names` of the first constraint
/// the row breaks, NULL when it breaks none ("NULL" for a table without
/// constraints). The table's columns are named unqualified.
struct TableConstraints {
    std::string which;
    std::vector<std::string> names;  ///< "CHECK (json_valid(stimulus_json))", "NOT NULL (level)"
};
/// `create_table_sql`: the CHECK clauses from this text instead of the
/// file's own (salvage judges an altered file's rows by atonlab's).
TableConstraints table_constraints(sql::Connection& db, const std::string& table,
                                   std::optional<std::string_view> create_table_sql = std::nullopt);

/// The rows of every table of the file (sqlite_schema, not sqlite_*) that
/// break a CHECK or NOT NULL constraint of the schema the file itself holds,
/// table by table, at most `limit` of them (0: all). One scan per table. The
/// expressions are the file's own, as a writer would evaluate them (a CHECK
/// fails when its value cast to NUMERIC is 0; NULL passes).
std::vector<ConstraintViolation> find_constraint_violations(sql::Connection& db, std::size_t limit);

/// "row 3 of trials breaks CHECK (json_valid(stimulus_json))"; for several,
/// the first three so, then "and more".
std::string describe(const std::vector<ConstraintViolation>& found);

}  // namespace atonlab::store::detail
