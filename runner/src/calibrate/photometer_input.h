#pragma once
// Photometer readings for `atonlab calibrate measure|check`: from a readings
// file (scripted runs, meters that log) or typed by the operator
// (docs/calibration.md, "Readings").
#include <filesystem>
#include <glm/vec3.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "calibration_patches.h"

namespace atonlab::runner {

struct PhotometerReading {
    double luminance_cd_m2 = 0.0;         ///< Y, cd/m²
    std::optional<glm::dvec3> xyz_cd_m2;  ///< X, Y, Z (Y = luminance) when the meter gave all three
    std::optional<int> line;              ///< the readings file's line; none when typed
    /// From an instrument (--instrument): the standard uncertainty of the
    /// luminance, cd/m², and what the instrument said, raw (calibrate/instrument.h).
    std::optional<double> uncertainty_cd_m2;
    std::string transcript;
};

/// A readings file: one reading per patch, in the order the patches are shown
/// (`--list-patches`); `#` starts a comment, blank lines are skipped. A line is
/// `[PATCH] Y` or `[PATCH] X Y Z`, values in cd/m² (Y is the luminance), an
/// optional unit `cd/m2` at the end. A PATCH name, when given, must be the
/// patch's own. Throws InputError naming the file, the line and the column.
std::vector<PhotometerReading> read_readings_file(const std::filesystem::path& path, const std::vector<Patch>& patches);

/// What the operator typed for one patch.
struct TypedReading {
    PhotometerReading reading;
};
enum class OperatorCommand { repeat, back, quit, help };
/// A typed line: a reading ("21.9", "21.9 cd/m2", "6.4 fL", "20.1 21.9 23.5"),
/// a command (r, b, q, ?) or, for a typo, the sentence saying what was wrong.
using OperatorLine = std::variant<TypedReading, OperatorCommand, std::string>;
OperatorLine parse_operator_line(std::string_view line);

}  // namespace atonlab::runner
