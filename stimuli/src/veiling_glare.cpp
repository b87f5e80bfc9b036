// The `cie` glare model over a whole frame: the CIE glare spread
// function (CIE 135/1-1999) integrated over each pixel's solid angle, and the frame-sized linear
// convolution by FFTW (veiling_glare.h).
#include "atonlab/stimuli/veiling_glare.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "atonlab/stimuli/footprint.h"

namespace atonlab::stimuli {

namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

/// The smallest n ≥ m whose prime factors are 2, 3, 5 and 7 (FFTW's fast sizes).
int fftw_size_at_least(int m) {
    for (int n = std::max(m, 1);; ++n) {
        int r = n;
        for (int p : {2, 3, 5, 7})
            while (r % p == 0) r /= p;
        if (r == 1) return n;
    }
}

/// GSF per px² of the image plane at (x, y) px from the principal point: the
/// density (sr⁻¹) times the pinhole's dΩ/dA = f / (f² + r²)^{3/2}.
double density_per_px2(const CieGlareSpread& gsf, double x, double y, double f) {
    const double r2 = x * x + y * y;
    const double theta_deg = std::atan(std::sqrt(r2) / f) * kRadToDeg;
    const double q = f * f + r2;
    return gsf.density_sr(theta_deg) * f / (q * std::sqrt(q));
}

/// Midpoint rule with s×s samples over the pixel square centred at (cx, cy);
/// `skip_inside` leaves out the samples within that radius (px) of the origin.
double pixel_quadrature(const CieGlareSpread& gsf, double cx, double cy, double f, int s, double skip_inside = 0.0) {
    double sum = 0;
    const double step = 1.0 / s;
    for (int b = 0; b < s; ++b) {
        const double y = cy - 0.5 + (b + 0.5) * step;
        for (int a = 0; a < s; ++a) {
            const double x = cx - 0.5 + (a + 0.5) * step;
            if (skip_inside > 0 && x * x + y * y < skip_inside * skip_inside) continue;
            sum += density_per_px2(gsf, x, y, f);
        }
    }
    return sum * step * step;
}

}  // namespace

double frame_pixel_solid_angle_sr(int i, int j, int width, int height, double focal_px) {
    return pixel_solid_angle_sr(i - 0.5 * width, j - 0.5 * height, focal_px);
}

VeilKernelQuadrant veil_kernel_quadrant(const CieGlareSpread& gsf, int width, int height, double f) {
    VeilKernelQuadrant k;
    k.width = width;
    k.height = height;
    k.value.assign(static_cast<std::size_t>(width) * height, 0.0);
    for (int dy = 0; dy < height; ++dy)
        for (int dx = 0; dx < width; ++dx) {
            double e;
            if (dx == 0 && dy == 0) {
                // The central pixel holds the steep core (the 0.0046° term): its
                // inscribed disc, a cone of half-angle atan(0.5/f), exactly by the
                // 1-D integral; the four corners by a fine midpoint rule.
                e = cie_energy_between(gsf, 0.0, std::atan(0.5 / f) * kRadToDeg) +
                    pixel_quadrature(gsf, 0.0, 0.0, f, 256, 0.5);
            } else {
                // Samples per axis: the GSF falls like θ⁻² … θ⁻³, so the midpoint
                // rule's relative error is about 0.5 / (r s)² (r in px): below
                // 1e-4 everywhere with these steps.
                const double r = std::hypot(dx, dy);
                const int s = r < 2 ? 64 : r < 4 ? 32 : r < 16 ? 8 : r < 64 ? 2 : 1;
                e = pixel_quadrature(gsf, dx, dy, f, s);
            }
            k.value[static_cast<std::size_t>(dy) * width + dx] = e;
        }
    return k;
}

struct VeilingGlare::Impl {
    int width = 0, height = 0;
    double focal_px = 0;
    CieObserver observer;
    bool ready = false;
    int builds = 0;
    int mx = 0, my = 0;  // padded sizes (≥ 2W − 1, 2H − 1)
    std::vector<double> real;
    std::vector<std::complex<double>> kernel_hat, work;
    std::vector<double> omega;  // H*W pixel solid angles (sr)
    fftw_plan forward = nullptr, inverse = nullptr;

