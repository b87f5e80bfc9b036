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

/// A procedure's level as read_study takes it (and trials.csv writes it),
/// without the noise of decimal steps summed in binary (-0.1 - 0.2 is
/// -0.30000000000000004; -0.1 - 0.2 + 0.2 is -0.09999999999999998): the
/// decimal with the fewest significant digits whose double lies within 1e-12
/// of the level (log10 units; for a linear level, 1e-12 of its value), as the
/// double nearest that decimal. The fits group levels on a far coarser grid (1e-9).
double level_value(double v, bool log10_scale);

}  // namespace atonlab::analysis::detail
