// The anchored spectral path (spectral_path.h): exact PSFs at a few anchor
// wavelengths, every sample interpolated in 1/λ from its nearest anchors, each
// rescaled by K2012 eq 4.9 over the short step to the sample.
#include "atonlab/stimuli/spectral_path.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "atonlab/stimuli/colour.h"
#include "atonlab/stimuli/error.h"

namespace atonlab::stimuli {

namespace {

/// A sample's share of the light for placing anchors: x̄ + ȳ + z̄ of its weight.
double sample_weight(const glm::dvec3& xyz) {
    return std::abs(xyz.x) + std::abs(xyz.y) + std::abs(xyz.z);
}

/// Lanczos-3 weights of one axis (windowed sinc, 6 taps): for output index i,
/// the source coordinate c + (i − c)·ratio, its first tap and the 6 weights
/// (normalised to sum 1, so a constant stays constant). |F|² is band-limited
/// (the pupil's autocorrelation spans at most the plane's half width), which a
/// windowed sinc reproduces far better than bilinear lookups: at the default
/// eye's sampling (3 texels to the first Airy zero) bilinear lookups alone
/// leave 2% (relative L2) of the exact path, Lanczos-3 a few tenths of that.
constexpr int kTaps = 6;  // add_rescaled's y pass spells out these six taps
constexpr double kLobes = kTaps / 2;
/// Anchors per sample between the outer anchors: 4, cubic in 1/λ (quadratic
/// left 0.0044 with the default eye at N = 512, cubic 0.0032).
constexpr std::size_t kOrder = 4;
struct Taps {
    std::vector<int> first;
    std::vector<double> weight;  // kTaps per output index
};
double sinc(double x) {
    if (std::abs(x) < 1e-12) return 1.0;
    const double px = std::numbers::pi * x;
    return std::sin(px) / px;
}
Taps taps(int n, double ratio) {
    Taps t;
    t.first.resize(static_cast<std::size_t>(n));
    t.weight.resize(static_cast<std::size_t>(n) * kTaps);
    const double c = n / 2;
    for (int i = 0; i < n; ++i) {
        const double s = c + (i - c) * ratio;
        const int first = static_cast<int>(std::floor(s)) - kTaps / 2 + 1;
        t.first[static_cast<std::size_t>(i)] = first;
        double sum = 0;
        double* w = &t.weight[static_cast<std::size_t>(i) * kTaps];
        for (int k = 0; k < kTaps; ++k) {
            const double d = s - (first + k);
            w[k] = std::abs(d) < kLobes ? sinc(d) * sinc(d / kLobes) : 0.0;
            sum += w[k];
        }
        for (int k = 0; k < kTaps; ++k) w[k] /= sum;
    }
    return t;
}

/// The X, Y and Z planes being accumulated (planes, not triples: the inner
/// loops then vectorise; fp32: ~90 terms of relative rounding 6e-8 each).
struct XyzPlanes {
    std::vector<float> c[3];
    explicit XyzPlanes(std::size_t texels) {
        for (auto& p : c) p.assign(texels, 0.0);
    }
};

/// Scratch planes of add_rescaled (fp32: the sum of a few dozen terms needs
/// nothing finer for 1e-2, and it halves the memory traffic).
struct Scratch {
    std::vector<float> rows, zero;
};

/// xyz += weight · F(c + (x − c)·ratio) for every texel, by separable Lanczos-3
/// (zero outside the grid): eq 4.9's lookup; the gain (λk/λ)² is in `weight`;
/// `source` is F in fp32.
void add_rescaled(XyzPlanes& xyz, int n, double ratio, const glm::dvec3& weight, const std::vector<float>& source,
                  Scratch& scratch) {
    const auto texels = static_cast<std::size_t>(n) * n;
    if (ratio == 1.0) {  // a sample at an anchor's own wavelength: no resampling
        for (int c = 0; c < 3; ++c) {
            const auto wc = static_cast<float>(weight[c]);
            for (std::size_t i = 0; i < texels; ++i) xyz.c[c][i] += wc * source[i];
        }
        return;
    }
    const Taps t = taps(n, ratio);
    scratch.rows.resize(texels);
    const std::vector<float> w32(t.weight.begin(), t.weight.end());
    // Along x, every row; the taps of interior texels need no bounds check.
    for (int y = 0; y < n; ++y) {
        const float* src = &source[static_cast<std::size_t>(y) * n];
        float* dst = &scratch.rows[static_cast<std::size_t>(y) * n];
        for (int x = 0; x < n; ++x) {
            const int first = t.first[static_cast<std::size_t>(x)];
            const float* w = &w32[static_cast<std::size_t>(x) * kTaps];
            float v = 0;
            if (first >= 0 && first + kTaps <= n) {
                for (int k = 0; k < kTaps; ++k) v += w[k] * src[first + k];
            } else {
                for (int k = 0; k < kTaps; ++k) {
                    const int sx = first + k;
                    if (sx >= 0 && sx < n) v += w[k] * src[sx];
                }
            }
            dst[x] = v;
        }
    }
    // Along y, straight into X, Y and Z: six rows (a zero row for taps off the
    // grid) combined across x, which vectorises.
    scratch.zero.assign(static_cast<std::size_t>(n), 0.0f);
    const glm::vec3 wc(weight);
    for (int y = 0; y < n; ++y) {
        const int first = t.first[static_cast<std::size_t>(y)];
        const float* w = &w32[static_cast<std::size_t>(y) * kTaps];
        const float* r[kTaps];
        for (int k = 0; k < kTaps; ++k) {
            const int sy = first + k;
            r[k] = sy >= 0 && sy < n ? &scratch.rows[static_cast<std::size_t>(sy) * n] : scratch.zero.data();
        }
        const std::size_t row = static_cast<std::size_t>(y) * n;
        float* dx = &xyz.c[0][row];
        float* dy = &xyz.c[1][row];
        float* dz = &xyz.c[2][row];
        for (int x = 0; x < n; ++x) {
            const float v =
                w[0] * r[0][x] + w[1] * r[1][x] + w[2] * r[2][x] + w[3] * r[3][x] + w[4] * r[4][x] + w[5] * r[5][x];
            dx[x] += wc.x * v;
            dy[x] += wc.y * v;
            dz[x] += wc.z * v;
        }
    }
}

/// An anchor's monochromatic PSF on λ0's grid, as mono_psf_reference() draws
/// it (the plane over W·λ/λ0) but transformed by FFTW in fp32: the anchors
/// are rescaled and summed in fp32 anyway (≈ 10% faster than double here).
MonoPsf anchor_psf(const EyeModel& eye, int n, double wavelength_nm, double time_s) {
    // The two-scale eye (eye_model.h): core and scatter at their own angular
    // scales, binned onto one grid, as the exact reference builds each wavelength.
    if (has_two_scales(eye)) return mono_psf_reference(eye, n, wavelength_nm, time_s);
    const double w = eye.plane_width_mm * wavelength_nm / kReferenceWavelengthNm;
    const ComplexImage<double> field = pupil_plane(eye, n, wavelength_nm, w, time_s);
    ComplexImage<float> f(n);
    for (std::size_t i = 0; i < field.data.size(); ++i) f.data[i] = std::complex<float>(field.data[i]);
    fftw_forward(f);
    MonoPsf p;
    p.n = n;
    p.degrees_per_texel = psf_degrees_per_texel(eye);
    p.wavelength_nm = wavelength_nm;
    p.value.resize(f.data.size());
    const int h = n / 2;
    double sum = 0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double v = std::norm(std::complex<double>(f.at(x, y)));          // |F|², K2012 eq 4.6
            p.value[static_cast<std::size_t>((y + h) % n) * n + (x + h) % n] = v;  // eq 4.8's shift
            sum += v;
        }
    if (sum > 0)
        for (double& v : p.value) v /= sum;  // §4.2.3: unit sum
    return p;
}

}  // namespace

