#pragma once
// Input as errors echo it and as readers take it in: every echoed value
// shortened to one line of bounded length, every input file read only up to a
// size limit (docs/fuzzing.md, "Limits on input").
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace atonlab::text {

/// The longest echo of a value in a message, in characters (bytes of UTF-8).
inline constexpr std::size_t kEchoMax = 80;
/// The longest message an input error may have, in bytes: a safety net for
/// sentences that list many allowed keys and echo several values.
inline constexpr std::size_t kMessageMax = 2000;

/// `value` as a message may echo it: control characters escaped (\n, \t, \r,
/// \xNN), so a message stays on one line, and cut after `max` characters with
/// "…" and the value's full length in bytes. UTF-8 is kept whole (a cut never
/// splits a character).
std::string echo(std::string_view value, std::size_t max = kEchoMax);

/// A whole message made safe to print as one line: control characters escaped
/// and, past kMessageMax bytes, cut with "…".
std::string one_line(std::string_view message);

/// Largest text input files, in bytes. A scene or protocol file is a page or
/// two of TOML; 16 MiB leaves room for long tables without letting /dev/zero
/// or a mistaken video file exhaust the memory.
inline constexpr std::uintmax_t kMaxInputFileBytes = 16u << 20;

/// The text of a file, read up to `max_bytes`. On failure `text` is empty and
/// `error` is a clause saying why ("it is larger than 16 MiB", "No such file
/// or directory"), to be put in a sentence that names the file.
struct FileText {
    std::string text;
    std::string error;
    bool opened = false;  ///< the file could be opened (error then says why it could not be read)
    bool ok() const noexcept { return error.empty(); }
};
FileText read_text_file(const std::filesystem::path& file, std::uintmax_t max_bytes = kMaxInputFileBytes);

}  // namespace atonlab::text
