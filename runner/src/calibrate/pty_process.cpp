#include "pty_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/ioctl.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace atonlab::runner {
namespace {

int status_code(int status) {
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
    return -1;
}

}  // namespace

PtyProcess::PtyProcess(const std::vector<std::string>& argv) {
    master_ = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (master_ < 0 || grantpt(master_) != 0 || unlockpt(master_) != 0) {
        if (master_ >= 0) ::close(master_);
        throw std::runtime_error(std::string("no pseudo-terminal can be opened: ") + std::strerror(errno));
    }
    const char* slave_name = ptsname(master_);
    if (!slave_name) {
        ::close(master_);
        throw std::runtime_error("no pseudo-terminal name");
    }
    const std::string slave_path = slave_name;
    // Built before fork: the child only calls async-signal-safe functions.
    std::vector<std::string> args = argv;
    std::vector<char*> cargs;
    for (std::string& a : args) cargs.push_back(a.data());
    cargs.push_back(nullptr);
    pid_ = fork();
    if (pid_ < 0) {
        ::close(master_);
        throw std::runtime_error(std::string("cannot start a process: ") + std::strerror(errno));
    }
    if (pid_ == 0) {
        setsid();
        const int slave = ::open(slave_path.c_str(), O_RDWR);
        if (slave < 0) _exit(126);
        ioctl(slave, TIOCSCTTY, 0);
        termios t{};
        if (tcgetattr(slave, &t) == 0) {
            t.c_lflag &= ~static_cast<tcflag_t>(ECHO);
            tcsetattr(slave, TCSANOW, &t);
        }
        dup2(slave, 0);
        dup2(slave, 1);
        dup2(slave, 2);
        // Nothing else of atonlab's (the study file, the GL device) reaches the child.
        closefrom(3);
        execvp(cargs[0], cargs.data());
        _exit(127);
    }
}

PtyProcess::~PtyProcess() {
    finish(std::chrono::milliseconds(0));
}

void PtyProcess::send(std::string_view bytes) {
    while (!bytes.empty() && !closed_) {
        const ssize_t n = ::write(master_, bytes.data(), bytes.size());
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return;  // the process has gone; the next read sees it
        bytes.remove_prefix(static_cast<std::size_t>(n));
    }
}

bool PtyProcess::read_some(std::chrono::steady_clock::time_point deadline) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    pollfd p{master_, POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (ready < 0 && errno == EINTR) return true;
    if (ready == 0) return std::chrono::steady_clock::now() < deadline;
    char buf[4096];
    const ssize_t n = ::read(master_, buf, sizeof buf);
    if (n <= 0) {  // EIO: every slave descriptor is closed (the process exited)
        if (n < 0 && errno == EINTR) return true;
        closed_ = true;
        return false;
    }
    for (ssize_t i = 0; i < n; ++i)
        if (buf[i] != '\r') output_ += buf[i];
    return true;
}

int PtyProcess::finish(std::chrono::milliseconds wait) {
    if (pid_ > 0) {
        // Exited, not yet reaped (WNOWAIT): its process group id cannot be reused
        // until it is, so the group can be ended safely first.
        auto exited = [&] {
            siginfo_t info{};
            return waitid(P_PID, static_cast<id_t>(pid_), &info, WEXITED | WNOHANG | WNOWAIT) == 0 &&
                   info.si_pid == pid_;
        };
        auto wait_up_to = [&](std::chrono::milliseconds ms) {
            const auto until = std::chrono::steady_clock::now() + ms;
            while (!exited() && std::chrono::steady_clock::now() < until)
                std::this_thread::sleep_for(std::chrono::milliseconds(10));
            return exited();
        };
        if (!wait_up_to(wait)) {
            kill(-pid_, SIGTERM);
            if (!wait_up_to(std::chrono::milliseconds(1000))) kill(-pid_, SIGKILL);
        }
        // Whatever the process started in its group (a shell's sleep) goes with it.
        kill(-pid_, SIGKILL);
        int status = 0;
        status_ = waitpid(pid_, &status, 0) == pid_ ? status_code(status) : -1;
        pid_ = -1;
    }
    if (master_ >= 0) {
        ::close(master_);
        master_ = -1;
        closed_ = true;
    }
    return status_;
}

}  // namespace atonlab::runner
