// The `cie` veil's two convolutions (veil_convolution.h): the pruned, parallel
// FFT and the direct sum over lit pixels.
#include "veil_convolution.h"

#include <algorithm>
#include <complex>
#include <cstdlib>
#include <new>
#include <stdexcept>

#include "fftw_planner.h"
#include "parallel.h"

namespace atonlab::stimuli::detail {

int fftw_size_at_least(int m) {
    // FFTW_ESTIMATE's plans run fastest, for the lengths a frame needs, on
    // lengths with a large power of two: per 1-D transform on the 2-core VM,
    // c2c 2160 = 2⁴·135 took 8.1 µs, 2304 = 2⁸·9 5.1 µs; r2c 3840 = 2⁸·15
    // 6.0 µs, 4096 4.1 µs (docs/bench.md "cie_veil_methods"). So: the smallest
    // 2^a · q ≥ m with q odd and at most 9 (at most 12.5% above m).
    int best = 0;
    for (int q : {1, 3, 5, 7, 9}) {
        int n = q;
        while (n < m) n *= 2;
        if (best == 0 || n < best) best = n;
    }
    return best;
}

namespace {

/// chunk[t] … chunk[t + 1] for t < workers: [0, count) in contiguous parts.
std::vector<int> chunks(int count, int workers) {
    std::vector<int> c(static_cast<std::size_t>(workers) + 1);
    for (int t = 0; t <= workers; ++t) c[static_cast<std::size_t>(t)] = count * t / workers;
    return c;
}

}  // namespace

VeilFft::~VeilFft() {
    destroy();
}

void VeilFft::destroy() {
    std::lock_guard lock(fftw_planner_mutex());
    for (fftw_plan* p : {&row_forward_, &row_inverse_, &column_forward_, &column_inverse_}) {
        if (*p) fftw_destroy_plan(*p);
        *p = nullptr;
    }
    for (fftw_complex* b : block_) fftw_free(b);
    block_.clear();
    fftw_free(rows_);
    fftw_free(spec_);
    rows_ = nullptr;
    spec_ = nullptr;
}

void VeilFft::build(const VeilKernelQuadrant& kernel) {
    destroy();
    w_ = kernel.width;
    h_ = kernel.height;
    mx_ = fftw_size_at_least(2 * w_ - 1);
    my_ = fftw_size_at_least(2 * h_ - 1);
    cols_ = mx_ / 2 + 1;
    half_ = my_ / 2 + 1;
    row_stride_ = (static_cast<std::size_t>(mx_) + 3) / 4 * 4;       // 4 doubles: 32 bytes
    spec_stride_ = (static_cast<std::size_t>(cols_) + 1) / 2 * 2;    // 2 complex doubles
    column_stride_ = (static_cast<std::size_t>(my_) + 1) / 2 * 2;
    const auto uh = static_cast<std::size_t>(h_), umy = static_cast<std::size_t>(my_);
    const auto ucols = static_cast<std::size_t>(cols_);
    const int workers = worker_count(h_);
    row_chunk_ = chunks(h_, workers);
    block_chunk_ = chunks((cols_ + kBlockColumns - 1) / kBlockColumns, workers);
    {
        std::lock_guard lock(fftw_planner_mutex());
        rows_ = fftw_alloc_real(uh * row_stride_);
        spec_ = fftw_alloc_complex(uh * spec_stride_);
        if (rows_ == nullptr || spec_ == nullptr) throw std::bad_alloc();
        for (int t = 0; t < workers; ++t) {
            block_.push_back(fftw_alloc_complex(column_stride_ * kBlockColumns));
            if (block_.back() == nullptr) throw std::bad_alloc();
        }
        // One 1-D plan per shape, run on every row and column by FFTW's
        // new-array execute (every row and column starts as aligned as the
        // first, which the plans were made on). FFTW_ESTIMATE: the same plan,
        // hence the same bits, every time and for every thread count.
        row_forward_ = fftw_plan_dft_r2c_1d(mx_, rows_, spec_, FFTW_ESTIMATE);
        row_inverse_ = fftw_plan_dft_c2r_1d(mx_, spec_, rows_, FFTW_ESTIMATE | FFTW_DESTROY_INPUT);
        fftw_complex* block = block_.front();
        column_forward_ = fftw_plan_dft_1d(my_, block, block, FFTW_FORWARD, FFTW_ESTIMATE);
        column_inverse_ = fftw_plan_dft_1d(my_, block, block, FFTW_BACKWARD, FFTW_ESTIMATE);
        for (fftw_plan p : {row_forward_, row_inverse_, column_forward_, column_inverse_})
            if (p == nullptr) throw std::runtime_error("FFTW could not plan the veil's transforms");
    }

    // The kernel with its centre at index (0, 0), negative offsets wrapped, by
    // one full 2-D transform (once per frame size and observer). K is even in
    // x and y, so its spectrum is real and even: only the real parts of the
    // frequencies 0 … my/2 along y are kept (the imaginary parts, and the
    // difference between ky and my − ky, are rounding, ≈ 1e-17 of the largest).
    std::vector<double> wrapped(umy * static_cast<std::size_t>(mx_), 0.0);
    for (int dy = -(h_ - 1); dy <= h_ - 1; ++dy)
        for (int dx = -(w_ - 1); dx <= w_ - 1; ++dx)
            wrapped[static_cast<std::size_t>((dy + my_) % my_) * static_cast<std::size_t>(mx_) +
                    static_cast<std::size_t>((dx + mx_) % mx_)] = kernel.at(std::abs(dx), std::abs(dy));
    std::vector<std::complex<double>> hat(umy * ucols);
    fftw_plan p;
    {
        std::lock_guard lock(fftw_planner_mutex());
        p = fftw_plan_dft_r2c_2d(my_, mx_, wrapped.data(), reinterpret_cast<fftw_complex*>(hat.data()), FFTW_ESTIMATE);
    }
    fftw_execute(p);
    count_cpu_ffts();
    {
        std::lock_guard lock(fftw_planner_mutex());
        fftw_destroy_plan(p);
    }
    // FFTW's inverse is unnormalised: the 1/(mx·my) goes into the kernel.
    const double norm = 1.0 / (static_cast<double>(mx_) * my_);
    const auto uhalf = static_cast<std::size_t>(half_);
    kernel_hat_.resize(ucols * uhalf);
    for (std::size_t c = 0; c < ucols; ++c)
        for (std::size_t y = 0; y < uhalf; ++y) kernel_hat_[c * uhalf + y] = hat[y * ucols + c].real() * norm;
}

// Columns first … first + kBlockColumns − 1 of spec_ (fewer at the right edge)
// along y, each into its own stretch of the worker's block (the frame's h rows,
// zeros below): transformed, multiplied by the kernel's spectrum, transformed
// back, and the frame's h rows copied back (the rest is the padding's wrap,
// never read).
void VeilFft::column_block(int worker, int first) {
    const auto umy = static_cast<std::size_t>(my_), uh = static_cast<std::size_t>(h_);
    const auto uhalf = static_cast<std::size_t>(half_), ld = spec_stride_, cs = column_stride_;
    const auto c0 = static_cast<std::size_t>(first);
    const std::size_t n = std::min<std::size_t>(kBlockColumns, static_cast<std::size_t>(cols_) - c0);
    fftw_complex* block = block_[static_cast<std::size_t>(worker)];
    for (std::size_t y = 0; y < uh; ++y) {
        const fftw_complex* src = spec_ + y * ld + c0;
        for (std::size_t b = 0; b < n; ++b) {
            block[b * cs + y][0] = src[b][0];
            block[b * cs + y][1] = src[b][1];
        }
    }
    for (std::size_t b = 0; b < n; ++b) {
        fftw_complex* col = block + b * cs;
        std::fill(&col[uh][0], &col[umy][0], 0.0);
        fftw_execute_dft(column_forward_, col, col);
        const double* k = &kernel_hat_[(c0 + b) * uhalf];
        for (std::size_t y = 0; y < uhalf; ++y) {
            col[y][0] *= k[y];
            col[y][1] *= k[y];
        }
        for (std::size_t y = uhalf; y < umy; ++y) {  // K̂ is even along y: frequency y is my − y's
            col[y][0] *= k[umy - y];
            col[y][1] *= k[umy - y];
        }
        fftw_execute_dft(column_inverse_, col, col);
    }
    for (std::size_t y = 0; y < uh; ++y) {
        fftw_complex* dst = spec_ + y * ld + c0;
        for (std::size_t b = 0; b < n; ++b) {
            dst[b][0] = block[b * cs + y][0];
            dst[b][1] = block[b * cs + y][1];
        }
    }
}

void VeilFft::convolve(std::vector<double>& e) {
    count_cpu_ffts(2);  // one forward and one inverse 2-D transform (rows and columns in stages below)
    const auto umx = static_cast<std::size_t>(mx_);
    const auto uw = static_cast<std::size_t>(w_);
    const int workers = static_cast<int>(block_.size());
    // Stage by stage, each worker on its own rows or column blocks: along x
    // over the frame's rows (the padding rows are zero, their transforms too),
    // along y block by block with the kernel's product between, back along x
    // for the frame's rows only.
    parallel_chunks(workers, [&](int t0, int t1, int) {
        for (int j = row_chunk_[static_cast<std::size_t>(t0)]; j < row_chunk_[static_cast<std::size_t>(t1)]; ++j) {
            const auto uj = static_cast<std::size_t>(j);
            double* row = rows_ + uj * row_stride_;
            std::copy_n(&e[uj * uw], uw, row);
            std::fill(row + uw, row + umx, 0.0);
            fftw_execute_dft_r2c(row_forward_, row, spec_ + uj * spec_stride_);
        }
    });
    parallel_chunks(workers, [&](int t0, int t1, int) {
        for (int t = t0; t < t1; ++t)
            for (int b = block_chunk_[static_cast<std::size_t>(t)]; b < block_chunk_[static_cast<std::size_t>(t) + 1];
                 ++b)
                column_block(t, b * kBlockColumns);
    });
    parallel_chunks(workers, [&](int t0, int t1, int) {
        for (int j = row_chunk_[static_cast<std::size_t>(t0)]; j < row_chunk_[static_cast<std::size_t>(t1)]; ++j) {
            const auto uj = static_cast<std::size_t>(j);
            double* row = rows_ + uj * row_stride_;
            fftw_execute_dft_c2r(row_inverse_, spec_ + uj * spec_stride_, row);
            std::copy_n(row, uw, &e[uj * uw]);
        }
    });
}

void veil_direct_sum(const VeilKernelQuadrant& kernel, const std::vector<LitPixel>& lit,
                     std::vector<double> (&out)[3]) {
    const int w = kernel.width, h = kernel.height;
    const auto uw = static_cast<std::size_t>(w);
    for (auto& o : out) o.assign(uw * static_cast<std::size_t>(h), 0.0);
    // Row by row of the output: each lit pixel adds its kernel row |j − p.j|,
    // read outwards from p.i (both directions contiguous in the quadrant).
    parallel_chunks(h, [&](int j0, int j1, int) {
        for (int j = j0; j < j1; ++j) {
            double* o[3];
            for (int c = 0; c < 3; ++c) o[c] = &out[c][static_cast<std::size_t>(j) * uw];
            for (const LitPixel& p : lit) {
                const double* k = &kernel.value[static_cast<std::size_t>(std::abs(j - p.j)) * uw];
                const double er = p.e[0], eg = p.e[1], eb = p.e[2];
                for (int i = 0; i < p.i; ++i) {
                    const double v = k[p.i - i];
                    o[0][i] += er * v;
                    o[1][i] += eg * v;
                    o[2][i] += eb * v;
                }
                for (int i = p.i; i < w; ++i) {
                    const double v = k[i - p.i];
                    o[0][i] += er * v;
                    o[1][i] += eg * v;
                    o[2][i] += eb * v;
                }
            }
        }
    });
}

}  // namespace atonlab::stimuli::detail