std::vector<double> spectral_anchor_wavelengths(const SpectralSamples& samples, int count) {
    if (count < 1)
        throw InputError(SourceLocation{"", 0, 0, "spectral_anchors"},
                         fmt::format("the number of anchor wavelengths must be at least 1, not {}.", count));
    const std::size_t ns = samples.wavelength_nm.size();
    std::vector<double> cumulative(ns);
    double total = 0;
    for (std::size_t s = 0; s < ns; ++s) {
        total += sample_weight(samples.xyz_weight[s]);
        cumulative[s] = total;
    }
    std::vector<double> out;
    for (int k = 0; k < count; ++k) {
        const double q = count == 1 ? 0.5 : 0.01 + 0.98 * k / (count - 1);
        // The sample whose cumulative weight range holds q·total.
        const auto it = std::lower_bound(cumulative.begin(), cumulative.end(), q * total);
        const auto s = static_cast<std::size_t>(
            std::min<std::ptrdiff_t>(it - cumulative.begin(), static_cast<std::ptrdiff_t>(ns) - 1));
        if (out.empty() || samples.wavelength_nm[s] > out.back()) out.push_back(samples.wavelength_nm[s]);
    }
    return out;
}

RgbPsf spectral_psf_from_anchors(const std::vector<MonoPsf>& anchors, const SpectralSamples& samples) {
    const int n = anchors.front().n;
    XyzPlanes xyz(static_cast<std::size_t>(n) * n);
    const std::size_t k = anchors.size();
    std::vector<std::vector<float>> source(k);  // each anchor's PSF in fp32
    for (std::size_t i = 0; i < k; ++i) source[i].assign(anchors[i].value.begin(), anchors[i].value.end());
    Scratch scratch;
    double brightest = 0;
    for (const auto& w : samples.xyz_weight) brightest = std::max(brightest, sample_weight(w));
    for (std::size_t s = 0; s < samples.wavelength_nm.size(); ++s) {
        const double lambda = samples.wavelength_nm[s];
        // The (up to) kOrder anchors nearest in 1/λ, and their Lagrange weights in 1/λ.
        std::vector<std::size_t> near(k);
        for (std::size_t i = 0; i < k; ++i) near[i] = i;
        std::sort(near.begin(), near.end(), [&](std::size_t i, std::size_t j) {
            return std::abs(1 / anchors[i].wavelength_nm - 1 / lambda) <
                   std::abs(1 / anchors[j].wavelength_nm - 1 / lambda);
        });
        // Beyond the outer anchors (the spectrum's 1% tails) the two nearest
        // extrapolate linearly, and a sample with under 1% of the brightest
        // sample's weight takes the nearest alone (a third fewer rescales for D65).
        const bool tail = lambda < anchors.front().wavelength_nm || lambda > anchors.back().wavelength_nm;
        const bool faint = sample_weight(samples.xyz_weight[s]) < 0.01 * brightest;
        near.resize(std::min<std::size_t>(k, tail ? (faint ? 1 : 2) : kOrder));
        for (std::size_t i : near) {
            double share = 1;
            for (std::size_t j : near)
                if (j != i)
                    share *= (1 / lambda - 1 / anchors[j].wavelength_nm) /
                             (1 / anchors[i].wavelength_nm - 1 / anchors[j].wavelength_nm);
            if (share == 0) continue;
            // K2012 eq 4.9 from the anchor λk: F_λ(x) = F_λk(x λk/λ) (λk/λ)².
            const double ratio = anchors[i].wavelength_nm / lambda;
            add_rescaled(xyz, n, ratio, samples.xyz_weight[s] * (share * ratio * ratio), source[i], scratch);
        }
    }
    // XYZ → linear Rec.709, clipped at 0, unit luminance sum: as spectral_psf_exact (psf.cpp).
    RgbPsf out;
    out.n = n;
    out.degrees_per_texel = anchors.front().degrees_per_texel;
    out.rgb.resize(xyz.c[0].size());
    for (std::size_t i = 0; i < out.rgb.size(); ++i)
        out.rgb[i] = glm::max(xyz_to_linear_rgb({xyz.c[0][i], xyz.c[1][i], xyz.c[2][i]}), glm::dvec3(0.0));
    const double y = out.luminance_sum();
    if (y > 0)
        for (auto& v : out.rgb) v /= y;
    return out;
}

RgbPsf spectral_psf_anchored(const EyeModel& eye, int n, const SpectralSamples& samples, int anchors, double time_s) {
    std::vector<MonoPsf> psfs;
    for (double lambda : spectral_anchor_wavelengths(samples, anchors))
        psfs.push_back(anchor_psf(eye, n, lambda, time_s));
    return spectral_psf_from_anchors(psfs, samples);
}

}  // namespace atonlab::stimuli
