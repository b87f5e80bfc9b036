#pragma once
// SIGINT / SIGTERM during a session: a flag checked between trials. The trial
// being shown is finished and committed; then the session is marked "quit".

#include <csignal>

namespace atonlab::runner {

/// The signal that asked the session to stop, 0 while none has.
int stop_signal() noexcept;
/// Asks the session to stop as signal `signal_number` would (the Python
/// module's KeyboardInterrupt, RunOptions::after_trial): the trial being shown
/// is finished and committed first.
void request_stop(int signal_number) noexcept;

/// Installs the handlers for its lifetime (the flag is cleared first).
class StopSignals {
public:
    StopSignals();
    ~StopSignals() { restore(); }
    StopSignals(const StopSignals&) = delete;
    StopSignals& operator=(const StopSignals&) = delete;
    /// Back to what was there (after the last trial, a signal ends the summary at once).
    void restore();

private:
    struct sigaction old_int_ {};
    struct sigaction old_term_ {};
    bool restored_ = false;
};

}  // namespace atonlab::runner
