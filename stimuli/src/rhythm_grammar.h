#pragma once
// The grammar half of light characters (rhythm.cpp does the timing): a chart
// text such as "Fl(2) R 10s" read into classes, group counts, colours and a
// period, with one-sentence errors. Internal to the stimuli library.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace atonlab::stimuli::rhythm_detail {

// ---- Character model ---------------------------------------------------------

enum class Kind {
    fixed,
    flash,
    long_flash,
    quick,
    very_quick,
    ultra_quick,
    interrupted_quick,
    interrupted_very_quick,
    interrupted_ultra_quick,
    occulting,
    isophase,
    morse,
};

const char* kind_name(Kind k);

inline bool is_flashing(Kind k) {
    return k == Kind::flash || k == Kind::long_flash || k == Kind::quick || k == Kind::very_quick ||
           k == Kind::ultra_quick;
}
inline bool is_quick(Kind k) {
    return k == Kind::quick || k == Kind::very_quick || k == Kind::ultra_quick;
}
inline bool is_interrupted(Kind k) {
    return k == Kind::interrupted_quick || k == Kind::interrupted_very_quick || k == Kind::interrupted_ultra_quick;
}

struct Element {
    Kind kind = Kind::fixed;
    std::vector<int> groups;  ///< flash/eclipse counts, "(2+1)" -> {2, 1}; empty when not written
    std::string morse;        ///< upper-case letters for Mo
};

struct Parsed {
    bool alternating = false;
    std::vector<Element> elements;  ///< empty only for "Al.WR 4s"
    std::vector<std::string> colours;
    std::optional<double> period_s;
};

/// Throws InputError "rhythm 'TEXT': WHAT".
[[noreturn]] void fail(std::string_view text, const std::string& what);

/// Shortest decimal that round-trips, for messages and the normalised text.
std::string num(double v);

/// International Morse code (ITU-R M.1677) of an upper-case letter, '.' dot, '-' dash.
const char* morse_code(char upper_letter);

/// The chart text `src` read by the grammar of docs/light-characters.md.
Parsed parse_character(std::string_view src);

}  // namespace atonlab::stimuli::rhythm_detail
