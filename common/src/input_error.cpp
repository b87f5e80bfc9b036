#include "atonlab/common/input_error.h"

#include <fmt/format.h>

#include <cstdio>
#include <mutex>
#include <set>

#include "atonlab/common/input_text.h"

namespace atonlab {
namespace {

std::string format_error(const SourceLocation& w, const std::string& message) {
    std::string s;
    if (!w.option.empty()) {
        s += w.option + ": ";
    } else if (!w.file.empty()) {
        s += w.file;
        if (w.line > 0) s += fmt::format(":{}", w.line);
        s += ": ";
    }
    if (!w.key.empty()) s += fmt::format("{} '{}': ", w.key_is_column ? "column" : "key", text::echo(w.key));
    s += message;
    // One line of bounded length, whatever the message echoes.
    return text::one_line(s);
}

}  // namespace

InputError::InputError(SourceLocation where, const std::string& message)
    : std::runtime_error(format_error(where, message)), where_(std::move(where)), message_(text::one_line(message)) {}

InputError::InputError(SourceLocation where, const std::string& message, std::vector<std::string> further)
    : std::runtime_error([&] {
          std::string s = format_error(where, message);
          for (const std::string& f : further) s += "\n" + f;
          return s;
      }()),
      further_(std::move(further)),
      where_(std::move(where)),
      message_(text::one_line(message)) {}

InputError::InputError(const std::string& message)
    : std::runtime_error(text::one_line(message)), message_(text::one_line(message)) {}

}  // namespace atonlab

namespace atonlab {

std::string note_deprecated(const SourceLocation& where, const std::string& old_spelling,
                            const std::string& new_spelling) {
    static std::mutex mutex;
    static std::set<std::string> said;
    const std::lock_guard lock(mutex);
    if (!said.insert(old_spelling).second) return {};
    SourceLocation at = where;
    at.key.clear();  // the note names the spelling itself
    std::string line = format_error(at, fmt::format("note: {} is deprecated; write {}", old_spelling, new_spelling));
    std::fprintf(stderr, "%s\n", line.c_str());
    return line;
}

}  // namespace atonlab
