#pragma once
// Reading a whole input file into a string: the one place that does it, with
// the size limit of input files (docs/fuzzing.md, "Limits on input") and an
// error that names the file.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "atonlab/common/input_error.h"
#include "atonlab/common/input_text.h"

namespace atonlab::files {

/// The whole text of `file`, read up to `max_bytes` (/dev/zero or a video file
/// given by mistake is refused, not read until the memory runs out). `what`
/// names the file's role in the message ("scene template", "readings file").
/// Throws InputError at the file (no line): "FILE: cannot read the WHAT: REASON.",
/// message() without the file, the reason being
/// the system's ("No such file or directory"), "it is a directory" or "it is
/// larger than 16.0 MiB, the most an input file may be".
std::string read_text(const std::filesystem::path& file, std::string_view what,
                      std::uintmax_t max_bytes = text::kMaxInputFileBytes);

}  // namespace atonlab::files