    ~Impl() { destroy_plans(); }
    void destroy_plans() {
        if (forward) fftw_destroy_plan(forward);
        if (inverse) fftw_destroy_plan(inverse);
        forward = inverse = nullptr;
    }
    static fftw_complex* as_fftw(std::vector<std::complex<double>>& v) {
        // std::complex<double> is layout-compatible with fftw_complex (FFTW manual §4.1.1).
        return reinterpret_cast<fftw_complex*>(v.data());
    }

    void build(int w, int h, double f, const CieObserver& obs) {
        const CieGlareSpread gsf = cie_glare_spread(obs);  // validates the observer first
        ready = false;
        destroy_plans();
        width = w;
        height = h;
        focal_px = f;
        observer = obs;
        mx = fftw_size_at_least(2 * w - 1);
        my = fftw_size_at_least(2 * h - 1);
        const std::size_t cols = static_cast<std::size_t>(mx / 2 + 1);
        real.assign(static_cast<std::size_t>(mx) * my, 0.0);
        kernel_hat.assign(cols * my, {0.0, 0.0});
        work.assign(kernel_hat.size(), {0.0, 0.0});
        forward = fftw_plan_dft_r2c_2d(my, mx, real.data(), as_fftw(work), FFTW_ESTIMATE);
        inverse = fftw_plan_dft_c2r_2d(my, mx, as_fftw(work), real.data(), FFTW_ESTIMATE);

        const VeilKernelQuadrant q = veil_kernel_quadrant(gsf, w, h, f);
        // The kernel with its centre at index (0, 0), negative offsets wrapped.
        for (int dy = -(h - 1); dy <= h - 1; ++dy)
            for (int dx = -(w - 1); dx <= w - 1; ++dx)
                real[static_cast<std::size_t>((dy + my) % my) * mx + (dx + mx) % mx] = q.at(std::abs(dx), std::abs(dy));
        fftw_execute_dft_r2c(forward, real.data(), as_fftw(kernel_hat));

        omega.resize(static_cast<std::size_t>(w) * h);
        for (int j = 0; j < h; ++j)
            for (int i = 0; i < w; ++i)
                omega[static_cast<std::size_t>(j) * w + i] = frame_pixel_solid_angle_sr(i, j, w, h, f);
        ready = true;
        ++builds;
    }
};

VeilingGlare::VeilingGlare() : impl_(std::make_unique<Impl>()) {}
VeilingGlare::~VeilingGlare() = default;

int VeilingGlare::kernel_builds() const {
    return impl_->builds;
}

glm::dvec3 VeilingGlare::apply(std::vector<float>& rgba, int w, int h, double f, const CieObserver& obs) {
    Impl& m = *impl_;
    if (!m.ready || m.width != w || m.height != h || m.focal_px != f || m.observer.age_years != obs.age_years ||
        m.observer.pigmentation != obs.pigmentation)
        m.build(w, h, f, obs);
    const double norm = 1.0 / (static_cast<double>(m.mx) * m.my);  // FFTW's c2r is unnormalised
    glm::dvec3 outside{0.0};
    for (int c = 0; c < 3; ++c) {
        std::fill(m.real.begin(), m.real.end(), 0.0);
        double in = 0;
        for (int j = 0; j < h; ++j)
            for (int i = 0; i < w; ++i) {
                const std::size_t p = static_cast<std::size_t>(j) * w + i;
                const double e = static_cast<double>(rgba[4 * p + static_cast<std::size_t>(c)]) * m.omega[p];
                m.real[static_cast<std::size_t>(j) * m.mx + i] = e;
                in += e;
            }
        if (!(in > 0)) continue;
        fftw_execute_dft_r2c(m.forward, m.real.data(), Impl::as_fftw(m.work));
        for (std::size_t t = 0; t < m.work.size(); ++t) m.work[t] *= m.kernel_hat[t];
        fftw_execute_dft_c2r(m.inverse, Impl::as_fftw(m.work), m.real.data());
        double out = 0;
        for (int j = 0; j < h; ++j)
            for (int i = 0; i < w; ++i) {
                const std::size_t p = static_cast<std::size_t>(j) * w + i;
                // Rounding leaves ±1e-16 of the total where the true value is ~0: no negative light.
                const double e = std::max(0.0, m.real[static_cast<std::size_t>(j) * m.mx + i] * norm);
                out += e;
                rgba[4 * p + static_cast<std::size_t>(c)] = static_cast<float>(e / m.omega[p]);
            }
        outside[c] = std::clamp(1.0 - out / in, 0.0, 1.0);
    }
    return outside;
}

}  // namespace atonlab::stimuli
