#pragma once
// FFTW's planner is not thread-safe (FFTW manual §5.4, "Thread safety"); only
// fftw_execute is. Every plan creation and destruction in the library goes
// through this one lock (defined in fft.cpp). The transforms' counter lives
// here too.
#include <mutex>

namespace atonlab::stimuli::detail {

std::mutex& fftw_planner_mutex();

/// Adds n whole-image transforms to cpu_fft_count() (cpu_threads.h); called
/// where each 2-D transform runs.
void count_cpu_ffts(unsigned n = 1);

}  // namespace atonlab::stimuli::detail
