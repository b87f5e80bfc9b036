// Light characters (IALA Recommendation E-110, "Rhythmic characters of lights")
// turned into the blink profile B(t) of K2012 §4.1 / §5.1.
//
// Where E-110 fixes a duration (long flash >= 2 s; quick 50-79, very quick
// 80-159, ultra quick >= 160 flashes a minute; Morse dash = 3 dots) we follow
// it; where it leaves a duration free we use the nominal values below, listed
// with the grammar in docs/light-characters.md. Keep the two in step.
//
// Every on/off edge becomes a linear ramp of RhythmTiming::ramp_s centred on
// the nominal edge. That is the nominal square wave convolved with a box of
// width ramp_s, so the integral of every flash (and the duty cycle) equals the
// nominal value exactly, whatever the ramp.
#include "atonlab/stimuli/rhythm.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <charconv>
#include <cmath>
#include <optional>
#include <utility>

#include "atonlab/stimuli/error.h"

namespace atonlab::stimuli {
namespace {

// ---- Nominal durations, seconds (docs/light-characters.md, "Timing") ----------

/// A flash and the eclipse between two flashes of one group.
struct FlashTiming {
    double flash_s;
    double eclipse_s;
    double cycle_s() const { return flash_s + eclipse_s; }
};

constexpr FlashTiming fl_timing{0.5, 1.0};   // E-110 leaves both free
constexpr FlashTiming lfl_timing{2.0, 2.0};  // E-110: a long flash lasts at least 2 s
constexpr FlashTiming q_timing{0.3, 0.7};    // 60 flashes/min (E-110: 50..79, usually 50 or 60)
constexpr FlashTiming vq_timing{0.2, 0.3};   // 120 flashes/min (E-110: 80..159, usually 100 or 120)
constexpr FlashTiming uq_timing{0.1, 0.15};  // 240 flashes/min (E-110: >= 160, usually 240..300)

constexpr double oc_eclipse_s = 1.0;        // occulting eclipse (IALA example Oc(2) 13s = 1,1,1,10)
constexpr double oc_light_between_s = 1.0;  // light between the eclipses of a group (same example)

constexpr double morse_dot_s = 0.5;
constexpr double morse_dash_s = 3 * morse_dot_s;        // E-110 / ITU: a dash is three dots
constexpr double morse_element_gap_s = morse_dot_s;     // ITU: one dot between dots and dashes
constexpr double morse_letter_gap_s = 3 * morse_dot_s;  // ITU: three dots between letters

/// Periods are decimals ("4.8s") and the nominal durations are not exact in
/// binary, so "at least" comparisons forgive this much rounding.
constexpr double slack_s = 1e-9;

/// Interrupted quick: the interruption lasts at least this many flash cycles.
constexpr double interruption_cycles = 3.0;

/// Rate limits of continuous quick lights, flashes per minute (E-110).
struct RateLimits {
    double min_per_min;
    double max_per_min;  ///< exclusive; for UQ set by the flash length (dark at least as long as the flash)
};

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

const char* kind_name(Kind k) {
    switch (k) {
        case Kind::fixed:
            return "F";
        case Kind::flash:
            return "Fl";
        case Kind::long_flash:
            return "LFl";
        case Kind::quick:
            return "Q";
        case Kind::very_quick:
            return "VQ";
        case Kind::ultra_quick:
            return "UQ";
        case Kind::interrupted_quick:
            return "IQ";
        case Kind::interrupted_very_quick:
            return "IVQ";
        case Kind::interrupted_ultra_quick:
            return "IUQ";
        case Kind::occulting:
            return "Oc";
        case Kind::isophase:
            return "Iso";
        case Kind::morse:
            return "Mo";
    }
    return "?";
}

bool is_flashing(Kind k) {
    return k == Kind::flash || k == Kind::long_flash || k == Kind::quick || k == Kind::very_quick ||
           k == Kind::ultra_quick;
}
bool is_quick(Kind k) {
    return k == Kind::quick || k == Kind::very_quick || k == Kind::ultra_quick;
}
bool is_interrupted(Kind k) {
    return k == Kind::interrupted_quick || k == Kind::interrupted_very_quick || k == Kind::interrupted_ultra_quick;
}

FlashTiming flash_timing(Kind k) {
    switch (k) {
        case Kind::flash:
            return fl_timing;
        case Kind::long_flash:
            return lfl_timing;
        case Kind::quick:
        case Kind::interrupted_quick:
            return q_timing;
        case Kind::very_quick:
        case Kind::interrupted_very_quick:
            return vq_timing;
        case Kind::ultra_quick:
        case Kind::interrupted_ultra_quick:
            return uq_timing;
        default:
            assert(false && "not a flashing class");
            return fl_timing;
    }
}

RateLimits rate_limits(Kind k) {
    switch (k) {
        case Kind::quick:
            return {50, 80};
        case Kind::very_quick:
            return {80, 160};
        default:
            return {160, 60.0 / (2 * uq_timing.flash_s)};  // eclipse at least as long as the flash
    }
}

struct Element {
    Kind kind = Kind::fixed;
    std::vector<int> groups;  ///< flash/eclipse counts, "(2+1)" -> {2, 1}; empty when not written
    std::string morse;        ///< upper-case letters for Mo
};

/// One phase of the nominal square wave: lit or dark for dur_s seconds.
struct Phase {
    bool lit;
    double dur_s;
};

/// A lit interval [a_s, b_s) of the nominal square wave, 0 <= a < b <= period.
struct Interval {
    double a_s;
    double b_s;
};

// ---- Errors ------------------------------------------------------------------

[[noreturn]] void fail(std::string_view text, const std::string& what) {
    throw InputError(fmt::format("rhythm '{}': {}", text, what));
}

/// Shortest decimal that round-trips, for messages and the normalised text.
std::string num(double v) {
    return fmt::format("{}", v);
}

// ---- Tokens ------------------------------------------------------------------

enum class Tok { word, number, lparen, rparen, plus, end };

struct Token {
    Tok kind;
    std::string text;  ///< as written
    double value = 0;  ///< numbers only
    std::size_t pos;   ///< offset in the source
};

bool is_letter(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
}
bool is_digit(char c) {
    return c >= '0' && c <= '9';
}

std::string lower(std::string_view s) {
    std::string r(s);
    for (char& c : r)
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    return r;
}

/// Splits a chart text into words, numbers and ( ) +. Spaces and dots are
/// separators ("Fl.G.3s", "L.Fl"), except a dot between two digits, which is a
/// decimal point ("2.5s").
std::vector<Token> tokenize(std::string_view src) {
    std::vector<Token> out;
    std::size_t i = 0;
    while (i < src.size()) {
        const char c = src[i];
        if (c == ' ' || c == '\t' || c == '.' || c == ',') {
            ++i;
        } else if (is_letter(c)) {
            std::size_t j = i;
            while (j < src.size() && is_letter(src[j])) ++j;
            out.push_back({Tok::word, std::string(src.substr(i, j - i)), 0, i});
            i = j;
        } else if (is_digit(c) || (c == '-' && i + 1 < src.size() && is_digit(src[i + 1]))) {
            std::size_t j = i + 1;
            while (j < src.size() && is_digit(src[j])) ++j;
            if (j + 1 < src.size() && src[j] == '.' && is_digit(src[j + 1])) {
                j += 1;
                while (j < src.size() && is_digit(src[j])) ++j;
            }
            const std::string t(src.substr(i, j - i));
            double v = 0;
            const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
            if (ec != std::errc() || ptr != t.data() + t.size() || !std::isfinite(v))
                fail(src, fmt::format("the number '{}' is out of range", t));
            out.push_back({Tok::number, t, v, i});
            i = j;
        } else if (c == '(' || c == ')' || c == '+') {
            const Tok k = c == '(' ? Tok::lparen : c == ')' ? Tok::rparen : Tok::plus;
            out.push_back({k, std::string(1, c), 0, i});
            ++i;
        } else {
            fail(src, fmt::format("unexpected character '{}'", c));
        }
    }
    out.push_back({Tok::end, "", 0, src.size()});
    return out;
}

// ---- Morse -------------------------------------------------------------------

/// International Morse code (ITU-R M.1677), '.' dot, '-' dash.
const char* morse_code(char upper_letter) {
    static constexpr std::array<const char*, 26> codes{
        ".-", "-...", "-.-.", "-..",  ".",   "..-.", "--.", "....", "..",   ".---", "-.-",  ".-..", "--",
        "-.", "---",  ".--.", "--.-", ".-.", "...",  "-",   "..-",  "...-", ".--",  "-..-", "-.--", "--.."};
    return codes[static_cast<std::size_t>(upper_letter - 'A')];
}

// ---- Parser ------------------------------------------------------------------

struct Alias {
    std::array<const char*, 3> words;  ///< lower case, nullptr-terminated
    Kind kind;
};

// Chart spellings, current (E-110) and older ("Gp Occ", "Qk.Fl", "V.Qk.Fl").
constexpr std::array<Alias, 24> class_aliases{{
    {{"int", "qk", "fl"}, Kind::interrupted_quick},
    {{"v", "qk", "fl"}, Kind::very_quick},
    {{"i", "v", "q"}, Kind::interrupted_very_quick},
    {{"i", "u", "q"}, Kind::interrupted_ultra_quick},
    {{"qk", "fl", nullptr}, Kind::quick},
    {{"l", "fl", nullptr}, Kind::long_flash},
    {{"v", "q", nullptr}, Kind::very_quick},
    {{"u", "q", nullptr}, Kind::ultra_quick},
    {{"i", "q", nullptr}, Kind::interrupted_quick},
    {{"i", "vq", nullptr}, Kind::interrupted_very_quick},
    {{"i", "uq", nullptr}, Kind::interrupted_ultra_quick},
    {{"f", nullptr, nullptr}, Kind::fixed},
    {{"fl", nullptr, nullptr}, Kind::flash},
    {{"lfl", nullptr, nullptr}, Kind::long_flash},
    {{"q", nullptr, nullptr}, Kind::quick},
    {{"vq", nullptr, nullptr}, Kind::very_quick},
    {{"uq", nullptr, nullptr}, Kind::ultra_quick},
    {{"iq", nullptr, nullptr}, Kind::interrupted_quick},
    {{"ivq", nullptr, nullptr}, Kind::interrupted_very_quick},
    {{"iuq", nullptr, nullptr}, Kind::interrupted_ultra_quick},
    {{"oc", nullptr, nullptr}, Kind::occulting},
    {{"occ", nullptr, nullptr}, Kind::occulting},
    {{"iso", nullptr, nullptr}, Kind::isophase},
    {{"mo", nullptr, nullptr}, Kind::morse},
}};

/// Splits a word into IALA colour letters (W, R, G, Bu, Y), or nothing.
std::optional<std::vector<std::string>> split_colours(std::string_view word) {
    std::vector<std::string> out;
    const std::string w = lower(word);
    for (std::size_t i = 0; i < w.size();) {
        if (w.compare(i, 2, "bu") == 0) {
            out.emplace_back("Bu");
            i += 2;
        } else if (w[i] == 'w' || w[i] == 'r' || w[i] == 'g' || w[i] == 'y') {
            out.emplace_back(1, static_cast<char>(w[i] - 'a' + 'A'));
            i += 1;
        } else {
            return std::nullopt;
        }
    }
    return out;
}

struct Parsed {
    bool alternating = false;
    std::vector<Element> elements;  ///< empty only for "Al.WR 4s"
    std::vector<std::string> colours;
    std::optional<double> period_s;
};

class Parser {
public:
    explicit Parser(std::string_view src) : src_(src), toks_(tokenize(src)) {}

