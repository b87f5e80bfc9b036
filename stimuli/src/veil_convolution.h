#pragma once
// The two ways the `cie` veil (veiling_glare.h) convolves one channel of a
// frame's illuminances with the kernel K (issue 27 item 3):
//  - VeilFft: the linear convolution by FFTW in double, zero-padded to
//    mx × my ≥ (2W − 1) × (2H − 1), done as 1-D transforms so that the zero
//    rows are skipped (only the frame's H rows are transformed along x, and
//    only its H rows transformed back) and the rows and columns are shared
//    among the cores; plans made once per frame size and reused;
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

private:
    void destroy();
    int w_ = 0, h_ = 0, mx_ = 0, my_ = 0, cols_ = 0;
    double* rows_ = nullptr;          // h × mx reals (the frame's rows, padded along x)
    fftw_complex* spec_ = nullptr;    // my × cols (cols = mx/2 + 1)
    std::vector<double> kernel_hat_;  // my × cols: the kernel's spectrum (real: K is even in x and y)
    std::vector<fftw_plan> row_forward_, column_forward_, column_inverse_, row_inverse_;  // one per worker
    std::vector<int> row_chunk_, column_chunk_;  // worker t: [chunk[t], chunk[t + 1])
};

/// A pixel with light: its column i, row j and illuminance per channel (lux).
struct LitPixel {
    int i = 0, j = 0;
    double e[3] = {0, 0, 0};
};

/// The three channels by the direct sum: out[c] (h × w, lux) = Σ_p e_p[c] K(q − p)
/// over the lit pixels. `kernel` is the frame's quadrant (w × h).
void veil_direct_sum(const VeilKernelQuadrant& kernel, const std::vector<LitPixel>& lit, std::vector<double> (&out)[3]);

/// The smallest n ≥ m whose prime factors are 2, 3, 5 and 7 (FFTW's fast sizes).
int fftw_size_at_least(int m);

}  // namespace atonlab::stimuli::detail
