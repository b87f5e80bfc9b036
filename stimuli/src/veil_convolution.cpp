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
    for (int n = std::max(m, 1);; ++n) {
        int r = n;
        for (int p : {2, 3, 5, 7})
            while (r % p == 0) r /= p;
        if (r == 1) return n;
    }
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
    for (auto* plans : {&row_forward_, &column_forward_, &column_inverse_, &row_inverse_}) {
        for (fftw_plan p : *plans)
            if (p) fftw_destroy_plan(p);
        plans->clear();
    }
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
    const auto spec_count = static_cast<std::size_t>(my_) * static_cast<std::size_t>(cols_);
    const int workers = worker_count(h_);
    row_chunk_ = chunks(h_, workers);
    column_chunk_ = chunks(cols_, workers);
    {
        std::lock_guard lock(fftw_planner_mutex());
        rows_ = fftw_alloc_real(static_cast<std::size_t>(h_) * static_cast<std::size_t>(mx_));
        spec_ = fftw_alloc_complex(spec_count);
        if (rows_ == nullptr || spec_ == nullptr) throw std::bad_alloc();
        // One plan per worker over its own rows or columns, made once for this
        // frame size (FFTW_ESTIMATE: the same plan, hence the same bits, every time).
        for (int t = 0; t < workers; ++t) {
            const int r0 = row_chunk_[static_cast<std::size_t>(t)],
                      rn = row_chunk_[static_cast<std::size_t>(t) + 1] - r0;
            const int c0 = column_chunk_[static_cast<std::size_t>(t)],
                      cn = column_chunk_[static_cast<std::size_t>(t) + 1] - c0;
            double* rows = rows_ + static_cast<std::ptrdiff_t>(r0) * mx_;
            fftw_complex* spec_rows = spec_ + static_cast<std::ptrdiff_t>(r0) * cols_;
            fftw_complex* spec_cols = spec_ + c0;
            row_forward_.push_back(fftw_plan_many_dft_r2c(1, &mx_, rn, rows, nullptr, 1, mx_, spec_rows, nullptr, 1,
                                                          cols_, FFTW_ESTIMATE));
            column_forward_.push_back(fftw_plan_many_dft(1, &my_, cn, spec_cols, nullptr, cols_, 1, spec_cols, nullptr,
                                                         cols_, 1, FFTW_FORWARD, FFTW_ESTIMATE));
            column_inverse_.push_back(fftw_plan_many_dft(1, &my_, cn, spec_cols, nullptr, cols_, 1, spec_cols, nullptr,
                                                         cols_, 1, FFTW_BACKWARD, FFTW_ESTIMATE));
            row_inverse_.push_back(fftw_plan_many_dft_c2r(1, &mx_, rn, spec_rows, nullptr, 1, cols_, rows, nullptr, 1,
                                                          mx_, FFTW_ESTIMATE | FFTW_DESTROY_INPUT));
        }
        for (auto* plans : {&row_forward_, &column_forward_, &column_inverse_, &row_inverse_})
            for (fftw_plan p : *plans)
                if (p == nullptr) throw std::runtime_error("FFTW could not plan the veil's transforms");
    }

    // The kernel with its centre at index (0, 0), negative offsets wrapped, by
    // one full 2-D transform (once per frame size and observer). K is even in
    // x and y, so its spectrum is real: only the real parts are kept (the
    // imaginary parts are rounding, ≈ 1e-17 of the largest).
    std::vector<double> wrapped(static_cast<std::size_t>(my_) * static_cast<std::size_t>(mx_), 0.0);
    for (int dy = -(h_ - 1); dy <= h_ - 1; ++dy)
        for (int dx = -(w_ - 1); dx <= w_ - 1; ++dx)
            wrapped[static_cast<std::size_t>((dy + my_) % my_) * static_cast<std::size_t>(mx_) +
                    static_cast<std::size_t>((dx + mx_) % mx_)] = kernel.at(std::abs(dx), std::abs(dy));
    std::vector<std::complex<double>> hat(spec_count);
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
    kernel_hat_.resize(spec_count);
    for (std::size_t i = 0; i < spec_count; ++i) kernel_hat_[i] = hat[i].real() * norm;
}

void VeilFft::convolve(std::vector<double>& e) {
    count_cpu_ffts(2);  // one forward and one inverse 2-D transform (rows and columns in stages below)
    const auto umx = static_cast<std::size_t>(mx_), ucols = static_cast<std::size_t>(cols_);
    const auto uw = static_cast<std::size_t>(w_);
    const int workers = static_cast<int>(row_forward_.size());
    // Stage by stage, each worker on its own rows or columns: along x over the
    // frame's rows (the padding rows are zero, their transforms too), along y
    // over every column with the kernel's product between, back along x for
    // the frame's rows only.
    parallel_chunks(workers, [&](int t0, int t1, int) {
        for (int t = t0; t < t1; ++t) {
            const int r0 = row_chunk_[static_cast<std::size_t>(t)], r1 = row_chunk_[static_cast<std::size_t>(t) + 1];
            for (int j = r0; j < r1; ++j) {
                double* row = rows_ + static_cast<std::size_t>(j) * umx;
                std::copy_n(&e[static_cast<std::size_t>(j) * uw], uw, row);
                std::fill(row + uw, row + umx, 0.0);
            }
            fftw_execute(row_forward_[static_cast<std::size_t>(t)]);
        }
    });
    std::fill(reinterpret_cast<double*>(spec_ + static_cast<std::ptrdiff_t>(h_) * cols_),
              reinterpret_cast<double*>(spec_ + static_cast<std::ptrdiff_t>(my_) * cols_), 0.0);
    parallel_chunks(workers, [&](int t0, int t1, int) {
        for (int t = t0; t < t1; ++t) {
            fftw_execute(column_forward_[static_cast<std::size_t>(t)]);
            const auto c0 = static_cast<std::size_t>(column_chunk_[static_cast<std::size_t>(t)]);
            const auto c1 = static_cast<std::size_t>(column_chunk_[static_cast<std::size_t>(t) + 1]);
            for (std::size_t y = 0; y < static_cast<std::size_t>(my_); ++y)
                for (std::size_t c = c0; c < c1; ++c) {
                    const double k = kernel_hat_[y * ucols + c];
                    spec_[y * ucols + c][0] *= k;
                    spec_[y * ucols + c][1] *= k;
                }
            fftw_execute(column_inverse_[static_cast<std::size_t>(t)]);
        }
    });
    parallel_chunks(workers, [&](int t0, int t1, int) {
        for (int t = t0; t < t1; ++t) {
            fftw_execute(row_inverse_[static_cast<std::size_t>(t)]);
            const int r0 = row_chunk_[static_cast<std::size_t>(t)], r1 = row_chunk_[static_cast<std::size_t>(t) + 1];
            for (int j = r0; j < r1; ++j)
                std::copy_n(rows_ + static_cast<std::size_t>(j) * umx, uw, &e[static_cast<std::size_t>(j) * uw]);
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
