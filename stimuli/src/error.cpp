#include "atonlab/stimuli/error.h"

#include <fmt/format.h>

namespace atonlab {
namespace {

std::string format_error(const SourceLocation& w, const std::string& message) {
    std::string s;
    if (!w.file.empty()) {
        s += w.file;
        if (w.line > 0) s += fmt::format(":{}", w.line);
        s += ": ";
    }
    if (!w.key.empty()) s += fmt::format("key '{}': ", w.key);
    s += message;
    return s;
}

}  // namespace

InputError::InputError(SourceLocation where, const std::string& message)
    : std::runtime_error(format_error(where, message)), where_(std::move(where)), message_(message) {}

InputError::InputError(const std::string& message) : std::runtime_error(message), message_(message) {}

}  // namespace atonlab
