// The schema's CHECK and NOT NULL constraints evaluated over a file's rows
// (constraints.h).
#include "constraints.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <optional>

namespace atonlab::store::detail {
namespace {

bool word_char(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '$';
}

bool iequals(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i])))
            return false;
    return true;
}

// The text inside the parentheses that open at `open`, or nullopt when they
// never close (the file's schema text would then not have loaded at all).
std::optional<std::string_view> balanced(std::string_view s, std::size_t open) {
    int depth = 0;
    for (std::size_t i = open; i < s.size();) {
        if (const std::size_t past = skip_quoted(s, i); past != i) {
            i = past;
            continue;
        }
        if (s[i] == '(') ++depth;
        if (s[i] == ')' && --depth == 0) return s.substr(open + 1, i - open - 1);
        ++i;
    }
    return std::nullopt;
}

std::string sql_identifier(std::string_view identifier) {
    std::string out = "\"";
    for (const char c : identifier) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

// An expression's text on one line with its runs of white space as one
// space, for a message.
std::string one_line(std::string_view text) {
    std::string out;
    for (const char c : text) {
        const bool space = std::isspace(static_cast<unsigned char>(c)) != 0;
        if (space && (out.empty() || out.back() == ' ')) continue;
        out += space ? ' ' : c;
    }
    while (!out.empty() && out.back() == ' ') out.pop_back();
    return out;
}

}  // namespace

// SQLite's lexical rules
// (sqlite.org/lang_keywords.html, lang_comment.html): '…' and "…" and `…`
// with the quote doubled inside, […], -- to the end of the line, /* … */.
std::size_t skip_quoted(std::string_view s, std::size_t i) {
    const char c = s[i];
    if (c == '\'' || c == '"' || c == '`') {
        for (std::size_t j = i + 1; j < s.size(); ++j) {
            if (s[j] != c) continue;
            if (j + 1 < s.size() && s[j + 1] == c) {
                ++j;
                continue;
            }
            return j + 1;
        }
        return s.size();
    }
    if (c == '[') {
        const std::size_t end = s.find(']', i);
        return end == std::string_view::npos ? s.size() : end + 1;
    }
    if (s.substr(i, 2) == "--") {
        const std::size_t end = s.find('\n', i);
        return end == std::string_view::npos ? s.size() : end + 1;
    }
    if (s.substr(i, 2) == "/*") {
        const std::size_t end = s.find("*/", i + 2);
        return end == std::string_view::npos ? s.size() : end + 2;
    }
    return i;
}

std::vector<std::string> check_clauses(std::string_view sql) {
    std::vector<std::string> out;
    for (std::size_t i = 0; i < sql.size();) {
        if (const std::size_t past = skip_quoted(sql, i); past != i) {
            i = past;
            continue;
        }
        if (!word_char(sql[i])) {
            ++i;
            continue;
        }
        std::size_t end = i;
        while (end < sql.size() && word_char(sql[end])) ++end;
        const bool check = iequals(sql.substr(i, end - i), "CHECK");
        i = end;
        if (!check) continue;
        // White space and comments between CHECK and its "(".
        while (i < sql.size()) {
            const bool comment = sql.substr(i, 2) == "--" || sql.substr(i, 2) == "/*";
            if (comment) {
                i = skip_quoted(sql, i);
            } else if (std::isspace(static_cast<unsigned char>(sql[i])) != 0) {
                ++i;
            } else {
                break;
            }
        }
        if (i >= sql.size() || sql[i] != '(') continue;
        const auto body = balanced(sql, i);
        if (!body) break;
        out.emplace_back(*body);
        i += body->size() + 2;
    }
    return out;
}