    Parsed parse() {
        Parsed p;
        if (peek().kind == Tok::end) fail(src_, "the light character is empty");
        if (is_word("al") || is_word("alt")) {
            p.alternating = true;
            ++i_;
        }
        parse_elements(p);
        parse_colours(p);
        parse_period(p);
        if (peek().kind != Tok::end) fail(src_, fmt::format("unexpected '{}' at the end", rest_from(peek().pos)));
        return p;
    }

private:
    const Token& peek(std::size_t ahead = 0) const { return toks_[std::min(i_ + ahead, toks_.size() - 1)]; }
    bool is_word(const char* lower_word, std::size_t ahead = 0) const {
        return peek(ahead).kind == Tok::word && lower(peek(ahead).text) == lower_word;
    }
    std::string rest_from(std::size_t pos) const {
        std::string_view r = src_.substr(pos);
        while (!r.empty() && (r.back() == ' ' || r.back() == '\t')) r.remove_suffix(1);
        return std::string(r);
    }

    /// Longest chart spelling of a class at the cursor; advances past it.
    std::optional<Kind> match_class() {
        std::size_t best_len = 0;
        std::optional<Kind> best;
        for (const Alias& a : class_aliases) {
            std::size_t n = 0;
            while (n < a.words.size() && a.words[n] != nullptr && is_word(a.words[n], n)) ++n;
            const bool full = n == a.words.size() || a.words[n] == nullptr;
            if (full && n > best_len) {
                best_len = n;
                best = a.kind;
            }
        }
        i_ += best_len;
        return best;
    }

