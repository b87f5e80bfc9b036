#pragma once
// The pieces of the GPU FFT (fft.cpp, shaders/fft_rows.comp) that another
// transform of the library builds on: the `cie` veil's rectangular, padded
// images (veil_gpu.cpp) use the same line passes and twiddle table as GpuFft.
#include <vector>

#include "atonlab/stimuli/fft.h"
#include "atonlab/stimuli/gl/objects.h"

namespace atonlab::stimuli::detail {

/// fft_rows.comp transforming lines of n points (a power of two) in place:
/// rows of an image of `pitch` points per row, or its columns (stride pitch).
/// One workgroup per line; its data at storage binding 0, the twiddle table
/// (table_from_double) at binding 1.
gl::Program fft_line_program(int n, int pitch, bool columns, TwiddleSource twiddles);

/// W_N^k = e^{-2πik/N} = (cos, -sin)(2πk/N) for k < N/2, evaluated in double
/// and rounded once to float: n floats (n/2 vec2).
std::vector<float> fft_twiddle_table(int n);

}  // namespace atonlab::stimuli::detail
