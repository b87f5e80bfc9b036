#pragma once
// Running a child process from a test (the atonlab binary, xdotool, ...):
// stdout and stderr to files, an exit status as a shell reports it; and the
// whole run captured (run_captured, and atonlab() where the test's build names
// the binary in ATONLAB_BINARY).
#include <cerrno>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace atonlab::test {

/// Exit status, or 128 + N for a child killed by signal N (as a shell reports it); -1 otherwise.
inline int status_code(int status) {
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
    return -1;
}

/// Starts argv[0] with argv, stdout and stderr to the files (truncated).
/// stdin_null: stdin from /dev/null. drop_root: as root, run as "nobody"
/// (root ignores file permissions). The child exits 120/121/122 when it
/// cannot redirect, drop privileges or exec; 123 when, dropped to "nobody",
/// it may not exec the program (EACCES: a directory above it, such as a
/// mktemp -d checkout's, is not searchable by others).
inline pid_t spawn_to_files(std::vector<std::string> argv, const std::filesystem::path& out,
                            const std::filesystem::path& err, bool stdin_null = false, bool drop_root = false) {
    const pid_t pid = fork();
    if (pid == 0) {
        const int o = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int e = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (o < 0 || e < 0 || dup2(o, 1) < 0 || dup2(e, 2) < 0) _exit(120);
        if (stdin_null) {
            const int i = open("/dev/null", O_RDONLY);
            if (i < 0 || dup2(i, 0) < 0) _exit(120);
        }
        if (drop_root && geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0)) _exit(121);
        std::vector<char*> cargs;
        for (std::string& a : argv) cargs.push_back(a.data());
        cargs.push_back(nullptr);
        execv(cargs[0], cargs.data());
        _exit(drop_root && errno == EACCES ? 123 : 122);
    }
    return pid;
}

/// Waits for the child; its status_code.
inline int wait_for(pid_t pid) {
    int status = 0;
    waitpid(pid, &status, 0);
    return status_code(status);
}

/// spawn_to_files, then wait_for.
inline int run_to_files(std::vector<std::string> argv, const std::filesystem::path& out,
                        const std::filesystem::path& err, bool stdin_null = false) {
    return wait_for(spawn_to_files(std::move(argv), out, err, stdin_null));
}

/// What a child printed and how it ended.
struct Captured {
    int code = -1;  ///< status_code
    std::string out, err;
};

/// Runs argv with stdin from /dev/null, stdout and stderr to DIR/TAG.out and
/// DIR/TAG.err (left there to look at after a failure), and waits for it.
Captured run_captured(std::vector<std::string> argv, const std::filesystem::path& dir, const std::string& tag = "r");

#ifdef ATONLAB_BINARY
/// `atonlab ARGS...`, the binary the test's build names, as run_captured.
inline Captured atonlab(std::vector<std::string> args, const std::filesystem::path& dir, const std::string& tag = "r") {
    args.insert(args.begin(), ATONLAB_BINARY);
    return run_captured(std::move(args), dir, tag);
}
#endif

}  // namespace atonlab::test