    void parse_elements(Parsed& p) {
        for (;;) {
            if (is_word("gp") || is_word("gr")) ++i_;  // "Gp Fl(2)": group is implied by the count
            const Token& at = peek();
            const std::optional<Kind> k = match_class();
            if (!k) {
                if (p.alternating && p.elements.empty()) return;  // "Al.WR 4s": colours follow
                if (at.kind == Tok::word)
                    fail(src_, fmt::format("'{}' is not a light class (F, Fl, LFl, Q, VQ, UQ, IQ, "
                                           "IVQ, IUQ, Oc, Iso or Mo)",
                                           at.text));
                if (!p.elements.empty())
                    fail(src_, at.kind == Tok::end
                                   ? std::string("'+' must be followed by a light class")
                                   : fmt::format("'+' must be followed by a light class, not '{}'", rest_from(at.pos)));
                if (at.kind == Tok::end) fail(src_, "the light class is missing");
                fail(src_, fmt::format("expected a light class before '{}'", rest_from(at.pos)));
            }
            Element e;
            e.kind = *k;
            if (peek().kind == Tok::lparen) {
                parse_group(e);
            } else if (e.kind == Kind::morse) {
                fail(src_, "Morse (Mo) needs its letter(s) in brackets, e.g. 'Mo(U) 15s'");
            }
            p.elements.push_back(std::move(e));
            if (peek().kind != Tok::plus) return;
            ++i_;
        }
    }

