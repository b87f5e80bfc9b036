#include "atonlab/common/read_file.h"

#include <fmt/format.h>

#include <utility>

#include "atonlab/common/input_error.h"

namespace atonlab::files {

std::string read_text(const std::filesystem::path& file, std::string_view what, std::uintmax_t max_bytes) {
    text::FileText read = text::read_text_file(file, max_bytes);
    if (!read.ok())
        throw InputError(SourceLocation{file.string(), 0, 0, {}}, fmt::format("cannot read the {}: {}.", what, read.error));
    return std::move(read.text);
}

}  // namespace atonlab::files
