#pragma once
// The two ways the `cie` veil (veiling_glare.h) convolves one channel of a
// frame's illuminances with the kernel K (issue 27 item 3):
//  - VeilFft: the linear convolution by FFTW in double, zero-padded to
//    mx × my ≥ (2W − 1) × (2H − 1), done as 1-D transforms so that the zero
//    rows are skipped (only the frame's H rows are transformed along x, and
//    only its H rows transformed back) and the rows and columns are shared
//    among the cores; along y a few columns at a time, copied into a block
//    that stays in the core's cache for the forward transform, the kernel's
//    product and the inverse; one 1-D plan per transform shape (FFTW_ESTIMATE:
//    the same bits every time, for every thread count) on lengths FFTW_ESTIMATE
//    plans well (fftw_size_at_least); plans made once per frame size;
//  - veil_direct_sum: Σ over the lit pixels p of e(p) K(q − p) for every
//    pixel q, exact, O(W·H × lit pixels), rows shared among the cores.
#include <fftw3.h>

#include <vector>

#include "atonlab/stimuli/veiling_glare.h"

namespace atonlab::stimuli::detail {

class VeilFft {
public:
    VeilFft() = default;
    ~VeilFft();
    VeilFft(const VeilFft&) = delete;
    VeilFft& operator=(const VeilFft&) = delete;

    /// Plans for a w × h frame and the kernel's spectrum from its quadrant.
    void build(const VeilKernelQuadrant& kernel);
    /// e (h × w illuminances, row-major, lux) convolved with the kernel, in place.
    void convolve(std::vector<double>& e);

    /// Columns gathered together along y: a block of 8 columns of my complex
    /// doubles (288 KiB at 1080 rows, my = 2304) stays in a core's L2 cache.
    static constexpr int kBlockColumns = 8;

private:
    void destroy();
    void column_block(int worker, int first_column);
    int w_ = 0, h_ = 0, mx_ = 0, my_ = 0, cols_ = 0, half_ = 0;
    /// Row strides (elements) of rows_ and spec_: every row starts on a 32-byte
    /// boundary, as the arrays the plans were measured on (FFTW's new-array execute).
    std::size_t row_stride_ = 0, spec_stride_ = 0, column_stride_ = 0;  // column_stride_: in a block
    double* rows_ = nullptr;        // h rows of mx reals (the frame's rows, padded along x)
    fftw_complex* spec_ = nullptr;  // h rows of cols = mx/2 + 1: the frame's rows transformed along x
    /// The kernel's spectrum, real (K is even in x and y) and even along y:
    /// column c's frequencies 0 … my/2 at [c · half, (c + 1) · half), half = my/2 + 1.
    std::vector<double> kernel_hat_;
    /// One row r2c and c2r, one column forward and back.
    fftw_plan row_forward_ = nullptr, row_inverse_ = nullptr, column_forward_ = nullptr, column_inverse_ = nullptr;
    std::vector<fftw_complex*> block_;          // one per worker: kBlockColumns columns of my, each contiguous
    std::vector<int> row_chunk_, block_chunk_;  // worker t: [chunk[t], chunk[t + 1]) rows or column blocks
};

/// A pixel with light: its column i, row j and illuminance per channel (lux).
struct LitPixel {
    int i = 0, j = 0;
    double e[3] = {0, 0, 0};
};

/// The three channels by the direct sum: out[c] (h × w, lux) = Σ_p e_p[c] K(q − p)
/// over the lit pixels. `kernel` is the frame's quadrant (w × h).
void veil_direct_sum(const VeilKernelQuadrant& kernel, const std::vector<LitPixel>& lit, std::vector<double> (&out)[3]);

/// The transform length for m samples: the smallest 2^a · q ≥ m, q ∈ {1, 3, 5, 7, 9}
/// (the lengths FFTW_ESTIMATE's plans run fastest).
int fftw_size_at_least(int m);

}  // namespace atonlab::stimuli::detail
