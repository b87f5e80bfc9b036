#pragma once
// Running gnuplot as a subprocess on a script in a private temporary folder.
#include <filesystem>
#include <string>
#include <string_view>

namespace atonlab::analysis::detail {

/// A folder made with mkdtemp under the system's temporary directory, removed
/// (with everything in it) by the destructor.
class TempFolder {
public:
    explicit TempFolder(std::string_view prefix);
    ~TempFolder();
    TempFolder(const TempFolder&) = delete;
    TempFolder& operator=(const TempFolder&) = delete;
    const std::filesystem::path& path() const noexcept { return path_; }

private:
    std::filesystem::path path_;
};

struct GnuplotRun {
    bool not_found = false;  ///< the program could not be started (not installed)
    int exit_status = 0;     ///< gnuplot's exit status (128 + N when killed by signal N)
    std::string errors;      ///< what gnuplot wrote on stderr (its error messages, and warnings)
};

/// Runs `program script` with stdout and stderr captured into files of `folder`.
GnuplotRun run_gnuplot(const std::string& program, const std::filesystem::path& script,
                       const std::filesystem::path& folder);

/// A gnuplot string literal: single quotes, a quote inside doubled.
std::string gp_quote(std::string_view text);

}  // namespace atonlab::analysis::detail
