#include "spotread_output.h"

#include <charconv>
#include <cmath>
#include <vector>

namespace atonlab::runner::spotread {
namespace {

// spotread.c: printf("Hit ESC or Q to exit, any other key to take a reading: ") (with or
// without "instrument switch or " before "any").
constexpr std::string_view kReady = "any other key to take a reading:";
// spotread.c: printf("\n Result is XYZ: %f %f %f, ...\n").
constexpr std::string_view kResult = "Result is XYZ:";
// instappsup.c, inst_handle_calibrate: each instruction ends with
// printf(" or hit Esc or Q to abort: ") (or "..., or S to skip: "); a failed
// calibration asks "Hit any key to retry, or Esc or Q to abort:".
constexpr std::string_view kCalibrationPrompt = "Esc or Q to abort";
// Errors: spotread.c "Spot read failed ..." (misread, communication, sensor position),
// ierror's "Got '%s' (%s) error.", numlib's error() "spotread: Error - ...",
// usage()'s "Diagnostic: ...", "Failed to initialise communications with instrument",
// "Instrument initialisation failed with ...", "Spot read got abort or error ...".
constexpr std::string_view kErrors[] = {
    "Spot read failed",  "error.", "Error - ", "Diagnostic:", "Failed to initialise", "initialisation failed",
    "got abort or error"};

std::string_view line_at(std::string_view text, std::size_t pos) {
    const std::size_t begin = text.rfind('\n', pos) == std::string_view::npos ? 0 : text.rfind('\n', pos) + 1;
    const std::size_t end = text.find('\n', pos);
    return text.substr(begin, (end == std::string_view::npos ? text.size() : end) - begin);
}

std::string trimmed(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return std::string(s);
}

}  // namespace

Scan scan(std::string_view out) {
    struct Hit {
        std::size_t at;
        Scan scan;
    };
    std::vector<Hit> hits;
    if (const auto r = out.find(kResult); r != std::string_view::npos) {
        const auto nl = out.find('\n', r);
        if (nl != std::string_view::npos) hits.push_back({r, {State::result, nl + 1, trimmed(out.substr(r, nl - r))}});
    }
    if (const auto k = out.find(kReady); k != std::string_view::npos) {
        std::size_t end = k + kReady.size();
        if (end < out.size() && out[end] == ' ') ++end;  // the prompt's own space
        hits.push_back({k, {State::ready, end, trimmed(line_at(out, k))}});
    }
    if (const auto c = out.find(kCalibrationPrompt); c != std::string_view::npos)
        hits.push_back({c, {State::calibration, c + kCalibrationPrompt.size(), trimmed(line_at(out, c))}});
    for (const std::string_view e : kErrors) {
        const auto at = out.find(e);
        if (at == std::string_view::npos) continue;
        // A failed calibration is the calibration prompt's business; an error line
        // counts once it is complete (or spotread waits on it for a key).
        const std::string_view line = line_at(out, at);
        const std::size_t end = (line.data() - out.data()) + line.size();
        if (end == out.size() && out.find("retry:", at) == std::string_view::npos) continue;
        hits.push_back({at, {State::failed, end, trimmed(line)}});
    }
    if (hits.empty()) return {};
    const Hit* first = &hits.front();
    for (const Hit& h : hits)
        if (h.at < first->at) first = &h;
    return first->scan;
}

std::optional<glm::dvec3> parse_result(std::string_view line) {
    const auto r = line.find(kResult);
    if (r == std::string_view::npos) return std::nullopt;
    std::string_view rest = line.substr(r + kResult.size());
    glm::dvec3 xyz{0.0};
    for (int i = 0; i < 3; ++i) {
        while (!rest.empty() && rest.front() == ' ') rest.remove_prefix(1);
        double v = 0.0;
        const auto [ptr, ec] = std::from_chars(rest.data(), rest.data() + rest.size(), v);
        if (ec != std::errc() || ptr == rest.data() || !std::isfinite(v)) return std::nullopt;
        xyz[i] = v;
        rest.remove_prefix(static_cast<std::size_t>(ptr - rest.data()));
    }
    // The three numbers end at the comma before the second colour space, or the line.
    while (!rest.empty() && rest.front() == ' ') rest.remove_prefix(1);
    if (!rest.empty() && rest.front() != ',') return std::nullopt;
    return xyz;
}

std::string calibration_instruction(std::string_view out) {
    const auto c = out.find(kCalibrationPrompt);
    std::string_view head = out.substr(0, c == std::string_view::npos ? out.size() : c);
    // The instruction starts after the last blank line or "calibration" announcement before the prompt.
    std::size_t begin = 0;
    for (std::string_view mark : {std::string_view("calibration before continuing\n"),
                                  std::string_view("needs calibration.\n"), std::string_view("\n\n")})
        if (const auto m = head.rfind(mark); m != std::string_view::npos) begin = std::max(begin, m + mark.size());
    std::string text;
    for (char ch : head.substr(begin)) {
        if (ch == '\n') ch = ' ';
        if (ch == ' ' && (text.empty() || text.back() == ' ')) continue;
        text += ch;
    }
    // The prompt's own words before "Esc or Q to abort" (" or hit", "Hit any key to retry, or") are not the
    // instruction.
    auto drop_word = [&](std::string_view w) {
        while (!text.empty() && (text.back() == ' ' || text.back() == ',')) text.pop_back();
        if (text.size() >= w.size() && std::string_view(text).substr(text.size() - w.size()) == w)
            text.resize(text.size() - w.size());
        while (!text.empty() && (text.back() == ' ' || text.back() == ',')) text.pop_back();
    };
    drop_word("hit");
    drop_word("or");
    drop_word("and then hit any key to continue");  // atonlab asks for Enter instead
    return text;
}

}  // namespace atonlab::runner::spotread
