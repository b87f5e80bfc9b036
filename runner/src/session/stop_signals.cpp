#include "atonlab/runner/session/stop_signals.h"

namespace atonlab::runner {

namespace {

volatile std::sig_atomic_t g_stop_signal = 0;

extern "C" void on_stop_signal(int signal_number) {
    g_stop_signal = signal_number;
}

}  // namespace

int stop_signal() noexcept {
    return g_stop_signal;
}

void request_stop(int signal_number) noexcept {
    g_stop_signal = signal_number;
}

StopSignals::StopSignals() {
    g_stop_signal = 0;
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sa.sa_flags = SA_RESTART;  // a write or fsync of the study file is not cut short
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
}

void StopSignals::restore() {
    if (restored_) return;
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
    restored_ = true;
}

}  // namespace atonlab::runner
