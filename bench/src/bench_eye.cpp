// The default eye's PSF against optics and the CIE (docs/glare.md,
// "Validation"): for pupils of 3, 5 and 7 mm, the core's FWHM against the
// diffraction limit, the encircled energy at 0.1°, 0.5° and 1°, the PSF per
// steradian at 1° … 20° against both CIE equations of a 25-year-old (the CIE
// glare spread function of CIE 135/1-1999, which the `cie` model uses, and the
// CIE 146:2002 General Disability Glare equation), and the lenticular halo's
// radius and colour order.
// Written as eye_validation.md next to bench.md; one row per pupil in bench.csv
// with the time the PSF took.
#include <fmt/format.h>

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "atonlab/stimuli/cie_glare.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/psf.h"
#include "bench_common.h"

namespace atonlab::bench {

using namespace atonlab::stimuli;
using namespace atonlab::display;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRadPerDeg = kPi / 180.0;

// The CIE observer both equations are evaluated for (cie_glare.h): 25 years,
// brown eyes.
constexpr CieObserver kObserver{25.0, 0.5};

/// |F(θ)|² of a pupil-plane field (n×n over width_mm) at angle θ (rad) along
/// x (axis 0) or y (axis 1), by the direct sum over the field's projection on
/// that axis: exact at any angle, no grid.
double intensity_on_axis(const std::vector<std::complex<double>>& projection, double width_mm, double theta_rad,
                         double wavelength_mm) {
    const int n = static_cast<int>(projection.size());
    const double h = width_mm / n;
    std::complex<double> f(0.0);
    for (int i = 0; i < n; ++i) {
        const double x = (i + 0.5 - 0.5 * n) * h;
        f += projection[static_cast<std::size_t>(i)] * std::polar(1.0, -2 * kPi * x * theta_rad / wavelength_mm);
    }
    return std::norm(f);
}

/// Full width at half maximum (rad) of the core, averaged over the x and y
/// axes, by bisection on the direct sum.
double core_fwhm_rad(const EyeModel& eye, int n) {
    const PupilParts parts = pupil_parts(eye, n, kReferenceWavelengthNm, eye.plane_width_mm);
    const double lambda_mm = kReferenceWavelengthNm * 1e-6;
    double sum = 0;
    for (int axis = 0; axis < 2; ++axis) {
        std::vector<std::complex<double>> proj(static_cast<std::size_t>(n), 0.0);
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) proj[static_cast<std::size_t>(axis == 0 ? i : j)] += parts.core.at(i, j);
        const double peak = intensity_on_axis(proj, eye.plane_width_mm, 0.0, lambda_mm);
        // The first zero of the Airy pattern (1.22 λ/D) bounds the half-maximum from above.
        double lo = 0, hi = 1.22 * lambda_mm / eye.pupil_diameter_mm;
        for (int k = 0; k < 50; ++k) {
            const double mid = 0.5 * (lo + hi);
            (intensity_on_axis(proj, eye.plane_width_mm, mid, lambda_mm) > 0.5 * peak ? lo : hi) = mid;
        }
        sum += lo + hi;  // 2 × the half width
    }
    return 0.5 * sum;
}

/// Fraction of a centred PSF's energy in texels whose centres lie within θ.
double encircled(const MonoPsf& p, double theta_deg) {
    const double r = theta_deg / p.degrees_per_texel;
    double s = 0;
    for (int y = 0; y < p.n; ++y)
        for (int x = 0; x < p.n; ++x)
            if (std::hypot(x - p.n / 2, y - p.n / 2) <= r) s += p.at(x, y);
    return s;
}

