#include "atonlab/display/readings_text.h"

#include <charconv>
#include <cmath>

namespace atonlab::display {

std::vector<ReadingToken> reading_tokens(std::string_view line, bool commas_separate) {
    const auto blank = [&](char ch) { return ch == ' ' || ch == '\t' || ch == '\r' || (commas_separate && ch == ','); };
    std::vector<ReadingToken> out;
    std::size_t i = 0;
    while (i < line.size()) {
        const char ch = line[i];
        if (blank(ch)) {
            ++i;
        } else if (ch == '#') {
            break;
        } else if (ch == '"') {
            const std::size_t end = line.find('"', i + 1);
            const std::size_t stop = end == std::string_view::npos ? line.size() : end;
            out.push_back({std::string(line.substr(i + 1, stop - i - 1)), static_cast<int>(i) + 1});
            i = stop + 1;
        } else {
            std::size_t j = i;
            while (j < line.size() && !blank(line[j]) && line[j] != '#') ++j;
            out.push_back({std::string(line.substr(i, j - i)), static_cast<int>(i) + 1});
            i = j;
        }
    }
    return out;
}

std::optional<double> reading_number(std::string_view s) {
    const auto b = s.find_first_not_of(" \t\r");
    if (b == std::string_view::npos) return std::nullopt;
    s = s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
    return v;
}

}  // namespace atonlab::display
