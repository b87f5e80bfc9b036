#pragma once
// RFC 4180 CSV: fields separated by commas, a field with a comma, quote or
// line break in double quotes, a quote inside doubled. Reading keeps the line
// number of each record for messages.
#include <istream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace atonlab::analysis::detail {

struct CsvRecord {
    int line = 0;  ///< 1-based line where the record starts
    std::vector<std::string> fields;
};

/// Reads the next record; std::nullopt at the end. A quote left open at the
/// end of the input is reported through `error` (the record is then absent).
std::optional<CsvRecord> read_csv_record(std::istream& in, int& line, std::string& error);

/// The field, quoted when it must be.
std::string csv_field(std::string_view text);

/// Shortest text that reads back as the same double (JSON/CSV numbers).
std::string number_text(double v);

}  // namespace atonlab::analysis::detail