/// Mean PSF per steradian over the ring of texel centres within ±5% (at least
/// ±1 texel) of θ; NaN where the ring leaves the grid's inscribed circle.
double per_sr(const MonoPsf& p, double theta_deg) {
    const double r = theta_deg / p.degrees_per_texel, w = std::max(1.0, 0.05 * r);
    if (r + w > p.n / 2 - 1) return std::nan("");
    double s = 0;
    int count = 0;
    for (int y = 0; y < p.n; ++y)
        for (int x = 0; x < p.n; ++x)
            if (std::abs(std::hypot(x - p.n / 2, y - p.n / 2) - r) <= w) {
                s += p.at(x, y);
                ++count;
            }
    const double texel_sr = std::pow(p.degrees_per_texel * kRadPerDeg, 2);
    return s / count / texel_sr;
}

/// The ring (degrees) of the largest azimuthal mean of channel c (3: luminance)
/// beyond from_deg.
double halo_peak_deg(const RgbPsf& p, int c, double from_deg) {
    const int n = p.n;
    std::vector<double> sum(static_cast<std::size_t>(n / 2), 0.0), count(sum.size(), 0.0);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const auto k = static_cast<std::size_t>(std::hypot(x - n / 2, y - n / 2));
            if (k >= sum.size()) continue;
            const glm::dvec3& v = p.at(x, y);
            sum[k] += c == 3 ? luminance_of_linear_rgb(v) : v[c];
            count[k] += 1;
        }
    auto first = static_cast<std::size_t>(std::ceil(from_deg / p.degrees_per_texel));
    std::size_t best = first;
    for (std::size_t k = first; k < sum.size(); ++k)
        if (sum[k] / count[k] > sum[best] / count[best]) best = k;
    return (static_cast<double>(best) + 0.5) * p.degrees_per_texel;
}

std::string cell(double v, const char* format) {
    return std::isnan(v) ? std::string("—") : fmt::format(fmt::runtime(format), v);
}

}  // namespace

