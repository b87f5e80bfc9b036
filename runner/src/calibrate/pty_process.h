#pragma once
// A child process whose stdin, stdout and stderr are a pseudo-terminal, for
// programs that read single keys from their console (ArgyllCMS spotread reads
// its "take a reading" key with the terminal in raw mode, so a pipe will not do).
#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

namespace atonlab::runner {

class PtyProcess {
public:
    /// Starts argv[0] (looked up on PATH) in a new session with the pty as its
    /// controlling terminal, echo off. Throws std::runtime_error when no pty
    /// can be opened or the process cannot be forked.
    explicit PtyProcess(const std::vector<std::string>& argv);
    /// Ends the process group (SIGTERM, then SIGKILL after 1 s) and reaps it.
    ~PtyProcess();
    PtyProcess(const PtyProcess&) = delete;
    PtyProcess& operator=(const PtyProcess&) = delete;

    /// Sends the bytes to the process's terminal.
    void send(std::string_view bytes);

    enum class Wait { matched, exited, timed_out };
    /// Reads what the process prints into output() until `done(output())`
    /// holds, the process closes its terminal (exits), or the deadline passes.
    template <class Done>
    Wait read_until(Done&& done, std::chrono::steady_clock::time_point deadline) {
        for (;;) {
            if (done(output_)) return Wait::matched;
            if (closed_) return Wait::exited;
            if (!read_some(deadline)) return closed_ ? (done(output_) ? Wait::matched : Wait::exited) : Wait::timed_out;
        }
    }

    /// Everything printed since the last clear_output(), carriage returns removed.
    const std::string& output() const { return output_; }
    void clear_output() { output_.clear(); }
    /// Drops the first n characters of output() (what has been acted on).
    void consume(std::size_t n) { output_.erase(0, n); }

    /// Waits up to `wait` for the process to exit by itself; then ends it as
    /// the destructor does. Returns its exit status (128 + N for signal N).
    int finish(std::chrono::milliseconds wait);

private:
    /// One read of the pty, waiting at most until the deadline; false on timeout or end of output.
    bool read_some(std::chrono::steady_clock::time_point deadline);

    int master_ = -1;
    pid_t pid_ = -1;
    bool closed_ = false;
    int status_ = -1;
    std::string output_;
};

}  // namespace atonlab::runner
