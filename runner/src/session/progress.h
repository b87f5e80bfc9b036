#pragma once
// A session's progress on stdout: a line per block run and per trial (one line
// rewritten on a terminal, every Nth trial otherwise), with an ETA.
#include <chrono>
#include <cstddef>
#include <optional>
#include <string>

#include "atonlab/protocols/protocol.h"
#include "atonlab/protocols/protocol_schedule.h"

namespace atonlab::runner {

/// Seconds since t (steady clock).
double seconds_since(std::chrono::steady_clock::time_point t);

/// A duration as "M:SS", or "H:MM:SS" from an hour on.
std::string clock_text(double seconds);

class Progress {
public:
    Progress(bool quiet, int every, std::optional<std::size_t> bound);

    /// A block run begins (runs: how many the schedule has; on_screen: shown, not simulated).
    void block(const protocols::Protocol& protocol, const protocols::ScheduledTrial& t, std::size_t runs,
               bool on_screen);
    /// After trial `committed` (1-based count of the session's stored trials) is stored.
    void trial(const protocols::Protocol& protocol, const protocols::ScheduledTrial& t, std::size_t committed);

    void end_line();
    double seconds() const { return seconds_since(start_); }
    std::size_t done_here() const noexcept { return done_here_; }

private:
    bool quiet_;
    bool tty_;
    int every_;
    std::optional<std::size_t> bound_;
    std::chrono::steady_clock::time_point start_;
    std::size_t done_here_ = 0;
    bool open_line_ = false;
};

}  // namespace atonlab::runner
