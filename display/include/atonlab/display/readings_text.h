#pragma once
// The words of a photometer readings line, read one way by every reader of
// readings: an ArgyllCMS .ti3 file (display/calibration.h) and the readings
// `atonlab calibrate` takes from a file or from the operator's keyboard.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace atonlab::display {

/// cd/m² in one foot-lambert: 1 fL = (1/π) cd/ft², 1 ft = 0.3048 m (NIST SP 811, B.9).
inline constexpr double kCdM2PerFootLambert = 3.4262590996353905;

/// One word of a line and where it starts.
struct ReadingToken {
    std::string text;
    int column = 0;  ///< 1-based
};

/// The words of `line`: separated by blanks (space, tab, CR), and by commas too
/// when `commas_separate`; a "quoted string" is one word (without its quotes);
/// `#` starts a comment that runs to the end of the line.
std::vector<ReadingToken> reading_tokens(std::string_view line, bool commas_separate = false);

/// A finite decimal number filling `s` (blanks around it allowed, a leading
/// '+' too), or nullopt.
std::optional<double> reading_number(std::string_view s);

}  // namespace atonlab::display
