// Conditions files (CSV): each row one [[block.condition]] of its block
// (protocol_reader.h; docs/protocol-file.md "Conditions files").
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "atonlab/common/csv.h"
#include "atonlab/common/input_text.h"
#include "atonlab/common/toml_text.h"
#include "atonlab/common/toml_value.h"
#include "protocol_reader.h"
#include "protocol_schema.h"

namespace atonlab::protocols::detail {

namespace {

/// A CSV cell as a value: the TOML value it is (a number, true / false, an
/// array), else the text as a string (toml_value.h: the one reading of a value's text).
TomlValue cell_value(const std::string& cell, const std::string& file) {
    if (auto v = TomlValue::parse(cell, nullptr, file)) return *v;
    if (auto v = TomlValue::string(cell, nullptr, file)) return *v;
    return TomlValue::of(std::string_view(cell));
}

/// The cell as an override's value text ("key=VALUE", the stored form of a
/// `set` line): the cell when it is one TOML value, else it quoted as a TOML string.
std::string override_text(const std::string& key, const std::string& cell) {
    return key + "=" + (TomlValue::parse(cell) ? cell : TomlValue::quoted(cell));
}

/// t[key] = a copy of the value's node.
void insert_value(toml::table& t, std::string_view key, const TomlValue& v) {
    v.node().visit([&](const auto& node) { t.insert_or_assign(key, node); });
}

/// The CSV text stored after "#@conditions_file NAME" in the protocol text, if any.
std::optional<std::string> embedded_csv(std::string_view text_, const std::string& name) {
    const std::string tag = "\n#@conditions_file " + name + "\n";
    std::size_t at = text_.find(tag);
    if (at == std::string::npos) return std::nullopt;
    at += tag.size();
    std::string out;
    while (at < text_.size() && text_.compare(at, 3, "#@|") == 0) {
        const std::size_t end = std::min(text_.find('\n', at), text_.size());
        out += std::string(text_.substr(at + 3, end - at - 3)) + "\n";
        at = end + 1;
    }
    return out;
}

/// What a column of a conditions file gives.
enum class Kind { name, block, string_key, other_key, procedure, set, test_set, reference_set };
constexpr std::string_view kStringKeys[] = {"task",      "presentation", "prompt",
                                            "level_key", "level_scale",  "level_on",
                                            "choice",    "test_light",   "reference_light"};

/// What each column of a conditions file's header is (its line 1).
std::vector<Kind> column_kinds(const std::string& file, const std::vector<std::string>& header) {
    std::vector<Kind> kinds;
    std::set<std::string> seen;
    for (std::size_t c = 0; c < header.size(); ++c) {
        const std::string& h = header[c];
        const int col = static_cast<int>(c) + 1;
        auto fail = [&](const std::string& m) {
            throw InputError(SourceLocation{file, 1, col, ""}, fmt::format("column {} '{}': {}", col, h, m));
        };
        if (h.empty()) fail("the column has no name.");
        if (!seen.insert(h).second) fail("the column appears twice in the header.");
        if (h == "name")
            kinds.push_back(Kind::name);
        else if (h == "block")
            kinds.push_back(Kind::block);
        else if (std::find(std::begin(kStringKeys), std::end(kStringKeys), h) != std::end(kStringKeys))
            kinds.push_back(Kind::string_key);
        else if (h == "left_position_m" || h == "right_position_m")
            kinds.push_back(Kind::other_key);
        else if (h.rfind("procedure.", 0) == 0 && h.size() > 10)
            kinds.push_back(Kind::procedure);
        else if (h.rfind("test:", 0) == 0 && h.find('.') != std::string::npos)
            kinds.push_back(Kind::test_set);
        else if (h.rfind("reference:", 0) == 0 && h.find('.') != std::string::npos)
            kinds.push_back(Kind::reference_set);
        else if (h.find('.') != std::string::npos && h.find_first_of(" =\"'") == std::string::npos)
            kinds.push_back(Kind::set);
        else
            fail(
                fmt::format("not a column of a conditions file: give name, a condition key ({}, "
                            "left_position_m, right_position_m), procedure.PARAMETER, a scene key "
                            "(section.key, a `set` override), test:KEY or reference:KEY (test_set, "
                            "reference_set), or block.{}",
                            toml_reader::join_quoted(kStringKeys), text::did_you_mean(h, kStringKeys)));
    }
    return kinds;
}

}  // namespace

void expand_conditions_file(Document& doc, std::string_view protocol_text, toml::table& bt, std::size_t bi,
                             const toml::node& f) {
    const std::string key = fmt::format("block[{}].conditions_file", bi);
    const std::string rel = doc.string(&f, key);
    if (rel.empty()) doc.fail(&f, key, "conditions_file must name a CSV file, got an empty string.");
    const std::filesystem::path csv = std::filesystem::path(rel).is_absolute()
                                          ? std::filesystem::path(rel)
                                          : std::filesystem::path(doc.file()).parent_path() / rel;
    text::FileText read = text::read_text_file(csv);
    std::string file = csv.string();
    if (!read.ok()) {
        // A stored protocol text carries its conditions files (with_conditions_files).
        if (auto embedded = embedded_csv(protocol_text, rel)) {
            read.text = std::move(*embedded);
            read.error.clear();
            file = rel;
        } else {
            doc.fail(&f, key,
                      fmt::format("cannot read the conditions file \"{}\": {}.", csv.string(), read.error));
        }
    }
    // One reader of CSV (common/csv.h): RFC 4180, blanks around a cell trimmed.
    CsvReader reader(read.text, file, CsvOptions{.trim = true});
    const auto header_record = reader.next();
    const std::vector<std::string> header = header_record ? header_record->texts() : std::vector<std::string>();
    if (header.empty() || (header.size() == 1 && header.front().empty()))
        throw InputError(SourceLocation{file, 1, 0, ""}, "the conditions file has no header row.");
    const std::vector<Kind> kinds = column_kinds(file, header);
    // Each row's condition, built as a table from its cells' values (no TOML text is made of them).
    std::vector<std::pair<toml::table, Document::CsvRow>> rows;
    const std::string block_name = bt.get("name") && bt.get("name")->is_string()
                                       ? *bt.get("name")->value<std::string>()
                                       : fmt::format("block{}", bi);
    while (const auto record = reader.next()) {
        if (record->blank()) continue;
        const int line = record->line;
        const std::vector<CsvField>& cells = record->fields;
        if (cells.size() != header.size())
            throw InputError(
                SourceLocation{file, line, 0, ""},
                fmt::format("the row has {} fields where the header has {}.", cells.size(), header.size()));
        Document::CsvRow row;
        row.file = file;
        row.line = line;
        toml::table condition, procedure;
        toml::array set, test_set, reference_set;
        bool take = true;
        for (std::size_t c = 0; c < cells.size(); ++c) {
            const std::string& cell = cells[c].text;
            const std::string& h = header[c];
            const int col = static_cast<int>(c) + 1;
            if (cell.empty()) continue;  // not given for this row
            row.columns.emplace_back(h, col);
            switch (kinds[c]) {
                case Kind::block:
                    take = cell == block_name;
                    break;
                case Kind::name:
                case Kind::string_key:
                    condition.insert_or_assign(h, cell);
                    break;
                case Kind::other_key:
                    insert_value(condition, h, cell_value(cell, file));
                    break;
                case Kind::procedure:
                    insert_value(procedure, std::string_view(h).substr(10), cell_value(cell, file));
                    break;
                case Kind::set:
                    set.push_back(override_text(h, cell));
                    row.set.push_back(col);
                    break;
                case Kind::test_set:
                    test_set.push_back(override_text(h.substr(5), cell));
                    row.test_set.push_back(col);
                    break;
                case Kind::reference_set:
                    reference_set.push_back(override_text(h.substr(10), cell));
                    row.reference_set.push_back(col);
                    break;
            }
        }
        if (!take) continue;
        if (!set.empty()) condition.insert_or_assign("set", std::move(set));
        if (!test_set.empty()) condition.insert_or_assign("test_set", std::move(test_set));
        if (!reference_set.empty()) condition.insert_or_assign("reference_set", std::move(reference_set));
        if (!procedure.empty()) condition.insert_or_assign("procedure", std::move(procedure));
        rows.emplace_back(std::move(condition), std::move(row));
    }
    if (rows.empty())
        doc.fail(&f, key,
                  fmt::format("the conditions file \"{}\" has no rows for block \"{}\" (one row per condition{}).",
                              file, block_name,
                              std::find(kinds.begin(), kinds.end(), Kind::block) != kinds.end()
                                  ? "; its block column names the block each row belongs to"
                                  : ""));
    if (!bt.contains("condition")) bt.insert("condition", toml::array{});
    toml::node* conds = bt.get("condition");
    if (!conds->is_array_of_tables() && !(conds->is_array() && conds->as_array()->empty()))
        return;  // reported where the block's conditions are read
    toml::array& carr = *conds->as_array();
    for (auto& [condition, row] : rows) {
        doc.add_csv_row(fmt::format("block[{}].condition[{}]", bi, carr.size()), std::move(row));
        carr.push_back(std::move(condition));
    }
}

}  // namespace atonlab::protocols::detail
