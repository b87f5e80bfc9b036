// The `cie` glare model over a whole frame: the CIE glare spread
// function (CIE 135/1-1999) integrated over each pixel's solid angle, and the
// frame's convolution with it, by the direct sum or the FFT
// (veil_convolution.h; veiling_glare.h).
#include "atonlab/stimuli/veiling_glare.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "atonlab/stimuli/footprint.h"
#include "parallel.h"
#include "veil_convolution.h"

namespace atonlab::stimuli {

namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

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
    // Rows on every core (each pixel computed as it would be alone).
    detail::parallel_chunks(height, [&](int dy0, int dy1, int) {
        for (int dy = dy0; dy < dy1; ++dy)
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
    });
    return k;
}

struct VeilingGlare::Impl {
    int width = 0, height = 0;
    double focal_px = 0;
    CieObserver observer;
    bool ready = false;
    int builds = 0;
    VeilMethod last = VeilMethod::automatic;
    VeilKernelQuadrant quadrant;  // the kernel (the direct sum reads it)
    detail::VeilFft fft;          // its spectrum and plans (built on the first FFT frame)
    bool fft_ready = false;
    std::vector<double> omega;  // H*W pixel solid angles (sr)
    std::vector<double> plane;  // one channel's illuminances (lux), H*W
    std::vector<double> direct[3];

    void build(int w, int h, double f, const CieObserver& obs) {
        const CieGlareSpread gsf = cie_glare_spread(obs);  // validates the observer first
        ready = false;
        fft_ready = false;
        width = w;
        height = h;
        focal_px = f;
        observer = obs;
        quadrant = veil_kernel_quadrant(gsf, w, h, f);
        omega.resize(static_cast<std::size_t>(w) * h);
        for (int j = 0; j < h; ++j)
            for (int i = 0; i < w; ++i)
                omega[static_cast<std::size_t>(j) * w + i] = frame_pixel_solid_angle_sr(i, j, w, h, f);
        ready = true;
        ++builds;
    }

    glm::dvec3 apply_fft(std::vector<float>& rgba);
    glm::dvec3 apply_direct(std::vector<float>& rgba, const std::vector<detail::LitPixel>& lit, const glm::dvec3& in);
};

glm::dvec3 VeilingGlare::Impl::apply_fft(std::vector<float>& rgba) {
    if (!fft_ready) {
        fft.build(quadrant);
        fft_ready = true;
    }
    const std::size_t pixels = omega.size();
    plane.resize(pixels);
    glm::dvec3 outside{0.0};
    for (int c = 0; c < 3; ++c) {
        const auto uc = static_cast<std::size_t>(c);
        double in = 0;
        for (std::size_t p = 0; p < pixels; ++p) {
            const double e = static_cast<double>(rgba[4 * p + uc]) * omega[p];
            plane[p] = e;
            in += e;
        }
        if (!(in > 0)) continue;
        fft.convolve(plane);
        double out = 0;
        for (std::size_t p = 0; p < pixels; ++p) {
            // Rounding leaves ±1e-16 of the total where the true value is ~0: no negative light.
            const double e = std::max(0.0, plane[p]);
            out += e;
            rgba[4 * p + uc] = static_cast<float>(e / omega[p]);
        }
        outside[c] = std::clamp(1.0 - out / in, 0.0, 1.0);
    }
    return outside;
}

glm::dvec3 VeilingGlare::Impl::apply_direct(std::vector<float>& rgba, const std::vector<detail::LitPixel>& lit,
                                            const glm::dvec3& in) {
    detail::veil_direct_sum(quadrant, lit, direct);
    glm::dvec3 outside{0.0};
    for (int c = 0; c < 3; ++c) {
        if (!(in[c] > 0)) continue;  // as the FFT: a channel without energy stays as it is
        const auto uc = static_cast<std::size_t>(c);
        double out = 0;
        for (std::size_t p = 0; p < omega.size(); ++p) {
            const double e = direct[c][p];
            out += e;
            rgba[4 * p + uc] = static_cast<float>(e / omega[p]);
        }
        outside[c] = std::clamp(1.0 - out / in[c], 0.0, 1.0);
    }
    return outside;
}

VeilingGlare::VeilingGlare() : impl_(std::make_unique<Impl>()) {}
VeilingGlare::~VeilingGlare() = default;

int VeilingGlare::kernel_builds() const {
    return impl_->builds;
}

VeilMethod VeilingGlare::last_method() const {
    return impl_->last;
}

glm::dvec3 VeilingGlare::apply(std::vector<float>& rgba, int w, int h, double f, const CieObserver& obs,
                               VeilMethod method) {
    Impl& m = *impl_;
    if (!m.ready || m.width != w || m.height != h || m.focal_px != f || m.observer.age_years != obs.age_years ||
        m.observer.pigmentation != obs.pigmentation)
        m.build(w, h, f, obs);
    // The lit pixels, up to one more than the direct sum takes by default.
    std::vector<detail::LitPixel> lit;
    glm::dvec3 in{0.0};
    const std::size_t limit =
        method == VeilMethod::direct ? m.omega.size() : static_cast<std::size_t>(kVeilDirectMaxLitPixels);
    bool few = method != VeilMethod::fft;
    for (int j = 0; j < h && few; ++j)
        for (int i = 0; i < w; ++i) {
            const std::size_t p = static_cast<std::size_t>(j) * w + i;
            const glm::dvec3 e = glm::dvec3(rgba[4 * p], rgba[4 * p + 1], rgba[4 * p + 2]) * m.omega[p];
            if (e.r == 0 && e.g == 0 && e.b == 0) continue;
            if (lit.size() == limit) {
                few = false;
                break;
            }
            lit.push_back({i, j, {e.r, e.g, e.b}});
            in += e;
        }
    m.last = few ? VeilMethod::direct : VeilMethod::fft;
    return few ? m.apply_direct(rgba, lit, in) : m.apply_fft(rgba);
}

}  // namespace atonlab::stimuli
