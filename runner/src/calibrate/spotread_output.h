#pragma once
// What ArgyllCMS spotread prints, as atonlab reads it (docs/calibration.md,
// "spotread"). The texts are spotread's own, from ArgyllCMS 3.2.0
// spectro/spotread.c and spectro/instappsup.c (the printf calls cited below).
#include <glm/vec3.hpp>
#include <optional>
#include <string>
#include <string_view>

namespace atonlab::runner::spotread {

/// What spotread's output, read so far, says it is waiting for or has done.
enum class State {
    busy,         ///< nothing to act on yet
    ready,        ///< "Hit ESC or Q to exit, any other key to take a reading: " (spotread.c)
    result,       ///< a complete " Result is XYZ: X Y Z, ..." line (spotread.c)
    calibration,  ///< a calibration instruction ending " or hit Esc or Q to abort: " (instappsup.c)
    failed,       ///< an error: "Spot read failed ...", "Got '...' error.", "... Error - ...", "Diagnostic: ..."
};

struct Scan {
    State state = State::busy;
    std::size_t end = 0;  ///< where the event's text ends in the output (for a result: after its line)
    std::string line;     ///< the line that says it (the result line, the error, the instruction)
};

/// The first event in `output` (spotread's terminal output, carriage returns removed).
Scan scan(std::string_view output);

/// X, Y, Z from " Result is XYZ: 95.0 100.0 108.9, D50 Lab: ..." (absolute
/// cd/m² in emissive mode, -e); nullopt when the line has no three numbers.
std::optional<glm::dvec3> parse_result(std::string_view line);

/// The calibration instruction spotread gave, its lines joined by spaces
/// ("Place cap on the instrument, or place on a dark surface, ...").
std::string calibration_instruction(std::string_view output);

}  // namespace atonlab::runner::spotread
