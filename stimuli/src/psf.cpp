#include "atonlab/stimuli/psf.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "atonlab/stimuli/error.h"
#include "psf_binning.h"

namespace atonlab::stimuli {

SpectralSamples spectral_samples(const display::Spectrum& spd, int count) {
    if (count < 1)
        throw InputError(SourceLocation{"", 0, 0, "spectral_samples"},
                         fmt::format("the number of spectral samples must be at least 1, not {}.", count));
    SpectralSamples s;
    const double width = (SpectralSamples::kLastNm - SpectralSamples::kFirstNm) / count;
    double y_total = 0;
    for (int i = 0; i < count; ++i) {
        const double lambda = SpectralSamples::kFirstNm + (i + 0.5) * width;
        const glm::dvec3 w = display::cie1931_cmf(lambda) * spd.at(lambda) * width;
        s.wavelength_nm.push_back(lambda);
        s.xyz_weight.push_back(w);
        y_total += w.y;
    }
    if (!(y_total > 0))
        throw InputError(SourceLocation{"", 0, 0, "spd"},
                         "the spectrum has no luminance between 380 and 780 nm, so its glare has no colour.");
    for (auto& w : s.xyz_weight) w /= y_total;
    return s;
}

glm::dvec3 RgbPsf::channel_sums() const {
    glm::dvec3 s{0.0};
    for (const auto& v : rgb) s += v;
    return s;
}

double RgbPsf::luminance_sum() const {
    return display::luminance_of_linear_rgb(channel_sums());
}

MonoPsf mono_psf_from_spectrum(const ComplexImage<double>& F, double degrees_per_texel, double wavelength_nm) {
    MonoPsf p;
    p.n = F.n;
    p.degrees_per_texel = degrees_per_texel;
    p.wavelength_nm = wavelength_nm;
    p.value.resize(F.data.size());
    const int n = F.n, h = n / 2;
    double sum = 0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double v = std::norm(F.at(x, y));  // |F|², eq 4.6
            // eq 4.8: the zero frequency moves to the centre texel (n/2, n/2).
            p.value[static_cast<std::size_t>((y + h) % n) * n + (x + h) % n] = v;
            sum += v;
        }
    if (sum > 0)
        for (double& v : p.value) v /= sum;  // §4.2.3: unit sum
    return p;
}

namespace {

// |F|², centred (eq 4.8), unnormalised.
std::vector<double> centred_power(const ComplexImage<double>& F) {
    const int n = F.n, h = n / 2;
    std::vector<double> out(F.data.size());
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            out[static_cast<std::size_t>((y + h) % n) * n + (x + h) % n] = std::norm(F.at(x, y));
    return out;
}

double sum_of(const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return s;
}

}  // namespace

namespace detail {

std::vector<AxisShare> axis_shares(int n_fine, int n_coarse, double ratio) {
    std::vector<AxisShare> out(static_cast<std::size_t>(n_fine));
    for (int k = 0; k < n_fine; ++k) {
        const double u = n_coarse / 2 + (k - n_fine / 2) * ratio;
        const double lo = u - 0.5 * ratio, hi = u + 0.5 * ratio;
        AxisShare& a = out[static_cast<std::size_t>(k)];
        a.first = static_cast<int>(std::floor(lo + 0.5));
        for (int m = a.first; m - 0.5 < hi; ++m) {
            const double overlap = std::min(hi, m + 0.5) - std::max(lo, m - 0.5);
            a.share.push_back(std::max(overlap, 0.0) / ratio);
        }
    }
    return out;
}

}  // namespace detail