    void parse_group(Element& e) {
        const std::size_t open = peek().pos;
        ++i_;
        std::size_t close = open;
        {
            std::size_t j = i_;
            while (toks_[j].kind != Tok::rparen && toks_[j].kind != Tok::end) ++j;
            if (toks_[j].kind == Tok::end)
                fail(src_, fmt::format("the bracket opened at '{}' is not closed", rest_from(open)));
            close = toks_[j].pos;
        }
        const std::string inner(src_.substr(open + 1, close - open - 1));
        const char* name = kind_name(e.kind);
        if (e.kind == Kind::morse) {
            std::string letters;
            for (char c : inner) {
                if (c == ' ') continue;
                if (!is_letter(c)) fail(src_, fmt::format("Morse code '{}' must be letters A to Z", inner));
                letters += c >= 'a' ? static_cast<char>(c - 'a' + 'A') : c;
            }
            if (letters.empty()) fail(src_, "Mo() needs at least one letter, e.g. 'Mo(U) 15s'");
            e.morse = letters;
            while (peek().kind != Tok::rparen) ++i_;
            ++i_;
            return;
        }
        if (e.kind == Kind::fixed || e.kind == Kind::isophase || is_interrupted(e.kind))
            fail(src_, fmt::format("{} takes no group count, but '{}({})' has one", name, name, inner));
        const char* unit = e.kind == Kind::occulting ? "eclipse" : "flash";
        for (;;) {
            const Token& t = peek();
            if (t.kind != Tok::number)
                fail(src_, fmt::format("the group '({})' must be whole numbers joined by '+'", inner));
            if (t.value != std::floor(t.value))
                fail(src_, fmt::format("the group count '{}' is not a whole number", t.text));
            if (t.value < 1) fail(src_, fmt::format("a group must have at least one {}", unit));
            if (t.value > 99) fail(src_, fmt::format("the group count '{}' is too large", t.text));
            e.groups.push_back(static_cast<int>(t.value));
            ++i_;
            if (peek().kind == Tok::rparen) break;
            if (peek().kind != Tok::plus)
                fail(src_, fmt::format("the group '({})' must be whole numbers joined by '+'", inner));
            ++i_;
        }
        ++i_;  // ')'
    }

    void parse_colours(Parsed& p) {
        while (peek().kind == Tok::word) {
            const Token& t = peek();
            const auto c = split_colours(t.text);
            if (!c) {
                if (p.alternating && p.elements.empty())
                    fail(src_, fmt::format("'{}' is neither a light class nor colour letters "
                                           "(W, R, G, Bu, Y)",
                                           t.text));
                fail(src_, fmt::format("'{}' is not a colour (W, R, G, Bu, Y)", t.text));
            }
            p.colours.insert(p.colours.end(), c->begin(), c->end());
            ++i_;
        }
    }

    void parse_period(Parsed& p) {
        if (peek().kind != Tok::number) return;
        const Token& n = peek();
        ++i_;
        const bool unit = is_word("s") || is_word("sec") || is_word("secs") || is_word("second") || is_word("seconds");
        if (!unit) fail(src_, fmt::format("the period '{}' needs the unit s, e.g. '{}s'", n.text, n.text));
        ++i_;
        if (!(n.value > 0)) fail(src_, fmt::format("the period must be positive, not '{} s'", n.text));
        p.period_s = n.value;
    }

    std::string_view src_;
    std::vector<Token> toks_;
    std::size_t i_ = 0;
};

// ---- Layout: nominal phases over one period -----------------------------------

std::string element_text(const Element& e) {
    std::string s = kind_name(e.kind);
    if (e.kind == Kind::morse) return s + "(" + e.morse + ")";
    if (!e.groups.empty()) {
        s += "(";
        for (std::size_t i = 0; i < e.groups.size(); ++i) s += (i ? "+" : "") + std::to_string(e.groups[i]);
        s += ")";
    }
    return s;
}

/// Builds the phases of one element (or a "+" sequence of flashing elements)
/// over period_s, starting at t = 0 with the first flash (flashing, Morse, Iso)
/// or the first eclipse (occulting), as light lists write phases.
class Layout {
public:
    /// shares > 1: the pattern fills one colour's share of an alternating period.
    Layout(std::string_view src, std::string body, int shares = 1)
        : src_(src), body_(std::move(body)), shares_(shares) {}

