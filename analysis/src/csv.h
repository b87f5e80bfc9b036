#pragma once
// The analysis's numbers as its CSV files write them. Reading and quoting
// CSV is common/csv.h's (CsvReader, csv_field).
#include <string>

#include "atonlab/common/csv.h"

namespace atonlab::analysis::detail {

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
