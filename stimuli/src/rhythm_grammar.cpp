// The grammar of light characters (IALA Recommendation E-110 chart texts, and
// older spellings): tokens, class aliases, colour letters, groups and period.
// rhythm.cpp lays the parsed character out in time.
#include "rhythm_grammar.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <optional>
#include <utility>

#include "atonlab/stimuli/error.h"

namespace atonlab::stimuli::rhythm_detail {

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

// ---- Errors ------------------------------------------------------------------

void fail(std::string_view text, const std::string& what) {
    throw InputError(fmt::format("rhythm '{}': {}", text, what));
}

std::string num(double v) {
    return fmt::format("{}", v);
}

// ---- Morse -------------------------------------------------------------------

const char* morse_code(char upper_letter) {
    static constexpr std::array<const char*, 26> codes{
        ".-", "-...", "-.-.", "-..",  ".",   "..-.", "--.", "....", "..",   ".---", "-.-",  ".-..", "--",
        "-.", "---",  ".--.", "--.-", ".-.", "...",  "-",   "..-",  "...-", ".--",  "-..-", "-.--", "--.."};
    return codes[static_cast<std::size_t>(upper_letter - 'A')];
}

namespace {

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

}  // namespace

Parsed parse_character(std::string_view src) {
    return Parser(src).parse();
}

}  // namespace atonlab::stimuli::rhythm_detail
