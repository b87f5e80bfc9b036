// Conditions files (CSV): each row one [[block.condition]] of its block
// (protocol_reader.h; docs/protocol-file.md "Conditions files").
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "atonlab/common/input_text.h"
#include "atonlab/common/toml_text.h"
#include "atonlab/common/toml_value.h"
#include "protocol_reader.h"
#include "protocol_schema.h"

namespace atonlab::protocols::detail {

namespace {

std::string_view trim_blanks(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
    return s;
}

std::string toml_string(std::string_view text) {
    std::string q = "\"";
    for (const char ch : text) {
        if (ch == '"' || ch == '\\') q += '\\';
        q += ch;
    }
    return q + "\"";
}

/// A CSV cell as TOML: the text itself when it is one TOML value (a number,
/// true / false, an array), else a TOML string of it.
std::string toml_value(const std::string& cell, bool always_string) {
    if (!always_string && TomlValue::parse(cell)) return cell;
    return toml_string(cell);
}

/// One CSV line split into fields (RFC 4180 quoting; a field may not span lines).
std::optional<std::vector<std::string>> csv_fields(std::string_view line, std::string& error) {
    std::vector<std::string> out;
    std::string field;
    bool quoted = false, was_quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
        const char ch = line[i];
        if (quoted) {
            if (ch == '"' && i + 1 < line.size() && line[i + 1] == '"') {
                field += '"';
                ++i;
            } else if (ch == '"') {
                quoted = false;
            } else {
                field += ch;
            }
        } else if (ch == '"' && field.empty() && !was_quoted) {
            quoted = was_quoted = true;
        } else if (ch == ',') {
            out.push_back(was_quoted ? field : std::string(trim_blanks(field)));
            field.clear();
            was_quoted = false;
        } else {
            field += ch;
        }
    }
    if (quoted) {
        error = "a quoted field is not closed on its line (a field may not span lines).";
        return std::nullopt;
    }
    out.push_back(was_quoted ? field : std::string(trim_blanks(field)));
    return out;
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
    std::vector<std::string> lines;
    for (std::size_t at = 0; at <= read.text.size();) {
        const std::size_t end = std::min(read.text.find('\n', at), read.text.size());
        lines.push_back(read.text.substr(at, end - at));
        at = end + 1;
    }
    if (!lines.empty() && lines.front().rfind("\xEF\xBB\xBF", 0) == 0) lines.front().erase(0, 3);
    std::string error;
    const auto header = csv_fields(lines.empty() ? std::string_view() : std::string_view(lines.front()), error);
    if (!header || header->empty() || (header->size() == 1 && header->front().empty()))
        throw InputError(SourceLocation{file, 1, 0, ""},
                         error.empty() ? "the conditions file has no header row." : error);
    const std::vector<Kind> kinds = column_kinds(file, *header);
    // One TOML line per CSV line: row N of the file is line N of the text.
    std::string toml_text = "\n";
    std::vector<std::pair<std::string, Document::CsvRow>> rows;
    const std::string block_name = bt.get("name") && bt.get("name")->is_string()
                                       ? *bt.get("name")->value<std::string>()
                                       : fmt::format("block{}", bi);
    for (std::size_t li = 1; li < lines.size(); ++li) {
        const int line = static_cast<int>(li) + 1;
        if (trim_blanks(lines[li]).empty()) {
            toml_text += "\n";
            continue;
        }
        const auto cells = csv_fields(lines[li], error);
        if (!cells) throw InputError(SourceLocation{file, line, 0, ""}, error);
        if (cells->size() != header->size())
            throw InputError(SourceLocation{file, line, 0, ""},
                fmt::format("the row has {} fields where the header has {}.", cells->size(), header->size()));
        Document::CsvRow row;
        row.file = file;
        row.line = line;
        std::string fields, procedure;
        std::vector<std::string> set, test_set, reference_set;
        bool take = true;
        for (std::size_t c = 0; c < cells->size(); ++c) {
            const std::string& cell = (*cells)[c];
            const std::string& h = (*header)[c];
            const int col = static_cast<int>(c) + 1;
            if (cell.empty()) continue;  // not given for this row
            row.columns.emplace_back(h, col);
            switch (kinds[c]) {
                case Kind::block:
                    take = cell == block_name;
                    break;
                case Kind::name:
                case Kind::string_key:
                    fields += fmt::format("{} = {}, ", h, toml_string(cell));
                    break;
                case Kind::other_key:
                    fields += fmt::format("{} = {}, ", h, toml_value(cell, false));
                    break;
                case Kind::procedure:
                    procedure += fmt::format("{}{} = {}", procedure.empty() ? "" : ", ", h.substr(10),
                                             toml_value(cell, false));
                    break;
                case Kind::set:
                    set.push_back(toml_string(h + "=" + toml_value(cell, false)));
                    row.set.push_back(col);
                    break;
                case Kind::test_set:
                    test_set.push_back(toml_string(h.substr(5) + "=" + toml_value(cell, false)));
                    row.test_set.push_back(col);
                    break;
                case Kind::reference_set:
                    reference_set.push_back(toml_string(h.substr(10) + "=" + toml_value(cell, false)));
                    row.reference_set.push_back(col);
                    break;
            }
        }
        if (!take) {
            toml_text += "\n";
            continue;
        }
        auto list = [](const std::vector<std::string>& v) {
            std::string out = "[";
            for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + v[i];
            return out + "]";
        };
        if (!set.empty()) fields += "set = " + list(set) + ", ";
        if (!test_set.empty()) fields += "test_set = " + list(test_set) + ", ";
        if (!reference_set.empty()) fields += "reference_set = " + list(reference_set) + ", ";
        if (!procedure.empty()) fields += "procedure = { " + procedure + " }, ";
        if (fields.size() >= 2) fields.resize(fields.size() - 2);
        const std::string row_key = fmt::format("row{}", line);
        toml_text += fmt::format("{} = {{ {} }}\n", row_key, fields);
        rows.emplace_back(row_key, std::move(row));
    }
    toml::table parsed;
    try {
        parsed = toml::parse(toml_text, file);
    } catch (const toml::parse_error& e) {
        throw InputError(SourceLocation{file, static_cast<int>(e.source().begin.line), 0, ""},
            fmt::format("a cell is not a TOML value: {}.", strip_period(std::string(e.description()))));
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
    for (auto& [row_key, row] : rows) {
        toml::node* t = parsed.get(row_key);
        if (t == nullptr || !t->is_table()) continue;
        doc.add_csv_row(fmt::format("block[{}].condition[{}]", bi, carr.size()), std::move(row));
        carr.push_back(std::move(*t->as_table()));
    }
}

}  // namespace atonlab::protocols::detail
