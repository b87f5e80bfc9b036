#include "session/progress.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace atonlab::runner {

namespace p = atonlab::protocols;

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

std::string clock_text(double seconds) {
    const auto total = static_cast<long long>(std::llround(std::max(0.0, seconds)));
    if (total >= 3600) return fmt::format("{}:{:02}:{:02}", total / 3600, total / 60 % 60, total % 60);
    return fmt::format("{}:{:02}", total / 60, total % 60);
}

Progress::Progress(bool quiet, int every, std::optional<std::size_t> bound)
    : quiet_(quiet),
      tty_(isatty(STDOUT_FILENO) == 1),
      every_(every > 0 ? every : 25),
      bound_(bound),
      start_(std::chrono::steady_clock::now()) {}

void Progress::block(const p::Protocol& protocol, const p::ScheduledTrial& t, std::size_t runs, bool on_screen) {
    if (quiet_) return;
    end_line();
    const p::Block& b = protocol.blocks[t.block];
    std::printf("block \"%s\" (run %zu of %zu, repetition %d of %d): adaptation %s%s\n", b.name.c_str(), t.run + 1,
                runs, t.repetition + 1, b.repetitions, clock_text(b.adaptation_s).c_str(),
                on_screen ? "" : " simulated");
    std::fflush(stdout);
}

void Progress::trial(const p::Protocol& protocol, const p::ScheduledTrial& t, std::size_t committed) {
    ++done_here_;
    if (quiet_) return;
    const double elapsed = seconds();
    std::string line = fmt::format("{} · trial {}", protocol.blocks[t.block].name, committed);
    if (bound_) line += fmt::format(" of ≤ {}", *bound_);
    line += fmt::format(" · {} elapsed", clock_text(elapsed));
    if (bound_ && done_here_ > 0 && *bound_ > committed)
        line += fmt::format(" · ETA ≤ {}", clock_text(elapsed / static_cast<double>(done_here_) *
                                                      static_cast<double>(*bound_ - committed)));
    if (tty_) {
        std::printf("\r\x1b[K%s", line.c_str());
        open_line_ = true;
    } else if (committed % static_cast<std::size_t>(every_) == 0) {
        std::printf("%s\n", line.c_str());
    }
    std::fflush(stdout);
}

void Progress::end_line() {
    if (open_line_) std::printf("\n");
    open_line_ = false;
}

}  // namespace atonlab::runner
