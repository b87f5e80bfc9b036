#include "csv.h"

#include <fmt/format.h>

#include <cmath>

namespace atonlab::analysis::detail {

std::optional<CsvRecord> read_csv_record(std::istream& in, int& line, std::string& error) {
    CsvRecord rec;
    std::string field;
    bool quoted = false;      // inside a quoted field
    bool any = false;         // read at least one character of this record
    bool was_quoted = false;  // the current field began with a quote
    rec.line = line + 1;
    int c = 0;
    while ((c = in.get()) != EOF) {
        any = true;
        const char ch = static_cast<char>(c);
        if (quoted) {
            if (ch == '"') {
                if (in.peek() == '"') {
                    in.get();
                    field += '"';
                } else {
                    quoted = false;
                }
            } else {
                if (ch == '\n') ++line;
                field += ch;
            }
            continue;
        }
        if (ch == '"' && field.empty() && !was_quoted) {
            quoted = true;
            was_quoted = true;
        } else if (ch == ',') {
            rec.fields.push_back(std::move(field));
            field.clear();
            was_quoted = false;
        } else if (ch == '\n') {
            ++line;
            if (!field.empty() && field.back() == '\r' && !was_quoted) field.pop_back();
            rec.fields.push_back(std::move(field));
            return rec;
        } else {
            field += ch;
        }
    }
    if (quoted) {
        error = fmt::format("a quoted field that begins on line {} is never closed", rec.line);
        return std::nullopt;
    }
    if (!any) return std::nullopt;
    ++line;
    if (!field.empty() && field.back() == '\r' && !was_quoted) field.pop_back();
    rec.fields.push_back(std::move(field));
    return rec;
}

std::string csv_field(std::string_view text) {
    if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
    std::string out = "\"";
    for (const char ch : text) {
        if (ch == '"') out += '"';
        out += ch;
    }
    return out + '"';
}

std::string number_text(double v) {
    // fmt's "{}" is the shortest text that round-trips (Ryu / Dragonbox).
    return std::isfinite(v) ? fmt::format("{}", v) : std::string();
}

}  // namespace atonlab::analysis::detail