    std::vector<Phase> build(const std::vector<Element>& els, double period_s) {
        phases_.clear();
        if (els.size() > 1) return sequence(els, period_s);
        const Element& e = els.front();
        switch (e.kind) {
            case Kind::occulting:
                return occulting(e, period_s);
            case Kind::isophase:
                return {{true, period_s / 2}, {false, period_s / 2}};
            case Kind::morse:
                return morse(e, period_s);
            case Kind::interrupted_quick:
            case Kind::interrupted_very_quick:
            case Kind::interrupted_ultra_quick:
                return interrupted(e, period_s);
            default:
                return flashing(e, period_s);
        }
    }

private:
    void push(bool lit, double dur_s) { phases_.push_back({lit, dur_s}); }
    double used() const {
        double s = 0;
        for (const Phase& ph : phases_) s += ph.dur_s;
        return s;
    }
    /// strict: the period must exceed needed_s; otherwise it may equal it.
    [[noreturn]] void too_short(double period_s, double needed_s, bool strict) const {
        const char* cmp = strict ? "more than" : "at least";
        if (shares_ > 1)
            fail(src_, fmt::format("the period {} s is too short for {}: each colour's {} s share needs "
                                   "{} {} s (see docs/light-characters.md)",
                                   num(period_s * shares_), body_, num(period_s), cmp, num(needed_s)));
        fail(src_, fmt::format("the period {} s is too short for {}: its nominal durations need {} {} s "
                               "(see docs/light-characters.md)",
                               num(period_s), body_, cmp, num(needed_s)));
    }
    /// n flashes of t separated by t.eclipse_s.
    void group_of_flashes(int n, const FlashTiming& t) {
        for (int i = 0; i < n; ++i) {
            if (i > 0) push(false, t.eclipse_s);
            push(true, t.flash_s);
        }
    }

    std::vector<Phase> flashing(const Element& e, double period_s) {
        const FlashTiming t = flash_timing(e.kind);
        const std::vector<int> groups = e.groups.empty() ? std::vector<int>{1} : e.groups;
        if (groups.size() == 1 && groups[0] == 1) {
            // Single flash: flashing means the eclipse is longer than the flash (E-110).
            if (e.groups.empty() && is_quick(e.kind)) {
                const RateLimits r = rate_limits(e.kind);
                const double per_min = 60.0 / period_s;
                if (per_min < r.min_per_min || per_min >= r.max_per_min)
                    fail(src_, fmt::format("{} flashes {} to {} times a minute, so its period must be "
                                           "in ({}, {}] s, not {} s",
                                           body_, num(r.min_per_min), num(r.max_per_min), num(60.0 / r.max_per_min),
                                           num(60.0 / r.min_per_min), num(period_s)));
            } else if (!(period_s - t.flash_s > t.flash_s)) {
                too_short(period_s, 2 * t.flash_s, true);
            }
            push(true, t.flash_s);
            push(false, period_s - t.flash_s);
            return phases_;
        }
        // Groups, composite groups (IALA example Oc(2+1) 12s = 1,1,1,4,1,4): every
        // group is followed by the same long eclipse, which must be at least twice
        // the eclipse inside a group so that the grouping is seen.
        double inside = 0;
        for (int n : groups) inside += n * t.flash_s + (n - 1) * t.eclipse_s;
        const double count = static_cast<double>(groups.size());
        const double long_s = (period_s - inside) / count;
        if (!(long_s >= 2 * t.eclipse_s - slack_s)) too_short(period_s, inside + count * 2 * t.eclipse_s, false);
        for (int n : groups) {
            group_of_flashes(n, t);
            push(false, long_s);
        }
        return phases_;
    }

    std::vector<Phase> sequence(const std::vector<Element>& els, double period_s) {
        // "Q(6)+LFl 15s": the elements follow each other at the rhythm of the one
        // before (the long flash comes where the 7th quick flash would).
        double longest_eclipse = 0;
        for (std::size_t k = 0; k < els.size(); ++k) {
            const Element& e = els[k];
            if (!is_flashing(e.kind))
                fail(src_, fmt::format("only flashing classes (Fl, LFl, Q, VQ, UQ) can be joined "
                                       "with '+', not {}",
                                       kind_name(e.kind)));
            if (e.groups.size() > 1)
                fail(src_, fmt::format("the composite group {} cannot be joined with '+'", element_text(e)));
            const FlashTiming t = flash_timing(e.kind);
            if (k > 0) {
                const double gap = flash_timing(els[k - 1].kind).eclipse_s;
                push(false, gap);
                longest_eclipse = std::max(longest_eclipse, gap);
            }
            const int n = e.groups.empty() ? 1 : e.groups[0];
            group_of_flashes(n, t);
            if (n > 1) longest_eclipse = std::max(longest_eclipse, t.eclipse_s);
        }
        const double inside = used();
        if (!(period_s - inside >= 2 * longest_eclipse - slack_s))
            too_short(period_s, inside + 2 * longest_eclipse, false);
        push(false, period_s - inside);
        return phases_;
    }

