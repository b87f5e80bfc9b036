#pragma once
// FFTW's planner is not thread-safe (FFTW manual §5.4, "Thread safety"); only
// fftw_execute is. Every plan creation and destruction in the library goes
// through this one lock (defined in fft.cpp).
#include <mutex>

namespace atonlab::stimuli::detail {

std::mutex& fftw_planner_mutex();

}  // namespace atonlab::stimuli::detail
