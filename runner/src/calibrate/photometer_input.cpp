#include "photometer_input.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <sstream>

#include "atonlab/common/read_file.h"
#include "atonlab/display/readings_text.h"
#include "atonlab/stimuli/error.h"

namespace atonlab::runner {
namespace {

using display::kCdM2PerFootLambert;
using display::reading_number;
using Token = display::ReadingToken;

/// A readings line's words: blanks or commas separate them (a meter's log may be CSV).
std::vector<Token> split(std::string_view line) {
    return display::reading_tokens(line, /*commas_separate=*/true);
}

/// cd/m² per unit for a unit word, or nullopt when `s` is not one.
std::optional<double> unit_scale(std::string_view s) {
    if (s == "cd/m2" || s == "cd/m²" || s == "cd/m^2" || s == "nit" || s == "nits") return 1.0;
    if (s == "fL" || s == "fl" || s == "ftL") return kCdM2PerFootLambert;
    return std::nullopt;
}

/// The values of a reading (1 or 3 numbers, then an optional unit) or why not.
std::variant<PhotometerReading, std::pair<std::string, int>> values_of(const std::vector<Token>& t, std::size_t first) {
    double scale = 1.0;
    std::size_t end = t.size();
    if (end > first && !reading_number(t[end - 1].text)) {
        if (const auto s = unit_scale(t[end - 1].text)) {
            scale = *s;
            --end;
        } else if (end - first >= 2) {
            return std::pair{fmt::format("'{}' is neither a number nor a unit (cd/m2 or fL)", t[end - 1].text),
                             t[end - 1].column};
        }
    }
    const std::size_t n = end - first;
    if (n != 1 && n != 3)
        return std::pair{fmt::format("a reading is one luminance (Y) or three values X Y Z, not {} values", n),
                         n == 0 ? 0 : t[first].column};
    double v[3] = {};
    for (std::size_t i = 0; i < n; ++i) {
        const auto x = reading_number(t[first + i].text);
        if (!x) return std::pair{fmt::format("'{}' is not a number", t[first + i].text), t[first + i].column};
        if (*x < 0.0)
            return std::pair{fmt::format("{} is negative; a photometer reads 0 or more", t[first + i].text),
                             t[first + i].column};
        v[i] = *x * scale;
    }
    PhotometerReading r;
    if (n == 1) {
        r.luminance_cd_m2 = v[0];
    } else {
        r.luminance_cd_m2 = v[1];
        r.xyz_cd_m2 = glm::dvec3(v[0], v[1], v[2]);
    }
    return r;
}

}  // namespace

std::vector<PhotometerReading> read_readings_file(const std::filesystem::path& path,
                                                  const std::vector<Patch>& patches) {
    const std::string file = path.string();
    std::istringstream in(files::read_text(path, "readings file"));
    std::vector<PhotometerReading> out;
    std::string line;
    int line_no = 0;
    while (std::getline(in, line)) {
        ++line_no;
        std::string_view text(line);
        if (const auto hash = text.find('#'); hash != std::string_view::npos) text = text.substr(0, hash);
        const std::vector<Token> t = split(text);
        if (t.empty()) continue;
        if (out.size() == patches.size())
            throw InputError(SourceLocation{file, line_no, t[0].column, ""},
                             fmt::format("there are {} patches but the file has more readings; this one has no patch "
                                         "(see --list-patches).",
                                         patches.size()));
        const Patch& patch = patches[out.size()];
        std::size_t first = 0;
        // A name only before a value: a lone word is a value that is not a number.
        if (t.size() >= 2 && !reading_number(t[0].text) && !unit_scale(t[1].text)) {
            if (t[0].text != patch.name)
                throw InputError(SourceLocation{file, line_no, t[0].column, "patch"},
                                 fmt::format("reading {} is for patch \"{}\", not \"{}\" (the patches are read in "
                                             "the order --list-patches shows).",
                                             out.size() + 1, patch.name, t[0].text));
            first = 1;
        }
        auto v = values_of(t, first);
        if (auto* bad = std::get_if<std::pair<std::string, int>>(&v))
            throw InputError(SourceLocation{file, line_no, bad->second, "cd_m2"},
                             fmt::format("patch \"{}\": {}.", patch.name, bad->first));
        PhotometerReading r = std::get<PhotometerReading>(v);
        r.line = line_no;
        out.push_back(r);
    }
    if (out.size() != patches.size())
        throw InputError(SourceLocation{file, line_no, 0, ""},
                         fmt::format("the file has {} readings but there are {} patches; the first without a reading "
                                     "is \"{}\" (see --list-patches).",
                                     out.size(), patches.size(), patches[out.size()].name));
    return out;
}

OperatorLine parse_operator_line(std::string_view line) {
    const std::vector<Token> t = split(line);
    if (t.empty()) return std::string("nothing was typed");
    if (t.size() == 1) {
        const std::string_view w = t[0].text;
        if (w == "r" || w == "R" || w == "repeat") return OperatorCommand::repeat;
        if (w == "b" || w == "B" || w == "back") return OperatorCommand::back;
        if (w == "q" || w == "Q" || w == "quit") return OperatorCommand::quit;
        if (w == "?" || w == "h" || w == "help") return OperatorCommand::help;
    }
    auto v = values_of(t, 0);
    if (auto* bad = std::get_if<std::pair<std::string, int>>(&v)) return bad->first;
    return TypedReading{std::get<PhotometerReading>(v)};
}

}  // namespace atonlab::runner