    std::vector<Phase> occulting(const Element& e, double period_s) {
        // The dark twin of flashing: eclipses of oc_eclipse_s separated by
        // oc_light_between_s inside a group; each group followed by a long light.
        const std::vector<int> groups = e.groups.empty() ? std::vector<int>{1} : e.groups;
        if (groups.size() == 1 && groups[0] == 1) {
            // Occulting means the light is longer than the eclipse (E-110).
            if (!(period_s - oc_eclipse_s > oc_eclipse_s)) too_short(period_s, 2 * oc_eclipse_s, true);
            push(false, oc_eclipse_s);
            push(true, period_s - oc_eclipse_s);
            return phases_;
        }
        double inside = 0;
        for (int n : groups) inside += n * oc_eclipse_s + (n - 1) * oc_light_between_s;
        const double count = static_cast<double>(groups.size());
        const double long_s = (period_s - inside) / count;
        if (!(long_s >= 2 * oc_light_between_s - slack_s))
            too_short(period_s, inside + count * 2 * oc_light_between_s, false);
        for (int n : groups) {
            for (int i = 0; i < n; ++i) {
                if (i > 0) push(true, oc_light_between_s);
                push(false, oc_eclipse_s);
            }
            push(true, long_s);
        }
        return phases_;
    }

    std::vector<Phase> morse(const Element& e, double period_s) {
        double longest_gap = 0;
        for (std::size_t l = 0; l < e.morse.size(); ++l) {
            if (l > 0) {
                push(false, morse_letter_gap_s);
                longest_gap = morse_letter_gap_s;
            }
            const std::string code = morse_code(e.morse[l]);
            for (std::size_t s = 0; s < code.size(); ++s) {
                if (s > 0) {
                    push(false, morse_element_gap_s);
                    longest_gap = std::max(longest_gap, morse_element_gap_s);
                }
                push(true, code[s] == '.' ? morse_dot_s : morse_dash_s);
            }
        }
        // The eclipse that ends the period must stand out from the gaps inside it;
        // a single dot/dash ("Mo(E)", "Mo(T)") must at least be shorter than its eclipse.
        const double inside = used();
        const double min_final = longest_gap > 0 ? 2 * longest_gap : inside;
        if (!(period_s - inside >= min_final - slack_s && period_s - inside > 0))
            too_short(period_s, inside + min_final, false);
        push(false, period_s - inside);
        return phases_;
    }

    std::vector<Phase> interrupted(const Element& e, double period_s) {
        // Quick flashes at the nominal rate for as long as the period allows while
        // leaving an interruption of at least interruption_cycles cycles.
        const FlashTiming t = flash_timing(e.kind);
        const double c = t.cycle_s();
        const double room = period_s - t.flash_s - interruption_cycles * c;
        const int n = room >= -slack_s ? 1 + static_cast<int>(std::floor((room + slack_s) / c)) : 0;
        if (n < 2) too_short(period_s, c + t.flash_s + interruption_cycles * c, false);
        group_of_flashes(n, t);
        push(false, period_s - used());
        return phases_;
    }