void bench_eye_validation(Bench& b) {
    const int n = b.quick() ? 256 : 512;
    const int n_far = b.quick() ? 256 : 2048;  // the far angles need the larger grid
    const std::vector<double> pupils = b.quick() ? std::vector<double>{5.0} : std::vector<double>{3.0, 5.0, 7.0};
    const std::vector<double> angles = {1.0, 2.0, 5.0, 10.0, 20.0};
    const SpectralSamples samples = spectral_samples(d65_spectrum(), 30);

    std::string md = fmt::format(
        "# Eye validation: the default eye against optics and the CIE glare equations\n\n"
        "`atonlab bench --only eye_validation`. The default eye (two scales, in focus, gratings and particles, "
        "halo at 4°), N = {} (the default; per-steradian values at N = {} to reach the far angles), λ0 = 575 nm "
        "for the monochromatic columns. The halo columns: the same eye with its particles off (their scatter is "
        "brighter than the halo at 4°), D65 with 30 samples, the largest azimuthal mean beyond 2°. CIE (sr⁻¹, age "
        "{} years, pigmentation {}): GSF, the CIE glare spread function of Vos & van den Berg (CIE 135/1-1999), "
        "the `{}` model's equation; General, the CIE 146:2002 General Disability Glare equation (valid 0.1° … "
        "100°).\n\n",
        n, n_far, kObserver.age_years, kObserver.pigmentation, glare_model_name(GlareModel::cie));
    md +=
        "| pupil | core FWHM (arcmin) | diffraction limit 1.029 λ/D | ratio | core share | EE 0.1° | EE 0.5° | "
        "EE 1° | halo peak (luminance, gratings) | red / blue peak | colour order "
        "|\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    // The two CIE equations at the angles (they do not depend on the pupil).
    std::string cie = "| θ | GSF (CIE 135/1) | General (CIE 146) | GSF / General |\n|---|---|---|---|\n";
    for (double a : angles) {
        const double g = cie_gsf_veil_per_lux(a, kObserver), c = cie146_general_veil_per_lux(a, kObserver);
        cie += fmt::format("| {}° | {:.4g} | {:.4g} | {:.3f} |\n", a, g, c, g / c);
    }
    std::string sr = "| pupil | N |";
    std::string sr_rule = "|---|---|";
    for (double a : angles) {
        sr += fmt::format(" PSF/sr at {0}° | ÷ GSF | ÷ General |", a);
        sr_rule += "---|---|---|";
    }
    sr += "\n" + sr_rule + "\n";

    for (double p : pupils) {
        EyeModel eye;
        eye.pupil_diameter_mm = p;
        MonoPsfParts parts;
        MonoPsf mono;
        const Timing build = measure_void(
            [&] {
                parts = mono_psf_parts(eye, n, kReferenceWavelengthNm);
                mono = parts.scatter;
                bin_into(parts.core, parts.core_fraction, mono);
            },
            TimeSpec{0, 1, false});
        // The halo on the gratings alone: in the default eye the particles'
        // scatter falls across it brighter than it (docs/glare.md).
        EyeModel gratings = eye;
        gratings.lens_particles.enabled = false;
        gratings.vitreous_particles.enabled = false;
        const RgbPsf rgb = spectral_psf_resampled(mono_psf_reference(gratings, n, kReferenceWavelengthNm), samples);

        const double fwhm = core_fwhm_rad(eye, n) / kRadPerDeg * 60;
        const double limit = 1.029 * kReferenceWavelengthNm * 1e-9 / (p * 1e-3) / kRadPerDeg * 60;
        // The gratings start at 1.6 mm: a pupil inside that has no halo.
        const bool halo = 0.5 * p > eye.gratings.inner_radius_mm;
        const double from = 0.5 * *eye.halo_radius_deg;
        const double lum = halo ? halo_peak_deg(rgb, 3, from) : std::nan("");
        const double red = halo ? halo_peak_deg(rgb, 0, from) : std::nan("");
        const double blue = halo ? halo_peak_deg(rgb, 2, from) : std::nan("");
        md += fmt::format("| {} mm | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {} | {} | {} |\n",
                          p, fwhm, limit, fwhm / limit, parts.core_fraction, encircled(mono, 0.1), encircled(mono, 0.5),
                          encircled(mono, 1.0), halo ? fmt::format("{:.2f}°", lum) : "none",
                          halo ? fmt::format("{:.2f}° / {:.2f}°", red, blue) : "—",
                          halo ? (red > blue ? "red outside" : "blue outside") : "—");

        for (int size : {n, n_far}) {
            if (size == n_far && n_far == n) continue;
            const MonoPsf far = size == n ? mono : mono_psf_reference(eye, size, kReferenceWavelengthNm);
            sr += fmt::format("| {} mm | {} |", p, size);
            for (double a : angles) {
                const double v = per_sr(far, a);
                const double g = cie_gsf_veil_per_lux(a, kObserver), c = cie146_general_veil_per_lux(a, kObserver);
                sr += fmt::format(" {} | {} | {} |", cell(v, "{:.4g}"), cell(v / g, "{:.3g}"), cell(v / c, "{:.3g}"));
            }
            sr += "\n";
        }

        Row r;
        r.bench = "eye_validation";
        r.setting = fmt::format("{} mm pupil", p);
        r.is_default = false;
        r.time = build;
        r.error = std::abs(fwhm / limit - 1);
        r.metric = "|core FWHM / diffraction limit 1.029 λ/D − 1|; the whole table in eye_validation.md";
        r.note = fmt::format("core FWHM {:.3f}′ (limit {:.3f}′), EE(1°) {:.3f}, halo {}", fwhm, limit,
                             encircled(mono, 1.0), halo ? fmt::format("{:.2f}°", lum) : "none");
        b.add(r);
        if (b.options.verbose) std::printf("eye_validation: %.0f mm done\n", p);
    }
    md += "\nThe two CIE equations at the angles of the comparison:\n\n" + cie +
          "\nPSF per steradian (λ0, azimuthal mean over ±5% of the angle) divided by each CIE equation; — where "
          "the angle lies beyond the PSF's grid (the glare beyond it is not drawn by the billboard).\n\n" +
          sr;
    b.documents.emplace_back("eye_validation.md", md);
}

}  // namespace atonlab::bench