void bin_into(const MonoPsf& fine, double weight, MonoPsf& coarse) {
    const double ratio = fine.degrees_per_texel / coarse.degrees_per_texel;
    const std::vector<detail::AxisShare> shares = detail::axis_shares(fine.n, coarse.n, ratio);
    for (int y = 0; y < fine.n; ++y) {
        const detail::AxisShare& sy = shares[static_cast<std::size_t>(y)];
        for (int x = 0; x < fine.n; ++x) {
            const double v = weight * fine.at(x, y);
            if (v == 0) continue;
            const detail::AxisShare& sx = shares[static_cast<std::size_t>(x)];
            for (std::size_t b = 0; b < sy.share.size(); ++b) {
                const int cy = sy.first + static_cast<int>(b);
                if (cy < 0 || cy >= coarse.n) continue;  // beyond the coarse grid: cannot happen for ratio ≤ 1
                for (std::size_t a = 0; a < sx.share.size(); ++a) {
                    const int cx = sx.first + static_cast<int>(a);
                    if (cx < 0 || cx >= coarse.n) continue;
                    coarse.value[static_cast<std::size_t>(cy) * coarse.n + cx] += v * sy.share[b] * sx.share[a];
                }
            }
        }
    }
}

MonoPsfParts mono_psf_parts(const EyeModel& eye, int n, double wavelength_nm, double time_s) {
    // The plane scales with λ so that λ/W_λ = λ0/W: every wavelength's FFT
    // lands on λ0's angular grid (the exact path of §4.2.4's approximation).
    const double w = eye.plane_width_mm * wavelength_nm / kReferenceWavelengthNm;
    PupilParts fields = pupil_parts(eye, n, wavelength_nm, w, time_s);
    fftw_forward(fields.core);
    fftw_forward(fields.scatter);
    MonoPsfParts out;
    out.core = {n, core_degrees_per_texel(eye), wavelength_nm, centred_power(fields.core)};
    out.scatter = {n, psf_degrees_per_texel(eye), wavelength_nm, centred_power(fields.scatter)};
    // Parseval: Σ|F|² = n² Σ|field|² for both, so their raw sums are in the
    // proportion of the pupil-plane energies; one factor keeps it.
    const double core_sum = sum_of(out.core.value), scatter_sum = sum_of(out.scatter.value);
    const double total = core_sum + scatter_sum;
    if (total > 0) {
        out.core_fraction = core_sum / total;
        for (double& v : out.scatter.value) v /= total;
        if (core_sum > 0)
            for (double& v : out.core.value) v /= core_sum;
    }
    return out;
}

MonoPsf mono_psf_reference(const EyeModel& eye, int n, double wavelength_nm, double time_s) {
    if (has_two_scales(eye)) {
        MonoPsfParts parts = mono_psf_parts(eye, n, wavelength_nm, time_s);
        MonoPsf out = std::move(parts.scatter);
        bin_into(parts.core, parts.core_fraction, out);
        return out;
    }
    const double w = eye.plane_width_mm * wavelength_nm / kReferenceWavelengthNm;
    ComplexImage<double> field = pupil_plane(eye, n, wavelength_nm, w, time_s);
    fftw_forward(field);
    return mono_psf_from_spectrum(field, psf_degrees_per_texel(eye), wavelength_nm);
}

std::vector<double> box_downsample(const std::vector<double>& image, int n) {
    const int m = n / 2;
    std::vector<double> out(static_cast<std::size_t>(m) * m);
    for (int y = 0; y < m; ++y)
        for (int x = 0; x < m; ++x) {
            auto at = [&](int xx, int yy) { return image[static_cast<std::size_t>(yy) * n + xx]; };
            out[static_cast<std::size_t>(y) * m + x] =
                0.25 * (at(2 * x, 2 * y) + at(2 * x + 1, 2 * y) + at(2 * x, 2 * y + 1) + at(2 * x + 1, 2 * y + 1));
        }
    return out;
}

