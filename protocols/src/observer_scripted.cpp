// The scripted observer: answers read from a file (observer.h).
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <system_error>

#include "atonlab/common/input_text.h"
#include "atonlab/protocols/observer.h"

namespace atonlab::protocols {

namespace {

/// A script's answer: a response word (response_word), or "first" / "second"
/// for the intervals of a temporal 2IFC (Left / Right).
std::optional<Response> scripted_response(std::string_view word) {
    if (word == "first") return Response::Left;
    if (word == "second") return Response::Right;
    return parse_response_word(word);
}

constexpr std::string_view kWordList =
    "left, right, first, second, yes, no, coarse_up, coarse_down, fine_up, fine_down, confirm";

std::vector<std::string_view> split(std::string_view s) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
        const std::size_t start = i;
        while (i < s.size() && s[i] != ' ' && s[i] != '\t' && s[i] != '\r') ++i;
        if (i > start) out.push_back(s.substr(start, i - start));
    }
    return out;
}

bool fits(Task task, Response r) {
    const auto actions = task_actions(task);
    return std::any_of(actions.begin(), actions.end(), [r](Action a) { return response_of(a) == r; });
}

std::string_view takes(Task task) {
    switch (task) {
        case Task::TwoAfc:
            return "left or right";
        case Task::YesNo:
            return "yes or no";
        case Task::Adjust:
            return "coarse_up, coarse_down, fine_up, fine_down or confirm";
    }
    return "?";
}

}  // namespace

ScriptedObserver ScriptedObserver::parse(std::string_view text, std::string_view file_name) {
    const std::string file(file_name);
    std::vector<Line> lines;
    int number = 0;
    std::size_t pos = 0;
    while (pos <= text.size()) {
        const std::size_t end = std::min(text.find('\n', pos), text.size());
        std::string_view line = text.substr(pos, end - pos);
        pos = end + 1;
        ++number;
        if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
        const std::vector<std::string_view> tokens = split(line);
        if (tokens.empty()) {
            if (end == text.size()) break;
            continue;
        }
        if (tokens.size() > 2)
            throw InputError(SourceLocation{file, number, 0, ""},
                                fmt::format("expected an answer and at most a response time in seconds "
                                            "(\"left 0.62\"), got \"{}\".",
                                            line));
        std::string word(tokens[0]);
        std::transform(word.begin(), word.end(), word.begin(), [](char c) {
            return c == '-' ? '_' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        });
        const std::optional<Response> response = scripted_response(word);
        if (!response)
            throw InputError(SourceLocation{file, number, 0, ""},
                                fmt::format("unknown answer \"{}\"; expected one of {}.", tokens[0], kWordList));
        Line l;
        l.line = number;
        l.word = std::string(tokens[0]);
        l.answer.response = *response;
        if (tokens.size() == 2) {
            double rt = 0.0;
            const auto [ptr, ec] = std::from_chars(tokens[1].data(), tokens[1].data() + tokens[1].size(), rt);
            if (ec != std::errc() || ptr != tokens[1].data() + tokens[1].size() || !std::isfinite(rt) || rt < 0.0)
                throw InputError(SourceLocation{file, number, 0, ""},
                    fmt::format("the response time \"{}\" is not a number of seconds >= 0.", tokens[1]));
            l.answer.response_time_s = rt;
        }
        lines.push_back(std::move(l));
        if (end == text.size()) break;
    }
    return ScriptedObserver(file, std::move(lines));
}

ScriptedObserver ScriptedObserver::load(const std::filesystem::path& file) {
    text::FileText read = text::read_text_file(file);  // only up to a limit (/dev/zero is refused)
    if (!read.ok())
        throw InputError(SourceLocation{file.string(), 0, 0, ""},
                         fmt::format("cannot read the answer file: {}.", read.error));
    return parse(read.text, file.string());
}

Answer ScriptedObserver::answer(const Shown& shown) {
    if (next_ >= lines_.size())
        throw InputError(SourceLocation{file_, 0, 0, ""},
                            fmt::format("the script's {} {} used up: answer {} needs one more line.", lines_.size(),
                                        lines_.size() == 1 ? "answer is" : "answers are", next_ + 1));
    const Line& l = lines_[next_];
    if (!fits(shown.task, l.answer.response))
        throw InputError(SourceLocation{file_, l.line, 0, ""},
                            fmt::format("the answer \"{}\" does not fit a {} trial, which takes {}.", l.word,
                                        to_string(shown.task), takes(shown.task)));
    ++next_;
    return l.answer;
}

}  // namespace atonlab::protocols
