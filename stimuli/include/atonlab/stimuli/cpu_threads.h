#pragma once
// How many threads the CPU glare paths use (issue 27 item 3: the PSF's anchors
// and bands, the `cie` veil's kernel, FFTs and direct sums). Results do not
// depend on it (each item is computed as it would be alone); the bench sets it
// to compare one core with all of them.
#include <cstdint>

namespace atonlab::stimuli {

/// At most n threads; 0 (the default): one per core the machine reports.
void set_cpu_threads(int n);
/// The limit set (0: one per core).
int cpu_threads();

/// Whole-image Fourier transforms the CPU has run in this process (FFTW: each
/// forward or inverse 2-D transform of one channel counts once, whatever its
/// size or precision). The simulator-frame bench reports it per frame
/// (docs/bench.md "simulator_frames"); GPU transforms are not counted.
std::uint64_t cpu_fft_count();

}  // namespace atonlab::stimuli
