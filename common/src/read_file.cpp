#include "atonlab/common/read_file.h"

#include <fmt/format.h>

#include <utility>

namespace atonlab::files {

ReadError::ReadError(std::filesystem::path file, std::string message)
    : std::runtime_error(text::one_line(file.string() + ": " + message)),
      file_(std::move(file)),
      message_(text::one_line(message)) {}

std::string read_text(const std::filesystem::path& file, std::string_view what, std::uintmax_t max_bytes) {
    text::FileText read = text::read_text_file(file, max_bytes);
    if (!read.ok()) throw ReadError(file, fmt::format("cannot read the {}: {}.", what, read.error));
    return std::move(read.text);
}

}  // namespace atonlab::files