double bilinear_zero_border(const std::vector<double>& image, int n, double x, double y) {
    const double fx = std::floor(x), fy = std::floor(y);
    const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
    const double tx = x - fx, ty = y - fy;
    auto at = [&](int xx, int yy) {
        if (xx < 0 || yy < 0 || xx >= n || yy >= n) return 0.0;
        return image[static_cast<std::size_t>(yy) * n + xx];
    };
    return (1 - ty) * ((1 - tx) * at(x0, y0) + tx * at(x0 + 1, y0)) +
           ty * ((1 - tx) * at(x0, y0 + 1) + tx * at(x0 + 1, y0 + 1));
}

namespace {

// XYZ → linear Rec.709, texels outside the gamut clipped at 0 (a display cannot
// emit negative light), then normalised to unit luminance sum.
RgbPsf finish_rgb(int n, double degrees_per_texel, const std::vector<glm::dvec3>& xyz) {
    RgbPsf out;
    out.n = n;
    out.degrees_per_texel = degrees_per_texel;
    out.rgb.resize(xyz.size());
    for (std::size_t i = 0; i < xyz.size(); ++i) out.rgb[i] = glm::max(display::xyz_to_linear_rgb(xyz[i]), glm::dvec3(0.0));
    const double y = out.luminance_sum();
    if (y > 0)
        for (auto& v : out.rgb) v /= y;
    return out;
}

}  // namespace

RgbPsf spectral_psf_resampled(const MonoPsf& psf, const SpectralSamples& samples) {
    const int n = psf.n;
    const double c = n / 2;
    const std::vector<double> level1 = box_downsample(psf.value, n);
    std::vector<glm::dvec3> xyz(psf.value.size(), glm::dvec3(0.0));
    for (std::size_t s = 0; s < samples.wavelength_nm.size(); ++s) {
        // eq 4.9: F_λ(x) = F_λ0(x λ0/λ); (λ0/λ)² keeps each wavelength's energy.
        const double ratio = psf.wavelength_nm / samples.wavelength_nm[s];
        const double lod = std::max(0.0, std::log2(ratio));  // minification only for λ < λ0
        const double gain = ratio * ratio;
        const glm::dvec3 w = samples.xyz_weight[s] * gain;
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double sx = c + (x - c) * ratio, sy = c + (y - c) * ratio;
                double v = bilinear_zero_border(psf.value, n, sx, sy);
                if (lod > 0) {
                    // Level 1 texel k covers level-0 texels 2k, 2k+1: centre at 2k + 0.5.
                    // Its values are averages, i.e. per-level-0-texel energies, like level 0.
                    const double v1 = bilinear_zero_border(level1, n / 2, (sx - 0.5) / 2, (sy - 0.5) / 2);
                    const double t = std::min(lod, 1.0);
                    v = (1 - t) * v + t * v1;
                }
                xyz[static_cast<std::size_t>(y) * n + x] += w * v;
            }
    }
    return finish_rgb(n, psf.degrees_per_texel, xyz);
}

RgbPsf spectral_psf_exact(const EyeModel& eye, int n, const SpectralSamples& samples, double time_s) {
    std::vector<glm::dvec3> xyz(static_cast<std::size_t>(n) * n, glm::dvec3(0.0));
    for (std::size_t s = 0; s < samples.wavelength_nm.size(); ++s) {
        const MonoPsf p = mono_psf_reference(eye, n, samples.wavelength_nm[s], time_s);
        for (std::size_t i = 0; i < xyz.size(); ++i) xyz[i] += samples.xyz_weight[s] * p.value[i];
    }
    return finish_rgb(n, psf_degrees_per_texel(eye), xyz);
}

double relative_l2(const RgbPsf& a, const RgbPsf& b) {
    double num = 0, den = 0;
    for (std::size_t i = 0; i < b.rgb.size(); ++i) {
        const glm::dvec3 d = a.rgb[i] - b.rgb[i];
        num += glm::dot(d, d);
        den += glm::dot(b.rgb[i], b.rgb[i]);
    }
    return den > 0 ? std::sqrt(num / den) : std::sqrt(num);
}

}  // namespace atonlab::stimuli
