#include "csv.h"

#include <fmt/format.h>

#include <charconv>
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

double level_value(double v, bool log10_scale) {
    if (!std::isfinite(v)) return v;
    const double tolerance = log10_scale ? 1e-12 : 1e-12 * std::abs(v);
    if (std::abs(v) <= tolerance) return 0.0;  // 0.3 - 0.1 - 0.2 is -2.8e-17
    for (int digits = 1; digits < 17; ++digits) {
        const std::string decimal = fmt::format("{:.{}g}", v, digits);
        double d = 0.0;
        const auto [ptr, ec] = std::from_chars(decimal.data(), decimal.data() + decimal.size(), d);
        if (ec == std::errc() && ptr == decimal.data() + decimal.size() && std::abs(d - v) <= tolerance) return d;
    }
    return v;  // 17 significant digits: the level itself
}

}  // namespace atonlab::analysis::detail
