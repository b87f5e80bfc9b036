#include "gnuplot.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "atonlab/common/input_text.h"

extern char** environ;

namespace atonlab::analysis::detail {

TempFolder::TempFolder(std::string_view prefix) {
    std::string pattern = (std::filesystem::temp_directory_path() / (std::string(prefix) + "XXXXXX")).string();
    if (!mkdtemp(pattern.data()))
        throw std::runtime_error("cannot create a temporary folder in " +
                                 std::filesystem::temp_directory_path().string() + ": " + std::strerror(errno));
    path_ = pattern;
}

TempFolder::~TempFolder() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
}

GnuplotRun run_gnuplot(const std::string& program, const std::filesystem::path& script,
                       const std::filesystem::path& folder) {
    GnuplotRun out;
    const std::string out_file = (folder / "gnuplot.stdout").string();
    const std::string err_file = (folder / "gnuplot.stderr").string();
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, 1, out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, 2, err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    std::string prog = program;
    std::string arg = script.string();
    std::vector<char*> argv{prog.data(), arg.data(), nullptr};
    pid_t pid = 0;
    const int rc = posix_spawnp(&pid, prog.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) {
        out.not_found = true;
        out.errors = std::strerror(rc);
        return out;
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0) {
        if (errno != EINTR) {
            out.exit_status = -1;
            out.errors = std::strerror(errno);
            return out;
        }
    }
    if (WIFEXITED(status))
        out.exit_status = WEXITSTATUS(status);
    else if (WIFSIGNALED(status))
        out.exit_status = 128 + WTERMSIG(status);
    // 127: the shell convention for "command not found", which some spawn
    // implementations report through the child instead of the return value.
    if (out.exit_status == 127) out.not_found = true;
    out.errors = text::read_text_file(err_file).text;
    return out;
}

std::string gp_quote(std::string_view text) {
    std::string out = "'";
    for (const char ch : text) {
        if (ch == '\'') out += '\'';
        if (ch == '\n' || ch == '\r') {
            out += ' ';
            continue;
        }
        out += ch;
    }
    return out + "'";
}

}  // namespace atonlab::analysis::detail
