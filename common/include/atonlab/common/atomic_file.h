#pragma once
// Files written whole or not at all: every output file of atonlab (images,
// report, summary, CSVs) is written to a temporary sibling, flushed to disk and
// renamed over the destination, so a crash or a full disk never leaves a
// partial file where a finished one is expected (docs/architecture.md
// "Errors and what is kept").
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace atonlab::files {

/// A file could not be written. what() is "PATH: REASON"; reason() is the
/// clause alone, for a caller that names the file in its own error type.
class WriteError : public std::runtime_error {
public:
    WriteError(std::filesystem::path path, std::string reason);
    const std::filesystem::path& path() const noexcept { return path_; }
    const std::string& reason() const noexcept { return reason_; }

private:
    std::filesystem::path path_;
    std::string reason_;
};

/// A temporary file next to the destination (created O_EXCL with mode 0666, so
/// the umask decides who can read the result), renamed over it by commit()
/// after an fsync. The destructor removes the temporary unless it was
/// committed, so every early exit cleans up. Throws WriteError.
class AtomicFile {
public:
    explicit AtomicFile(std::filesystem::path destination);
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;
    ~AtomicFile();

    const std::filesystem::path& temp_path() const noexcept { return temp_; }
    /// Hands the descriptor over (the caller then owns it, e.g. to fdopen).
    int release_fd() noexcept;
    /// Closes the descriptor so that a library can open temp_path() by name.
    void close_fd() noexcept;
    /// Flushes the finished temporary to disk and renames it over the destination.
    void commit();

private:
    std::filesystem::path destination_;
    std::filesystem::path temp_;
    int fd_ = -1;
    bool committed_ = false;
};

/// Writes `bytes` to `file` through an AtomicFile. Throws WriteError.
void write_file_atomically(const std::filesystem::path& file, std::string_view bytes);

}  // namespace atonlab::files
