// The file's schema against the one atonlab's migrations make (schema_check.h).
#include "schema_check.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <memory>
#include <mutex>
#include <tuple>
#include <utility>

#include "constraints.h"

namespace atonlab::store::detail {
namespace {

const char* article(std::string_view type) {
    return type == "index" ? "an" : "a";
}

// A text from the schema shortened for a sentence.
std::string quoted(std::string_view text) {
    constexpr std::size_t kShown = 80;
    if (text.size() <= kShown) return fmt::format("\"{}\"", text);
    return fmt::format("\"{}...\"", text.substr(0, kShown - 3));
}

// The database the first `version` steps make, in memory.
std::unique_ptr<sql::Connection> reference_db(std::span<const Migration> steps, int version) {
    auto db =
        std::make_unique<sql::Connection>(":memory:", SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_MEMORY);
    for (const Migration& step : steps) {
        if (step.to_version > version) break;
        const std::string text(step.sql);
        db->exec(text.c_str(), fmt::format("make the reference schema of version {}", step.to_version));
    }
    return db;
}

// One column as pragma_table_info lists it.
using Column = std::tuple<std::string, std::string, std::int64_t, std::optional<std::string>, std::int64_t>;

std::vector<Column> columns_of(sql::Connection& db, const std::string& table) {
    sql::Statement s(db, "SELECT name, type, \"notnull\", dflt_value, pk FROM pragma_table_info(?1)");
    s.bind(1, std::string_view(table));
    std::vector<Column> out;
    while (s.step("list the table's columns"))
        out.emplace_back(s.text(0), s.text(1), s.int64(2), s.optional_text(3), s.int64(4));
    return out;
}

std::vector<std::string> foreign_keys_of(sql::Connection& db, const std::string& table) {
    sql::Statement s(db,
                     "SELECT \"table\" || '(' || coalesce(\"to\", '') || ') from ' || \"from\" || ' on update ' || "
                     "on_update || ' on delete ' || on_delete FROM pragma_foreign_key_list(?1) ORDER BY id, seq");
    s.bind(1, std::string_view(table));
    std::vector<std::string> out;
    while (s.step("list the table's foreign keys")) out.push_back(s.text(0));
    return out;
}

const Column* find_column(const std::vector<Column>& columns, const std::string& name) {
    for (const Column& c : columns)
        if (std::get<0>(c) == name) return &c;
    return nullptr;
}

// What differs between two column lists, or "" when nothing does.
std::string column_difference(const std::string& table, const std::vector<Column>& ref,
                              const std::vector<Column>& file) {
    for (const Column& f : file)
        if (!find_column(ref, std::get<0>(f)))
            return fmt::format("column {} was added to table {}", std::get<0>(f), table);
    for (const Column& r : ref) {
        const Column* f = find_column(file, std::get<0>(r));
        if (!f) return fmt::format("column {} of table {} is missing", std::get<0>(r), table);
        const char* what = std::get<1>(*f) != std::get<1>(r)   ? "its type"
                           : std::get<2>(*f) != std::get<2>(r) ? "its NOT NULL"
                           : std::get<3>(*f) != std::get<3>(r) ? "its default"
                           : std::get<4>(*f) != std::get<4>(r) ? "its PRIMARY KEY"
                                                               : nullptr;
        if (what) return fmt::format("column {} of table {} differs ({})", std::get<0>(r), table, what);
    }
    if (ref != file) return fmt::format("the columns of table {} are in another order", table);
    return {};
}

// What differs between the CHECK clauses of two CREATE TABLE texts, or "".
std::string check_difference(const std::string& table, const std::string& ref_sql, const std::string& file_sql) {
    const std::vector<std::string> ref = check_clauses(ref_sql);
    const std::vector<std::string> file = check_clauses(file_sql);
    for (const std::string& r : ref) {
        if (std::find(file.begin(), file.end(), r) != file.end()) continue;
        if (file.size() < ref.size()) return fmt::format("the CHECK ({}) of table {} was removed", r, table);
        // The file's clause in the same place, to say what replaced it.
        const auto at = static_cast<std::size_t>(std::find(ref.begin(), ref.end(), r) - ref.begin());
        const std::string instead = at < file.size() ? file[at] : file.back();
        return fmt::format("the CHECK ({}) of table {} differs: the file has CHECK ({})", r, table, instead);
    }
    for (const std::string& f : file)
        if (std::find(ref.begin(), ref.end(), f) == ref.end())
            return fmt::format("a CHECK ({}) was added to table {}", f, table);
    if (ref != file) return fmt::format("the CHECK constraints of table {} are in another order", table);
    return {};
}

// Where two normalised texts first differ, as a short quote of each.
std::string text_difference(const std::string& ref, const std::string& file) {
    std::size_t at =
        static_cast<std::size_t>(std::mismatch(ref.begin(), ref.end(), file.begin(), file.end()).first - ref.begin());
    at = at > 20 ? at - 20 : 0;  // a little context before it
    return fmt::format("the file has {} where atonlab's has {}", quoted(std::string_view(file).substr(at)),
                       quoted(std::string_view(ref).substr(at)));
}

// What differs in a table whose CREATE TABLE text is not atonlab's.
std::string table_difference(sql::Connection& db, const SchemaObject& ref, const SchemaObject& file,
                             std::span<const Migration> steps, int version) {
    const std::unique_ptr<sql::Connection> reference = reference_db(steps, version);
    if (std::string why = column_difference(ref.name, columns_of(*reference, ref.name), columns_of(db, ref.name));
        !why.empty())
        return why;
    if (std::string why = check_difference(ref.name, ref.sql, file.sql); !why.empty()) return why;
    if (foreign_keys_of(*reference, ref.name) != foreign_keys_of(db, ref.name))
        return fmt::format("the foreign keys (REFERENCES) of table {} differ", ref.name);
    return fmt::format("the definition of table {} differs ({})", ref.name, text_difference(ref.sql, file.sql));
}

const SchemaObject* find_object(const std::vector<SchemaObject>& schema, const std::string& name) {
    for (const SchemaObject& o : schema)
        if (o.name == name) return &o;
    return nullptr;
}

}  // namespace

std::string normalise_sql(std::string_view sql) {
    std::string out;
    bool space = false;
    for (std::size_t i = 0; i < sql.size();) {
        const bool comment = sql.substr(i, 2) == "--" || sql.substr(i, 2) == "/*";
        if (comment || std::isspace(static_cast<unsigned char>(sql[i])) != 0) {
            space = true;
            i = comment ? skip_quoted(sql, i) : i + 1;
            continue;
        }
        if (space && !out.empty()) out += ' ';
        space = false;
        // A string literal or quoted identifier is kept as it is, white space and all.
        const std::size_t past = std::max(skip_quoted(sql, i), i + 1);
        out.append(sql.substr(i, past - i));
        i = past;
    }
    return out;
}

std::vector<SchemaObject> read_schema(sql::Connection& db) {
    sql::Statement s(db,
                     "SELECT type, name, tbl_name, sql FROM sqlite_schema WHERE name NOT LIKE 'sqlite\\_stat%' "
                     "ESCAPE '\\' ORDER BY rowid");
    std::vector<SchemaObject> out;
    while (s.step("read the file's schema"))
        out.push_back({s.text(0), s.text(1), s.text(2), s.is_null(3) ? std::string() : normalise_sql(s.text(3))});
    return out;
}

const std::vector<SchemaObject>& reference_schema(std::span<const Migration> steps, int version) {
    // Per migration list (the study's, the display-profile file's, a test's)
    // and version; std::map keeps each entry where it is while others are added.
    static std::mutex mutex;
    static std::map<std::pair<const Migration*, int>, std::vector<SchemaObject>> cache;
    const std::lock_guard<std::mutex> lock(mutex);
    const auto key = std::make_pair(steps.data(), version);
    auto it = cache.find(key);
    if (it == cache.end()) it = cache.emplace(key, read_schema(*reference_db(steps, version))).first;
    return it->second;
}

std::optional<std::string> reference_table_sql(std::span<const Migration> steps, int version,
                                               std::string_view table) {
    for (const SchemaObject& o : reference_schema(steps, version))
        if (o.type == "table" && o.name == table) return o.sql;
    return std::nullopt;
}

std::optional<std::string> first_schema_difference(sql::Connection& db, const std::vector<SchemaObject>& file_schema,
                                                   std::span<const Migration> steps, int version) {
    const std::vector<SchemaObject>& ref = reference_schema(steps, version);
    for (const SchemaObject& r : ref) {
        const SchemaObject* f = find_object(file_schema, r.name);
        if (!f) return fmt::format("{} {} {} is missing", article(r.type), r.type, r.name);
        if (f->type != r.type)
            return fmt::format("{} is {} {} in the file, {} {} in atonlab's schema", r.name, article(f->type), f->type,
                               article(r.type), r.type);
        if (f->tbl_name != r.tbl_name)
            return fmt::format("{} {} is on table {}, not {}", r.type, r.name, f->tbl_name, r.tbl_name);
        if (f->sql == r.sql) continue;
        if (r.type == "table") return table_difference(db, r, *f, steps, version);
        return fmt::format("{} {} differs ({})", r.type, r.name, text_difference(r.sql, f->sql));
    }
    for (const SchemaObject& f : file_schema)
        if (!find_object(ref, f.name)) return fmt::format("{} {} {} was added", article(f.type), f.type, f.name);
    return std::nullopt;
}

}  // namespace atonlab::store::detail
