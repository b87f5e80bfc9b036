// The anchored spectral path (spectral_path.h): exact PSFs at a few anchor
// wavelengths, every sample interpolated in 1/λ from its nearest anchors, each
// rescaled by K2012 eq 4.9 over the short step to the sample.
#include "atonlab/stimuli/spectral_path.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/error.h"
#include "parallel.h"
#include "spectral_terms.h"

namespace atonlab::stimuli {

namespace {

/// A sample's share of the light for placing anchors: x̄ + ȳ + z̄ of its weight.
double sample_weight(const glm::dvec3& xyz) {
    return std::abs(xyz.x) + std::abs(xyz.y) + std::abs(xyz.z);
}

constexpr int kTaps = detail::kLanczosTaps;

/// A term as the CPU sums it: the recipe's term (spectral_terms.h) with its
/// taps in fp32, tap-major for the x pass, and the runs along which the taps
/// read contiguous source texels.
struct Term : detail::SpectralTerm {
    std::vector<float> w;   // taps.weight in fp32
    std::vector<float> wx;  // the same tap-major (kTaps planes of n), for the x pass
    /// Runs [x0, x1) of interior texels whose first tap is x + shift: along
    /// such a run the taps read contiguous source texels, which vectorises.
    struct Run {
        int x0, x1, shift;
    };
    std::vector<Run> runs;
    std::vector<int> edge;  // the texels whose taps leave the grid
};

/// wx and runs of a term from its taps.
void prepare_x_pass(Term& t, int n) {
    const auto un = static_cast<std::size_t>(n);
    t.wx.resize(un * kTaps);
    for (std::size_t x = 0; x < un; ++x)
        for (std::size_t k = 0; k < kTaps; ++k) t.wx[k * un + x] = t.w[x * kTaps + k];
    for (int x = 0; x < n; ++x) {
        const int first = t.taps.first[static_cast<std::size_t>(x)];
        if (first < 0 || first + kTaps > n) {
            t.edge.push_back(x);
        } else if (!t.runs.empty() && t.runs.back().x1 == x && t.runs.back().shift == first - x) {
            ++t.runs.back().x1;
        } else {
            t.runs.push_back({x, x + 1, first - x});
        }
    }
}
struct Sample {
    glm::vec3 xyz;  // the sample's CMF × SPD weight
    std::vector<Term> terms;
};

/// Working planes kept between calls (per calling thread, one band space per
/// worker), so a call neither allocates nor zeroes megabytes: the path is
/// otherwise dominated by page faults.
struct BandSpace {
    std::vector<float> rows;  // x pass of the source rows one band needs
    std::vector<float> acc;   // one sample's band (scalar)
    std::vector<float> xyz;   // X, Y and Z of the band (planes)
    std::vector<float> zero;  // a zero row for taps off the grid
};
struct Workspace {
    std::vector<BandSpace> bands;             // one per worker thread
    std::vector<std::vector<float>> source;  // each anchor's PSF in fp32
};
Workspace& workspace() {
    thread_local Workspace w;
    return w;
}

/// Output rows per band: the band's X, Y, Z, its sample plane and the x pass of
/// its source rows (≈ 5 × 32 rows × 2 KB at N = 512) stay in the L2 cache while
/// all samples are added, instead of streaming full planes once per term.
constexpr int kBand = 32;
/// Texels per block of the y pass (two SSE or one AVX register of fp32).
constexpr std::size_t kLanes = 4;

/// acc[y − y0][x] += scale · F(c + (x − c)·ratio, c + (y − c)·ratio) for the
/// band's rows y0 … y1 − 1: separable Lanczos-3, zero outside the grid.
void add_term_band(BandSpace& ws, int n, int y0, int y1, const Term& t, const std::vector<float>& source) {
    const auto un = static_cast<std::size_t>(n);
    if (t.ratio == 1.0) {  // a sample at an anchor's own wavelength: no resampling
        for (int y = y0; y < y1; ++y) {
            const float* src = &source[static_cast<std::size_t>(y) * un];
            float* dst = &ws.acc[static_cast<std::size_t>(y - y0) * un];
            for (std::size_t x = 0; x < un; ++x) dst[x] += t.scale * src[x];
        }
        return;
    }
    // The source rows the band's taps reach, clipped to the grid.
    const int lo = std::max(0, t.taps.first[static_cast<std::size_t>(y0)]);
    const int hi = std::min(n, t.taps.first[static_cast<std::size_t>(y1 - 1)] + kTaps);
    if (ws.rows.size() < static_cast<std::size_t>(std::max(0, hi - lo)) * un)
        ws.rows.resize(static_cast<std::size_t>(hi - lo) * un);
    // Along x, those rows: along each run in blocks of kLanes (contiguous
    // loads, tap-major weights), the edge texels with bounds checks.
    for (int sy = lo; sy < hi; ++sy) {
        const float* src = &source[static_cast<std::size_t>(sy) * un];
        float* dst = &ws.rows[static_cast<std::size_t>(sy - lo) * un];
        for (const Term::Run& run : t.runs) {
            const auto x1 = static_cast<std::size_t>(run.x1);
            auto x = static_cast<std::size_t>(run.x0);
            const float* s0 = src + run.shift;  // s0[x + k]: tap k of texel x
            for (; x + kLanes <= x1; x += kLanes) {
                float v[kLanes] = {};
                for (std::size_t k = 0; k < kTaps; ++k)
                    for (std::size_t j = 0; j < kLanes; ++j) v[j] += t.wx[k * un + x + j] * s0[x + j + k];
                for (std::size_t j = 0; j < kLanes; ++j) dst[x + j] = v[j];
            }
            for (; x < x1; ++x) {
                float v = 0;
                for (std::size_t k = 0; k < kTaps; ++k) v += t.wx[k * un + x] * s0[x + k];
                dst[x] = v;
            }
        }
        for (int x : t.edge) {
            const int first = t.taps.first[static_cast<std::size_t>(x)];
            const float* w = &t.w[static_cast<std::size_t>(x) * kTaps];
            float v = 0;
            for (int k = 0; k < kTaps; ++k) {
                const int sx = first + k;
                if (sx >= 0 && sx < n) v += w[k] * src[sx];
            }
            dst[x] = v;
        }
    }
    // Along y into the band: six rows (a zero row for taps off the grid)
    // combined across x, which vectorises.
    for (int y = y0; y < y1; ++y) {
        const int first = t.taps.first[static_cast<std::size_t>(y)];
        const float* w = &t.w[static_cast<std::size_t>(y) * kTaps];
        const float* r[kTaps];
        for (int k = 0; k < kTaps; ++k) {
            const int sy = first + k;
            r[k] = sy >= lo && sy < hi ? &ws.rows[static_cast<std::size_t>(sy - lo) * un] : ws.zero.data();
        }
        float* dst = &ws.acc[static_cast<std::size_t>(y - y0) * un];
        float ws_[kTaps];
        for (int k = 0; k < kTaps; ++k) ws_[k] = t.scale * w[k];
        // Blocks of kLanes texels, loaded before they are stored, so that the
        // compiler's -O2 (straight-line) vectoriser takes them: no aliasing
        // question, no remainder loop.
        std::size_t x = 0;
        for (; x + kLanes <= un; x += kLanes) {
            float v[kLanes];
            for (std::size_t j = 0; j < kLanes; ++j) v[j] = dst[x + j];
            for (int k = 0; k < kTaps; ++k)
                for (std::size_t j = 0; j < kLanes; ++j) v[j] += ws_[k] * r[k][x + j];
            for (std::size_t j = 0; j < kLanes; ++j) dst[x + j] = v[j];
        }
        for (; x < un; ++x)
            for (int k = 0; k < kTaps; ++k) dst[x] += ws_[k] * r[k][x];
    }
}

/// An anchor's monochromatic PSF on λ0's grid into `out` (fp32, unit sum), as
/// mono_psf_reference() draws it (the plane over W·λ/λ0) but transformed by
/// FFTW in fp32: the anchors are rescaled and summed in fp32 anyway (≈ 10%
/// faster than double here).
void anchor_psf(std::vector<float>& out, const EyeModel& eye, int n, double wavelength_nm, double time_s) {
    // The two-scale eye (eye_model.h): core and scatter at their own angular
    // scales, binned onto one grid, exactly as the exact reference builds it.
    if (has_two_scales(eye)) {
        const MonoPsf p = mono_psf_reference(eye, n, wavelength_nm, time_s);
        out.assign(p.value.begin(), p.value.end());  // unit sum already
        return;
    }
    const double w = eye.plane_width_mm * wavelength_nm / kReferenceWavelengthNm;
    const ComplexImage<double> field = pupil_plane(eye, n, wavelength_nm, w, time_s);
    ComplexImage<float> f(n);
    for (std::size_t i = 0; i < field.data.size(); ++i) f.data[i] = std::complex<float>(field.data[i]);
    fftw_forward(f);
    out.resize(f.data.size());
    const int h = n / 2;
    double sum = 0;
    for (int y = 0; y < n; ++y) {
        float* row = &out[static_cast<std::size_t>((y + h) % n) * n];
        for (int x = 0; x < n; ++x) {
            const float v = std::norm(f.at(x, y));  // |F|², K2012 eq 4.6
            row[(x + h) % n] = v;                   // eq 4.8's shift
            sum += v;
        }
    }
    if (sum > 0) {
        const auto inv = static_cast<float>(1 / sum);  // §4.2.3: unit sum
        for (float& v : out) v *= inv;
    }
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

namespace detail {

LanczosTaps lanczos_taps(int n, double ratio) {
    // |F|² is band-limited (the pupil's autocorrelation spans at most the
    // plane's half width), which a windowed sinc reproduces far better than
    // bilinear lookups: at the default eye's sampling (3 texels to the first
    // Airy zero) bilinear lookups alone leave 2% (relative L2) of the exact
    // path, Lanczos-3 a few tenths of that.
    constexpr double kLobes = kLanczosTaps / 2;
    LanczosTaps t;
    t.first.resize(static_cast<std::size_t>(n));
    t.weight.resize(static_cast<std::size_t>(n) * kLanczosTaps);
    const double c = n / 2;
    for (int i = 0; i < n; ++i) {
        const double s = c + (i - c) * ratio;
        const int first = static_cast<int>(std::floor(s)) - kLanczosTaps / 2 + 1;
        t.first[static_cast<std::size_t>(i)] = first;
        double sum = 0;
        double* w = &t.weight[static_cast<std::size_t>(i) * kLanczosTaps];
        // The taps' distances d0 − k share their sines: sin π(d0 − k) =
        // (−1)^k sin πd0, and sin π(d0 − k)/3 by the angle difference.
        const double d0 = s - first;
        const double sin_d0 = std::sin(std::numbers::pi * d0);
        const double sin_w = std::sin(std::numbers::pi * d0 / kLobes), cos_w = std::cos(std::numbers::pi * d0 / kLobes);
        for (int k = 0; k < kLanczosTaps; ++k) {
            const double d = d0 - k;
            if (std::abs(d) >= kLobes) {
                w[k] = 0.0;
            } else if (std::abs(d) < 1e-12) {
                w[k] = 1.0;
            } else {
                const double a = std::numbers::pi * k / kLobes;
                const double sin_pd = (k % 2 == 0 ? 1.0 : -1.0) * sin_d0;
                const double sin_pd3 = sin_w * std::cos(a) - cos_w * std::sin(a);
                const double pd = std::numbers::pi * d;
                w[k] = sin_pd / pd * (sin_pd3 / (pd / kLobes));
            }
            sum += w[k];
        }
        for (int k = 0; k < kLanczosTaps; ++k) w[k] /= sum;
    }
    return t;
}

std::vector<SpectralSample> spectral_recipe(const std::vector<double>& anchor_nm, const SpectralSamples& samples,
                                            int n) {
    // Anchors per sample between the outer anchors: 4, cubic in 1/λ (quadratic
    // left 0.0044 with the default eye at N = 512, cubic 0.0032).
    constexpr std::size_t kOrder = 4;
    const std::size_t k = anchor_nm.size();
    double brightest = 0;
    for (const auto& w : samples.xyz_weight) brightest = std::max(brightest, sample_weight(w));
    std::vector<SpectralSample> recipe;
    for (std::size_t s = 0; s < samples.wavelength_nm.size(); ++s) {
        const double lambda = samples.wavelength_nm[s];
        // The (up to) kOrder anchors nearest in 1/λ, and their Lagrange weights in 1/λ.
        std::vector<std::size_t> near(k);
        for (std::size_t i = 0; i < k; ++i) near[i] = i;
        std::sort(near.begin(), near.end(), [&](std::size_t i, std::size_t j) {
            return std::abs(1 / anchor_nm[i] - 1 / lambda) <
                   std::abs(1 / anchor_nm[j] - 1 / lambda);
        });
        // Beyond the outer anchors (the spectrum's 1% tails) the two nearest
        // extrapolate linearly, and a sample with under 1% of the brightest
        // sample's weight takes the nearest alone (a third fewer rescales for
        // D65). Between them a sample under a quarter of the brightest's weight
        // is linear in its two nearest: with the default eye at N = 512 that
        // left 0.0029 from the exact path where cubic everywhere left 0.0032.
        const bool tail = lambda < anchor_nm.front() || lambda > anchor_nm.back();
        const double weight = sample_weight(samples.xyz_weight[s]);
        const bool faint = weight < 0.01 * brightest, weak = weight < 0.25 * brightest;
        near.resize(std::min<std::size_t>(k, tail ? (faint ? 1 : 2) : (weak ? 2 : kOrder)));
        SpectralSample sample{glm::vec3(samples.xyz_weight[s]), {}};
        for (std::size_t i : near) {
            double share = 1;
            for (std::size_t j : near)
                if (j != i)
                    share *= (1 / lambda - 1 / anchor_nm[j]) /
                             (1 / anchor_nm[i] - 1 / anchor_nm[j]);
            if (share == 0) continue;
            // K2012 eq 4.9 from the anchor λk: F_λ(x) = F_λk(x λk/λ) (λk/λ)².
            const double ratio = anchor_nm[i] / lambda;
            SpectralTerm t{i, ratio, static_cast<float>(share * ratio * ratio), {}};
            if (ratio != 1.0) t.taps = lanczos_taps(n, ratio);
            sample.terms.push_back(std::move(t));
        }
        recipe.push_back(std::move(sample));
    }
    return recipe;
}

}  // namespace detail

namespace {

void add_bands(BandSpace& ws, const std::vector<std::vector<float>>& source, const std::vector<Sample>& terms, int n,
               int first_band, int end_band, RgbPsf& out);

/// spectral_psf_from_anchors() on the anchors' PSFs already in ws.source
/// (fp32, unit sum, on λ0's grid) at wavelengths `anchor_nm` (ascending).
RgbPsf from_sources(Workspace& ws, int n, double degrees_per_texel, const std::vector<double>& anchor_nm,
                    const SpectralSamples& samples) {
    const auto un = static_cast<std::size_t>(n);
    std::vector<Sample> terms;
    for (detail::SpectralSample& r : detail::spectral_recipe(anchor_nm, samples, n)) {
        Sample sample{r.xyz, {}};
        for (detail::SpectralTerm& rt : r.terms) {
            Term t;
            static_cast<detail::SpectralTerm&>(t) = std::move(rt);
            if (t.ratio != 1.0) {
                t.w.assign(t.taps.weight.begin(), t.taps.weight.end());
                prepare_x_pass(t, n);
            }
            sample.terms.push_back(std::move(t));
        }
        terms.push_back(std::move(sample));
    }

    // Band by band: every sample's terms into the band's X, Y and Z, then the
    // band to linear Rec.709 (XYZ → RGB clipped at 0, as spectral_psf_exact).
    // The bands are independent: they are shared among the cores (issue 27
    // item 3), each computed as it would be alone (bit-identical results).
    RgbPsf out;
    out.n = n;
    out.degrees_per_texel = degrees_per_texel;
    out.rgb.resize(un * un);
    const int band_count = (n + kBand - 1) / kBand;
    ws.bands.resize(std::max<std::size_t>(ws.bands.size(), static_cast<std::size_t>(detail::worker_count(band_count))));
    detail::parallel_chunks(band_count, [&](int first_band, int end_band, int worker) {
        add_bands(ws.bands[static_cast<std::size_t>(worker)], ws.source, terms, n, first_band, end_band, out);
    });
    const double y = out.luminance_sum();
    if (y > 0)
        for (auto& v : out.rgb) v /= y;
    return out;
}

/// The bands [first_band, end_band) of `out` (from_sources()).
void add_bands(BandSpace& ws, const std::vector<std::vector<float>>& source, const std::vector<Sample>& terms, int n,
               int first_band, int end_band, RgbPsf& out) {
    const auto un = static_cast<std::size_t>(n);
    ws.acc.resize(static_cast<std::size_t>(kBand) * un);
    ws.xyz.resize(3 * static_cast<std::size_t>(kBand) * un);
    ws.zero.assign(un, 0.0f);
    for (int band = first_band; band < end_band; ++band) {
        const int y0 = band * kBand;
        const int y1 = std::min(n, y0 + kBand);
        const std::size_t texels = static_cast<std::size_t>(y1 - y0) * un;
        float* bx = ws.xyz.data();
        float* by = bx + texels;
        float* bz = by + texels;
        std::fill(ws.xyz.begin(), ws.xyz.begin() + static_cast<std::ptrdiff_t>(3 * texels), 0.0f);
        for (const Sample& s : terms) {
            std::fill(ws.acc.begin(), ws.acc.begin() + static_cast<std::ptrdiff_t>(texels), 0.0f);
            for (const Term& t : s.terms) add_term_band(ws, n, y0, y1, t, source[t.anchor]);
            const float* a = ws.acc.data();
            std::size_t i = 0;
            for (; i + kLanes <= texels; i += kLanes) {  // blocks of texels, as in add_term_band
                float v[kLanes], b[3][kLanes];
                for (std::size_t j = 0; j < kLanes; ++j) {
                    v[j] = a[i + j];
                    b[0][j] = bx[i + j];
                    b[1][j] = by[i + j];
                    b[2][j] = bz[i + j];
                }
                for (std::size_t j = 0; j < kLanes; ++j) {
                    b[0][j] += s.xyz.x * v[j];
                    b[1][j] += s.xyz.y * v[j];
                    b[2][j] += s.xyz.z * v[j];
                }
                for (std::size_t j = 0; j < kLanes; ++j) {
                    bx[i + j] = b[0][j];
                    by[i + j] = b[1][j];
                    bz[i + j] = b[2][j];
                }
            }
            for (; i < texels; ++i) {
                bx[i] += s.xyz.x * a[i];
                by[i] += s.xyz.y * a[i];
                bz[i] += s.xyz.z * a[i];
            }
        }
        glm::dvec3* dst = &out.rgb[static_cast<std::size_t>(y0) * un];
        for (std::size_t i = 0; i < texels; ++i)
            dst[i] = glm::max(display::xyz_to_linear_rgb({bx[i], by[i], bz[i]}), glm::dvec3(0.0));
    }
}

}  // namespace

RgbPsf spectral_psf_from_anchors(const std::vector<MonoPsf>& anchors, const SpectralSamples& samples) {
    Workspace& ws = workspace();
    ws.source.resize(std::max(ws.source.size(), anchors.size()));
    std::vector<double> anchor_nm;
    for (std::size_t i = 0; i < anchors.size(); ++i) {
        ws.source[i].assign(anchors[i].value.begin(), anchors[i].value.end());
        anchor_nm.push_back(anchors[i].wavelength_nm);
    }
    return from_sources(ws, anchors.front().n, anchors.front().degrees_per_texel, anchor_nm, samples);
}

RgbPsf spectral_psf_anchored(const EyeModel& eye, int n, const SpectralSamples& samples, int anchors, double time_s) {
    const std::vector<double> anchor_nm = spectral_anchor_wavelengths(samples, anchors);
    Workspace& ws = workspace();
    ws.source.resize(std::max(ws.source.size(), anchor_nm.size()));
    // Each anchor's PSF is independent of the others: the anchors are shared
    // among the cores (issue 27 item 3; each computed as it would be alone).
    detail::parallel_items(static_cast<int>(anchor_nm.size()), [&](int i) {
        const auto k = static_cast<std::size_t>(i);
        anchor_psf(ws.source[k], eye, n, anchor_nm[k], time_s);
    });
    return from_sources(ws, n, psf_degrees_per_texel(eye), anchor_nm, samples);
}

}  // namespace atonlab::stimuli