TableConstraints table_constraints(sql::Connection& db, const std::string& table,
                                   std::optional<std::string_view> create_table_sql) {
    TableConstraints out;
    std::vector<std::string> breaks;  // for each constraint, an SQL condition true for a row that breaks it
    std::optional<std::string> create(create_table_sql);
    if (!create) {
        sql::Statement s(db, "SELECT sql FROM sqlite_schema WHERE type = 'table' AND name = ?1");
        s.bind(1, std::string_view(table));
        if (s.step("read the table's schema") && !s.is_null(0)) create = s.text(0);
    }
    // A CHECK fails when its value, cast to NUMERIC, is zero; NULL passes
    // (sqlite.org/lang_createtable.html, "CHECK constraints"). The body
    // keeps its own lines, so a -- comment inside it ends where it ended.
    if (create) {
        for (const std::string& body : check_clauses(*create)) {
            breaks.push_back(fmt::format("CAST((\n{}\n) AS NUMERIC) = 0", body));
            out.names.push_back(fmt::format("CHECK ({})", one_line(body)));
        }
    }
    sql::Statement columns(db, "SELECT name FROM pragma_table_info(?1) WHERE \"notnull\"");
    columns.bind(1, std::string_view(table));
    while (columns.step("list the NOT NULL columns")) {
        const std::string column = columns.text(0);
        breaks.push_back(fmt::format("{} IS NULL", sql_identifier(column)));
        out.names.push_back(fmt::format("NOT NULL ({})", column));
    }
    // Every value within the connection's length limit (sqlite.h,
    // limit_to_atonlab). A text longer than it fails to load (SQLITE_TOOBIG):
    // `c < ''` (never true) loads it without counting its characters, as
    // length() would, and SQLite cannot fold it away as it folds `IS NULL` on
    // a NOT NULL column. A blob's length is read from its record header
    // without loading it, so it is compared. typeof() loads nothing. A file
    // no longer than the limit cannot hold a longer value (its pages hold
    // every byte of every value), so the checks are left out for it: most
    // studies (docs/store.md, "Limits").
    const std::int64_t limit = db.max_value_bytes();
    const std::int64_t file_bytes = db.query_int("PRAGMA page_count", "read the file's size") *
                                    db.query_int("PRAGMA page_size", "read the file's size");
    sql::Statement all(db, "SELECT name FROM pragma_table_info(?1)");
    all.bind(1, std::string_view(table));
    while (file_bytes > limit && all.step("list the columns")) {
        const std::string column = all.text(0);
        breaks.push_back(fmt::format("CASE typeof({0}) WHEN 'blob' THEN length({0}) > {1} WHEN 'text' THEN {0} < '' "
                                     "ELSE 0 END",
                                     sql_identifier(column), limit));
        out.names.push_back(fmt::format("{} ({}: at most {} bytes)", kLengthLimit, column, limit));
    }
    if (breaks.empty()) {
        out.which = "NULL";
        return out;
    }
    out.which = "CASE";
    for (std::size_t k = 0; k < breaks.size(); ++k) out.which += fmt::format("\n WHEN {} THEN {}", breaks[k], k);
    out.which += "\n END";
    return out;
}

std::vector<ConstraintViolation> find_constraint_violations(sql::Connection& db, std::size_t limit) {
    std::vector<std::string> tables;
    {
        sql::Statement s(db,
                         "SELECT name FROM sqlite_schema WHERE type = 'table' AND name NOT LIKE 'sqlite\\_%' "
                         "ESCAPE '\\' ORDER BY rootpage");
        while (s.step("list the file's tables")) tables.push_back(s.text(0));
    }
    std::vector<ConstraintViolation> out;
    for (const std::string& table : tables) {
        const TableConstraints c = table_constraints(db, table);
        if (c.names.empty()) continue;
        // One scan of the table: each row's first broken constraint, by number.
        sql::Statement s(db, fmt::format("SELECT r, k FROM (SELECT rowid AS r, {} AS k FROM {}) WHERE k IS NOT NULL "
                                         "ORDER BY r",
                                         c.which, sql_identifier(table)));
        const std::string doing = fmt::format("check the constraints of the {} table", table);
        try {
            while (s.step(doing)) {
                out.push_back({table, s.int64(0), c.names.at(static_cast<std::size_t>(s.int64(1)))});
                if (limit != 0 && out.size() >= limit) return out;
            }
        } catch (const StoreError& e) {
            // A text or blob longer than the connection's limit, loaded by a
            // CHECK or NOT NULL: SQLite stops the scan at that row (row id 0:
            // which one is not known).
            if ((e.sqlite_code() & 0xff) != SQLITE_TOOBIG) throw;
            out.push_back({table, 0, fmt::format("{} (at most {} bytes)", kLengthLimit, db.max_value_bytes())});
            if (limit != 0 && out.size() >= limit) return out;
        }
    }
    return out;
}

std::string describe(const std::vector<ConstraintViolation>& found) {
    std::string out;
    const std::size_t shown = std::min<std::size_t>(found.size(), 3);
    for (std::size_t i = 0; i < shown; ++i) {
        const ConstraintViolation& v = found[i];
        out += v.row_id != 0 ? fmt::format("{}row {} of {} breaks {}", i == 0 ? "" : "; ", v.row_id, v.table,
                                           v.constraint)
                             : fmt::format("{}a row of {} breaks {}", i == 0 ? "" : "; ", v.table, v.constraint);
    }
    if (found.size() > shown) out += "; and more";
    return out;
}

}  // namespace atonlab::store::detail
