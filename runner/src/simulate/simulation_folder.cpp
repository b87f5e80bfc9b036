// A simulation's folder (simulation_folder.h).
#include "simulate/simulation_folder.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>

#include <stdexcept>
#include <system_error>

#include "atonlab/common/input_error.h"
#include "atonlab/common/read_file.h"

namespace atonlab::runner {

namespace fs = std::filesystem;

fs::path tables_dir(const fs::path& dir) {
    return dir / "tables";
}

std::optional<analysis::SimulationManifest> read_manifest(const fs::path& dir) {
    std::error_code ec;
    if (!fs::exists(dir, ec)) return std::nullopt;
    if (!fs::is_directory(dir, ec))
        throw InputError(SourceLocation::command_line("--out"), fmt::format("{} is not a folder.", dir.string()));
    const fs::path m = analysis::simulation_manifest_path(dir);
    if (!fs::exists(m, ec)) {
        if (!fs::is_empty(dir, ec))
            throw InputError(SourceLocation::command_line("--out"),
                             fmt::format("{} holds other files but no simulation.json: give an empty or new folder "
                                         "(nothing in it was changed).",
                                         dir.string()));
        return std::nullopt;
    }
    try {
        return analysis::SimulationManifest::parse(files::read_text(m, "simulation manifest"), m.string());
    } catch (const std::runtime_error& e) {
        throw InputError(SourceLocation{m.string(), 0, 0, ""},
                         fmt::format("{} is not a simulation manifest this atonlab reads ({}); nothing in {} was "
                                     "changed.",
                                     m.string(), e.what(), dir.string()));
    }
}

void check_writable(const fs::path& dir) {
    std::error_code ec;
    fs::path existing = dir;
    while (!existing.empty() && !fs::exists(existing, ec)) existing = existing.parent_path();
    if (existing.empty()) existing = ".";
    if (!fs::is_directory(existing, ec))
        throw InputError(SourceLocation::command_line("--out"),
                         fmt::format("{} cannot be made: {} is not a folder.", dir.string(), existing.string()));
    // A probe file made and removed: access() says yes to root on any folder.
    std::string probe = (existing / ".atonlab-probe-XXXXXX").string();
    const int fd = ::mkstemp(probe.data());
    if (::access(existing.c_str(), W_OK | X_OK) != 0 || fd < 0) {
        const std::string why = std::generic_category().message(fd < 0 ? errno : EACCES);
        throw InputError(SourceLocation::command_line("--out"),
                         fmt::format("{} cannot be written: {} is not writable ({}).", dir.string(), existing.string(),
                                     why));
    }
    ::close(fd);
    ::unlink(probe.c_str());
}

}  // namespace atonlab::runner