    std::string_view src_;
    std::string body_;
    int shares_;
    std::vector<Phase> phases_;
};

// ---- Knots: the ramped, periodic B(t) of one channel --------------------------

/// Length of [lo, hi] covered by the periodic lit set (intervals repeat every period).
double lit_measure(const std::vector<Interval>& lit, double period_s, double lo, double hi) {
    double m = 0;
    for (const Interval& iv : lit)
        for (int k = -1; k <= 1; ++k) {
            const double a = iv.a_s + k * period_s;
            const double b = iv.b_s + k * period_s;
            m += std::max(0.0, std::min(b, hi) - std::max(a, lo));
        }
    return m;
}

bool lit_after(const std::vector<Interval>& lit, double t) {  // on [t, t + eps)
    for (const Interval& iv : lit)
        if (iv.a_s <= t && t < iv.b_s) return true;
    return false;
}
bool lit_before(const std::vector<Interval>& lit, double t) {  // on (t - eps, t]
    for (const Interval& iv : lit)
        if (iv.a_s < t && t <= iv.b_s) return true;
    return false;
}

std::vector<RhythmKnot> knots_from_intervals(const std::vector<Interval>& lit, double period_s, double ramp_s) {
    std::vector<RhythmKnot> k;
    if (ramp_s == 0) {
        // Jumps: two knots at the same time (rhythm_level is right-continuous there).
        std::vector<double> edges;
        for (const Interval& iv : lit)
            for (double e : {iv.a_s, iv.b_s})
                if (e > 0 && e < period_s) edges.push_back(e);
        std::sort(edges.begin(), edges.end());
        edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
        const double first = lit_after(lit, 0) ? 1 : 0;
        k.push_back({0, first});
        for (double e : edges) {
            k.push_back({e, lit_before(lit, e) ? 1.0 : 0.0});
            k.push_back({e, lit_after(lit, e) ? 1.0 : 0.0});
        }
        k.push_back({period_s, lit_before(lit, period_s) ? 1.0 : 0.0});
        k.push_back({period_s, first});
        k.erase(
            std::unique(k.begin(), k.end(),
                        [](const RhythmKnot& x, const RhythmKnot& y) { return x.t_s == y.t_s && x.level == y.level; }),
            k.end());
        return k;
    }
    // The square wave convolved with a box of width ramp_s is piecewise linear
    // with breaks at every edge +- ramp_s / 2; evaluate it exactly there.
    const double h = ramp_s / 2;
    auto level_at = [&](double t) {
        const double l = lit_measure(lit, period_s, t - h, t + h) / ramp_s;
        // Snap rounding noise so that plateaus are exactly 0 and 1.
        if (l < 1e-12) return 0.0;
        if (l > 1 - 1e-12) return 1.0;
        return l;
    };
    auto wrap = [&](double t) {
        double w = std::fmod(t, period_s);
        if (w < 0) w += period_s;
        return w >= period_s ? 0.0 : w;
    };
    std::vector<double> ts{0};
    for (const Interval& iv : lit)
        for (double e : {iv.a_s, iv.b_s}) {
            ts.push_back(wrap(e - h));
            ts.push_back(wrap(e + h));
        }
    std::sort(ts.begin(), ts.end());
    ts.erase(std::unique(ts.begin(), ts.end()), ts.end());
    for (double t : ts) k.push_back({t, level_at(t)});
    k.push_back({period_s, k.front().level});
    return k;
}

std::vector<Interval> lit_intervals(const std::vector<Phase>& phases, double offset_s) {
    std::vector<Interval> out;
    double t = offset_s;
    for (const Phase& ph : phases) {
        if (ph.lit) {
            if (!out.empty() && out.back().b_s == t)
                out.back().b_s = t + ph.dur_s;
            else
                out.push_back({t, t + ph.dur_s});
        }
        t += ph.dur_s;
    }
    return out;
}

void check_ramp(std::string_view src, const std::vector<Phase>& phases, double ramp_s) {
    for (const Phase& ph : phases)
        if (ph.dur_s < ramp_s)
            fail(src, fmt::format("the ramp time {} s is longer than its shortest phase ({} s)", num(ramp_s),
                                  num(ph.dur_s)));
}

}  // namespace

// ---- Public API --------------------------------------------------------------

Rhythm parse_rhythm(std::string_view text, const RhythmTiming& timing) {
    if (!(timing.ramp_s >= 0) || !std::isfinite(timing.ramp_s))
        fail(text, fmt::format("the ramp time must be a finite number >= 0, not {}", timing.ramp_s));
    const Parsed p = Parser(text).parse();

    Rhythm r;
    std::string colours;
    for (const std::string& c : p.colours) colours += c;

    if (p.alternating) {
        // "Al.Fl.WR 5s": the period is shared equally among the colours in the
        // order written; each share shows the class's single-element pattern.
        Kind base = Kind::fixed;
        if (p.elements.size() > 1 || (p.elements.size() == 1 && !p.elements[0].groups.empty()))
            fail(text,
                 "alternating lights are supported with a single class without a group "
                 "(Al.WR, Al.Fl.WR, Al.LFl.WR, Al.Oc.WR, Al.Iso.WR)");
        if (!p.elements.empty()) base = p.elements[0].kind;
        if (!(base == Kind::fixed || base == Kind::flash || base == Kind::long_flash || base == Kind::occulting ||
              base == Kind::isophase))
            fail(text,
                 fmt::format("alternating {} is not supported (use Al. with F, Fl, LFl, Oc or Iso)", kind_name(base)));
        if (p.colours.size() < 2) fail(text, "an alternating light needs at least two colour letters, e.g. 'Al.WR 4s'");
        if (std::all_of(p.colours.begin(), p.colours.end(), [&](const std::string& c) { return c == p.colours[0]; }))
            fail(text, "an alternating light needs at least two different colours");
        if (!p.period_s) fail(text, "an alternating light needs a period, e.g. 'Al.WR 4s'");
        r.period_s = *p.period_s;
        const double slot_s = r.period_s / static_cast<double>(p.colours.size());
        const std::string base_text = base == Kind::fixed ? "" : std::string(kind_name(base)) + ".";
        r.text = "Al." + base_text + colours + " " + num(r.period_s) + "s";

        std::vector<Phase> slot;
        if (base == Kind::fixed) {
            slot = {{true, slot_s}};
        } else {
            Element e;
            e.kind = base;
            const std::string al_text = r.text.substr(0, r.text.find(' '));
            slot = Layout(text, al_text, static_cast<int>(p.colours.size())).build({e}, slot_s);
        }
        check_ramp(text, slot, timing.ramp_s);
        std::vector<std::string> order;
        for (const std::string& c : p.colours)
            if (std::find(order.begin(), order.end(), c) == order.end()) order.push_back(c);
        for (const std::string& c : order) {
            std::vector<Interval> lit;
            for (std::size_t s = 0; s < p.colours.size(); ++s) {
                if (p.colours[s] != c) continue;
                const std::vector<Interval> part = lit_intervals(slot, static_cast<double>(s) * slot_s);
                for (const Interval& iv : part) {
                    if (!lit.empty() && lit.back().b_s == iv.a_s)
                        lit.back().b_s = iv.b_s;
                    else
                        lit.push_back(iv);
                }
            }
            // The last slot ends at period_s by construction; avoid a rounding sliver past it.
            for (Interval& iv : lit) iv.b_s = std::min(iv.b_s, r.period_s);
            r.channels.push_back({c, knots_from_intervals(lit, r.period_s, timing.ramp_s)});
        }
        return r;
    }

    std::string body;
    for (std::size_t i = 0; i < p.elements.size(); ++i) body += (i ? "+" : "") + element_text(p.elements[i]);
    r.chart_colours = colours;
    const Element& first = p.elements.front();

    if (p.elements.size() == 1 && first.kind == Kind::fixed) {
        if (p.period_s)
            fail(text, fmt::format("a fixed light (F) has no period, but '{} s' is given", num(*p.period_s)));
        r.text = colours.empty() ? "F" : "F " + colours;
        r.period_s = 0;
        r.channels.push_back({"", {{0, 1}}});
        return r;
    }
    for (const Element& e : p.elements)
        if (e.kind == Kind::fixed) fail(text, "F (fixed) cannot be joined with '+'");

    double period_s = 0;
    if (p.period_s) {
        period_s = *p.period_s;
    } else if (p.elements.size() == 1 && is_quick(first.kind) && first.groups.empty()) {
        period_s = flash_timing(first.kind).cycle_s();  // continuous Q/VQ/UQ: one flash cycle
    } else {
        fail(text, fmt::format("{} needs a period, e.g. '{} 10s'", body, body));
    }

    const std::vector<Phase> phases = Layout(text, body).build(p.elements, period_s);
    check_ramp(text, phases, timing.ramp_s);
    std::vector<Interval> lit = lit_intervals(phases, 0);
    for (Interval& iv : lit) iv.b_s = std::min(iv.b_s, period_s);

    r.period_s = period_s;
    r.text = body;
    if (!colours.empty()) r.text += " " + colours;
    if (p.period_s) r.text += " " + num(period_s) + "s";
    r.channels.push_back({"", knots_from_intervals(lit, period_s, timing.ramp_s)});
    return r;
}

double rhythm_level(const std::vector<RhythmKnot>& knots, double period_s, double t_s) {
    assert(!knots.empty());
    if (knots.empty()) return 0;
    if (!(period_s > 0) || !std::isfinite(t_s)) return knots.front().level;
    // Wrap into [0, period). std::fmod is exact in IEEE 754 (no rounding), so this
    // equals t - period * floor(t / period) computed exactly, for negative t too;
    // only the "+ period" for negative t rounds, and when it rounds up to the
    // period itself the exact phase was within half an ulp of it: use 0, which
    // has the same level. For |t| beyond about 2^53 * ulp(period) the input t
    // itself no longer resolves the phase; the result is still a level in [0, 1].
    double w = std::fmod(t_s, period_s);
    if (w < 0) w += period_s;
    if (w >= period_s) w = 0;
    // First knot strictly after w; with two knots at one time (ramp 0) this takes
    // the level after the jump.
    const auto it =
        std::upper_bound(knots.begin(), knots.end(), w, [](double t, const RhythmKnot& k) { return t < k.t_s; });
    if (it == knots.begin()) return it->level;
    if (it == knots.end()) return knots.back().level;
    const RhythmKnot& k1 = *it;
    const RhythmKnot& k0 = *(it - 1);
    const double f = (w - k0.t_s) / (k1.t_s - k0.t_s);
    return k0.level + f * (k1.level - k0.level);
}

std::vector<float> tabulate(const RhythmChannel& channel, double period_s, int n) {
    assert(n > 0);
    std::vector<float> out;
    if (n <= 0) return out;
    out.reserve(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
        out.push_back(static_cast<float>(rhythm_level(channel.knots, period_s, i * period_s / n)));
    return out;
}

double Rhythm::level(double t_s, std::size_t channel) const {
    return rhythm_level(channels.at(channel).knots, period_s, t_s);
}

double Rhythm::duty_cycle(std::size_t channel) const {
    const std::vector<RhythmKnot>& k = channels.at(channel).knots;
    if (!(period_s > 0)) return k.front().level;
    // Exact integral of the piecewise-linear B(t): trapezoids between knots.
    double area = 0;
    for (std::size_t i = 1; i < k.size(); ++i) area += 0.5 * (k[i].level + k[i - 1].level) * (k[i].t_s - k[i - 1].t_s);
    return area / period_s;
}

}  // namespace atonlab::stimuli
