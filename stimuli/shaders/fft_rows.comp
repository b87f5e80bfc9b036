// One pass of the 2D forward FFT (fft.cpp, GpuFft): a radix-2 decimation-in-time
// transform of every row of an n×n complex image in place, or of every column
// when FFT_COLUMNS is defined. One workgroup owns one line, held in shared memory
// for all log2(n) stages, so each pass reads and writes the SSBO once.
//
//   X[k] = Σ_x x[n] e^{-2πi k·x/N}  (forward, unnormalised, origin at index 0)
//
// Defines (prepended by GpuFft):
//   FFT_N        line length, a power of two as a uint literal (16u ... 2048u;
//                up to 4096u for the veil where shared memory allows)
//   FFT_LOG2N    log2(FFT_N) as a uint literal
//   FFT_THREADS  workgroup size; a divisor of FFT_N / 2
//   FFT_COLUMNS  transform columns (stride FFT_PITCH) instead of rows (stride 1)
//   FFT_PITCH    the image's row length as a uint literal (default FFT_N; a
//                rectangular image, veil_gpu.cpp, transforms its columns of
//                length FFT_N = its height with the pitch of its width)
//   FFT_TWIDDLE_TABLE   twiddles from binding 1, W_N^k for k < N/2, computed in
//                       double on the CPU and rounded once to float
//   FFT_TWIDDLE_SINCOS  twiddles from fp32 cos()/sin() here (driver accuracy)
layout(local_size_x = FFT_THREADS) in;

layout(std430, binding = 0) buffer Data { vec2 data[]; };  // (re, im), row-major
#ifdef FFT_TWIDDLE_TABLE
layout(std430, binding = 1) readonly buffer Twiddles { vec2 twiddles[]; };
#endif

#ifndef FFT_PITCH
#define FFT_PITCH FFT_N
#endif

shared vec2 line_values[FFT_N];

/// W_N^k = e^{-2πik/N} for 0 <= k < N/2.
vec2 twiddle(uint k) {
#ifdef FFT_TWIDDLE_TABLE
    return twiddles[k];
#else
    // k / N is exact in fp32 (N a power of two); the product with 2π rounds once.
    const float angle = -6.28318530717958647692 * (float(k) / float(FFT_N));
    return vec2(cos(angle), sin(angle));
#endif
}

vec2 complex_mul(vec2 a, vec2 b) { return vec2(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x); }

void main() {
    const uint tid = gl_LocalInvocationID.x;
#ifdef FFT_COLUMNS
    const uint base = gl_WorkGroupID.x;
    const uint stride = FFT_PITCH;
#else
    const uint base = gl_WorkGroupID.x * FFT_PITCH;
    const uint stride = 1u;
#endif

    // Load in bit-reversed order so the in-place DIT stages write natural order.
    for (uint i = tid; i < FFT_N; i += uint(FFT_THREADS))
        line_values[bitfieldReverse(i) >> (32u - FFT_LOG2N)] = data[base + i * stride];
    memoryBarrierShared();
    barrier();

    // Stage s combines pairs of length-m transforms (m = 2^s) into length 2m:
    //   X[k] = E[k] + W_2m^k O[k],  X[k + m] = E[k] - W_2m^k O[k],  W_2m^k = W_N^(k N/2m).
    for (uint s = 0u; s < FFT_LOG2N; ++s) {
        const uint m = 1u << s;
        for (uint j = tid; j < FFT_N / 2u; j += uint(FFT_THREADS)) {
            const uint k = j & (m - 1u);
            const uint i0 = ((j >> s) << (s + 1u)) + k;
            const uint i1 = i0 + m;
            const vec2 t = complex_mul(twiddle(k << (FFT_LOG2N - 1u - s)), line_values[i1]);
            const vec2 u = line_values[i0];
            line_values[i0] = u + t;
            line_values[i1] = u - t;
        }
        memoryBarrierShared();
        barrier();
    }

    for (uint i = tid; i < FFT_N; i += uint(FFT_THREADS)) data[base + i * stride] = line_values[i];
}
