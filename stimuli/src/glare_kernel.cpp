#include "atonlab/stimuli/glare_kernel.h"

#include <fftw3.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <mutex>
#include <numbers>

#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/footprint.h"
#include "fftw_planner.h"

namespace atonlab::stimuli {

namespace {

constexpr int kMaxKernelSize = kMaxGlareKernelPx;

}  // namespace

int glare_kernel_size_px(double pixels_per_degree, double radius_deg) {
    if (!(radius_deg > 0) || !std::isfinite(radius_deg))
        throw InputError(SourceLocation{"", 0, 0, "radius_deg"},
                         fmt::format("the glare billboard radius must be positive, not {} degrees.", radius_deg));
    if (!(pixels_per_degree > 0) || !std::isfinite(pixels_per_degree))
        throw InputError(
            SourceLocation{"", 0, 0, "pixels_per_degree"},
            fmt::format("the display must have a positive number of pixels per degree, not {}.", pixels_per_degree));
    const double size = glare_kernel_width_px(pixels_per_degree, radius_deg);
    if (size > kMaxKernelSize)
        throw InputError(SourceLocation{"", 0, 0, "radius_deg"},
                         fmt::format("a glare billboard of {} degrees is {} pixels wide at {:.1f} pixels per degree; "
                                     "the limit is {} pixels.",
                                     radius_deg, size, pixels_per_degree, kMaxKernelSize));
    return static_cast<int>(size);
}

double glare_kernel_width_px(double pixels_per_degree, double radius_deg) {
    return 2.0 * std::ceil(radius_deg * pixels_per_degree) + 1.0;
}

namespace {

// Applies the window at R, reports the cut against `total`, renormalises each channel.
// A channel the spectrum has (next to) no light in (its RGB clipped at 0: a red LED has
// no green or blue in Rec.709, but for a few aliased texels far out) takes the
// luminance's distribution, so a light whose displayed colour has some of that channel
// (red-optimum's blue, docs/glare.md "The light's spectrum") still spreads all of it.
void window_and_normalise(GlareKernel& k, const std::vector<glm::dvec3>& energy, glm::dvec3 total, GlareWindow window) {
    const int m = k.size, h = k.half();
    glm::dvec3 kept{0.0};
    std::vector<glm::dvec3> windowed(energy.size());
    for (int j = 0; j < m; ++j)
        for (int i = 0; i < m; ++i) {
            const double rho = std::hypot(i - h, j - h) / k.radius_px;
            const std::size_t idx = static_cast<std::size_t>(j) * m + i;
            windowed[idx] = energy[idx] * glare_window_weight(window, rho);
            kept += windowed[idx];
        }
    k.rgba.assign(energy.size(), glm::vec4(0.0f));
    const double kept_luminance = display::luminance_of_linear_rgb(kept);
    for (int c = 0; c < 3; ++c) {
        k.window_cut[c] = total[c] > 0 ? std::clamp(1.0 - kept[c] / total[c], 0.0, 1.0) : 0.0;
        glm::dvec3 unit(0.0);
        unit[c] = 1.0;
        // Its share of the kernel's luminance: under 1e-6, the channel's shape is noise.
        if (kept[c] > 0 && display::luminance_of_linear_rgb(unit * kept[c]) > 1e-6 * kept_luminance) {
            for (std::size_t idx = 0; idx < windowed.size(); ++idx)
                k.rgba[idx][c] = static_cast<float>(windowed[idx][c] / kept[c]);
        } else if (kept_luminance > 0) {
            for (std::size_t idx = 0; idx < windowed.size(); ++idx)
                k.rgba[idx][c] = static_cast<float>(display::luminance_of_linear_rgb(windowed[idx]) / kept_luminance);
        }
    }
}

// Overlap weights between the pixel grid (pitch 1/ppd degrees, pixel k centred
// at k/ppd for k in [-h, h]) and the PSF grid (pitch dpt, texel i centred at
// (i - n/2) dpt): w[k][i] = overlap length / dpt, so a texel's energy is shared
// among the pixels that cover it.
struct Overlap {
    int first;                   // first PSF texel touching pixel k
    std::vector<double> weight;  // for texels first, first+1, ...
};
std::vector<Overlap> overlap_weights(int h, double ppd, int n, double dpt) {
    std::vector<Overlap> out(static_cast<std::size_t>(2 * h + 1));
    const double c = n / 2;
    for (int k = -h; k <= h; ++k) {
        const double a = (k - 0.5) / ppd, b = (k + 0.5) / ppd;  // pixel span, degrees
        // texel i spans [(i - c - 0.5) dpt, (i - c + 0.5) dpt]
        const int i0 = std::max(0, static_cast<int>(std::floor(a / dpt + c + 0.5)));
        const int i1 = std::min(n - 1, static_cast<int>(std::floor(b / dpt + c + 0.5)));
        Overlap& o = out[static_cast<std::size_t>(k + h)];
        o.first = i0;
        for (int i = i0; i <= i1; ++i) {
            const double lo = std::max(a, (i - c - 0.5) * dpt), hi = std::min(b, (i - c + 0.5) * dpt);
            o.weight.push_back(std::max(0.0, hi - lo) / dpt);
        }
    }
    return out;
}

}  // namespace

GlareWindow glare_window_from_name(std::string_view name) {
    if (name == "none") return GlareWindow::none;
    if (name == "epanechnikov") return GlareWindow::epanechnikov;
    if (name == "silverman") return GlareWindow::silverman;
    throw InputError(
        SourceLocation{"", 0, 0, "window"},
        fmt::format("unknown glare window \"{}\"; it must be \"silverman\", \"epanechnikov\" or \"none\".", name));
}

std::string_view glare_window_name(GlareWindow w) {
    switch (w) {
        case GlareWindow::none:
            return "none";
        case GlareWindow::epanechnikov:
            return "epanechnikov";
        case GlareWindow::silverman:
            return "silverman";
    }
    return "none";
}

double glare_window_weight(GlareWindow w, double rho) {
    if (!(rho < 1.0)) return 0.0;
    const double q = 1.0 - rho * rho;
    switch (w) {
        case GlareWindow::none:
            return 1.0;
        case GlareWindow::epanechnikov:
            return q;  // K2012 eq 4.11 without 2/π
        case GlareWindow::silverman:
            return q * q;  // K2012 eq 4.12 without 3/π
    }
    return 1.0;
}

GlareKernel glare_kernel_from_psf(const RgbPsf& psf, double ppd, double radius_deg, GlareWindow window) {
    GlareKernel k;
    k.size = glare_kernel_size_px(ppd, radius_deg);
    k.pixels_per_degree = ppd;
    k.radius_px = radius_deg * ppd;
    const int m = k.size, h = k.half(), n = psf.n;
    const auto w = overlap_weights(h, ppd, n, psf.degrees_per_texel);
    // Separable resampling: along x for every PSF row, then along y.
    std::vector<glm::dvec3> rows(static_cast<std::size_t>(n) * m, glm::dvec3(0.0));
    for (int y = 0; y < n; ++y)
        for (int kx = 0; kx < m; ++kx) {
            const Overlap& o = w[static_cast<std::size_t>(kx)];
            glm::dvec3 s{0.0};
            for (std::size_t t = 0; t < o.weight.size(); ++t)
                s += o.weight[t] * psf.at(o.first + static_cast<int>(t), y);
            rows[static_cast<std::size_t>(y) * m + kx] = s;
        }
    std::vector<glm::dvec3> energy(static_cast<std::size_t>(m) * m, glm::dvec3(0.0));
    for (int ky = 0; ky < m; ++ky) {
        const Overlap& o = w[static_cast<std::size_t>(ky)];
        for (int kx = 0; kx < m; ++kx) {
            glm::dvec3 s{0.0};
            for (std::size_t t = 0; t < o.weight.size(); ++t)
                s += o.weight[t] * rows[static_cast<std::size_t>(o.first + static_cast<int>(t)) * m + kx];
            energy[static_cast<std::size_t>(ky) * m + kx] = s;
        }
    }
    window_and_normalise(k, energy, psf.channel_sums(), window);
    return k;
}

GlareKernel glare_kernel_from_radial(const RadialDensity& density, const SpectralSamples& samples, double ppd,
                                     double radius_deg, GlareWindow window) {
    GlareKernel k;
    k.size = glare_kernel_size_px(ppd, radius_deg);
    k.pixels_per_degree = ppd;
    k.radius_px = radius_deg * ppd;
    const int m = k.size, h = k.half();
    const std::size_t ns = samples.wavelength_nm.size();
    const double deg2_to_sr = std::pow(std::numbers::pi / 180.0, 2);

    // Per wavelength: the pixel's integral of the density (sr · density), by
    // midpoint sampling, finer near the centre where Spencer's f0 peaks within
    // a fraction of a pixel. The PSF is radially symmetric: one octant is computed.
    std::vector<glm::dvec3> energy(static_cast<std::size_t>(m) * m, glm::dvec3(0.0));
    std::vector<double> per_lambda(ns);
    for (int j = 0; j <= h; ++j)
        for (int i = j; i <= h; ++i) {
            const double r = std::hypot(i, j);
            const int s = r < 2.5 ? 64 : r < 10 ? 16 : r < 40 ? 4 : 2;
            std::fill(per_lambda.begin(), per_lambda.end(), 0.0);
            for (int sy = 0; sy < s; ++sy)
                for (int sx = 0; sx < s; ++sx) {
                    const double x = (i - 0.5 + (sx + 0.5) / s) / ppd, y = (j - 0.5 + (sy + 0.5) / s) / ppd;
                    const double theta = std::hypot(x, y);
                    for (std::size_t l = 0; l < ns; ++l) per_lambda[l] += density(theta, samples.wavelength_nm[l]);
                }
            glm::dvec3 xyz{0.0};
            const double area_sr = deg2_to_sr / (ppd * ppd) / (s * s);
            for (std::size_t l = 0; l < ns; ++l) xyz += samples.xyz_weight[l] * per_lambda[l] * area_sr;
            const glm::dvec3 rgb = glm::max(display::xyz_to_linear_rgb(xyz), glm::dvec3(0.0));
            const int offsets[8][2] = {{i, j}, {j, i}, {-i, j}, {-j, i}, {i, -j}, {j, -i}, {-i, -j}, {-j, -i}};
            for (const auto& o : offsets) energy[static_cast<std::size_t>(o[1] + h) * m + (o[0] + h)] = rgb;
        }
    // The whole PSF: ∫ density 2π sin θ dθ over 0 … 90° (θ in rad), on a grid
    // that is fine near 0 (u = sqrt(θ) spacing).
    glm::dvec3 total_xyz{0.0};
    constexpr int kSteps = 20000;
    const double u_max = std::sqrt(90.0);
    for (std::size_t l = 0; l < ns; ++l) {
        double integral = 0;
        for (int t = 0; t < kSteps; ++t) {
            const double u = (t + 0.5) * u_max / kSteps, du = u_max / kSteps;
            const double theta_deg = u * u, dtheta_deg = 2 * u * du;
            integral += density(theta_deg, samples.wavelength_nm[l]) * 2 * std::numbers::pi *
                        std::sin(theta_deg * std::numbers::pi / 180.0) * dtheta_deg * std::numbers::pi / 180.0;
        }
        total_xyz += samples.xyz_weight[l] * integral;
    }
    window_and_normalise(k, energy, glm::max(display::xyz_to_linear_rgb(total_xyz), glm::dvec3(0.0)), window);
    return k;
}

AreaLayers build_area_layers(const GlareKernel& kernel, double max_radius_px, int max_layers) {
    AreaLayers out;
    const int reach = max_radius_px > 0 ? static_cast<int>(std::ceil(max_radius_px)) : 0;
    out.size = kernel.size + 2 * reach;
    out.layers = reach == 0 ? 1 : std::max(2, std::min(max_layers, reach + 1));
    out.radius_step_px = out.layers > 1 ? max_radius_px / (out.layers - 1) : 0.0;
    const int m = out.size, km = kernel.size;
    out.rgba.assign(static_cast<std::size_t>(out.layers) * m * m, glm::vec4(0.0f));
    // Layer 0: the kernel, padded.
    for (int j = 0; j < km; ++j)
        for (int i = 0; i < km; ++i) out.rgba[static_cast<std::size_t>(j + reach) * m + (i + reach)] = kernel.at(i, j);
    if (out.layers == 1) return out;

    // Linear convolution by FFT on a P×P grid (P ≥ m: no wrap-around overlap).
    int p = 1;
    while (p < m + 2) p *= 2;
    const int pc = p / 2 + 1;  // r2c output width
    std::vector<double> real(static_cast<std::size_t>(p) * p);
    using Spectrum2D = std::vector<std::complex<double>>;
    Spectrum2D kernel_hat[3], disc_hat(static_cast<std::size_t>(p) * pc), product(disc_hat.size());
    // std::complex<double> is layout-compatible with fftw_complex (FFTW manual §4.1.1).
    auto as_fftw = [](Spectrum2D& v) { return reinterpret_cast<fftw_complex*>(v.data()); };
    // FFTW's planner is not thread-safe: the library's one lock (a render may
    // run beside this one, e.g. from Python with the GIL released).
    std::unique_lock planner(detail::fftw_planner_mutex());
    fftw_plan forward = fftw_plan_dft_r2c_2d(p, p, real.data(), as_fftw(disc_hat), FFTW_ESTIMATE);
    fftw_plan inverse = fftw_plan_dft_c2r_2d(p, p, as_fftw(product), real.data(), FFTW_ESTIMATE);
    planner.unlock();
    for (int c = 0; c < 3; ++c) {
        std::fill(real.begin(), real.end(), 0.0);
        for (int j = 0; j < km; ++j)
            for (int i = 0; i < km; ++i) real[static_cast<std::size_t>(j) * p + i] = kernel.at(i, j)[c];
        kernel_hat[c].resize(disc_hat.size());
        fftw_execute_dft_r2c(forward, real.data(), as_fftw(kernel_hat[c]));
        detail::count_cpu_ffts();
    }
    for (int layer = 1; layer < out.layers; ++layer) {
        // The disc of radius r centred on a pixel centre, exact pixel coverage,
        // normalised to unit sum, placed with its centre at index (0, 0) (wrapped).
        const double r = layer * out.radius_step_px;
        const int rr = static_cast<int>(std::ceil(r)) + 1;
        std::fill(real.begin(), real.end(), 0.0);
        double area = 0;
        for (int y = -rr; y <= rr; ++y)
            for (int x = -rr; x <= rr; ++x) {
                const double cov = disc_pixel_coverage(0.0, 0.0, r, x - 0.5, y - 0.5);
                real[static_cast<std::size_t>((y + p) % p) * p + (x + p) % p] = cov;
                area += cov;
            }
        for (double& v : real) v /= area;
        fftw_execute_dft_r2c(forward, real.data(), as_fftw(disc_hat));
        detail::count_cpu_ffts();
        for (int c = 0; c < 3; ++c) {
            for (std::size_t t = 0; t < product.size(); ++t) product[t] = kernel_hat[c][t] * disc_hat[t];
            fftw_execute_dft_c2r(inverse, as_fftw(product), real.data());  // unnormalised: divide by p²
            detail::count_cpu_ffts();
            // Result index q in the kernel's frame; layer texel i ↔ kernel index i - reach.
            double sum = 0;
            glm::vec4* dst = &out.rgba[static_cast<std::size_t>(layer) * m * m];
            std::vector<double> values(static_cast<std::size_t>(m) * m);
            for (int j = 0; j < m; ++j)
                for (int i = 0; i < m; ++i) {
                    const int qx = (i - reach + p) % p, qy = (j - reach + p) % p;
                    const double v =
                        std::max(0.0, real[static_cast<std::size_t>(qy) * p + qx] / (static_cast<double>(p) * p));
                    values[static_cast<std::size_t>(j) * m + i] = v;
                    sum += v;
                }
            for (std::size_t t = 0; t < values.size(); ++t)
                dst[t][c] = static_cast<float>(sum > 0 ? values[t] / sum : 0.0);
        }
    }
    planner.lock();
    fftw_destroy_plan(forward);
    fftw_destroy_plan(inverse);
    return out;
}

}  // namespace atonlab::stimuli
