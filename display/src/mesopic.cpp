// Scotopic and mesopic photometry: S/P ratios of spectra and CIE 191:2010's MES2 mesopic luminance.
// The V'(lambda) table lives in cie_tables.cpp.
#include "atonlab/display/mesopic.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "atonlab/common/input_error.h"

namespace atonlab::display {
namespace {

// CIE 191:2010 MES2: m = a + b log10(L_mes). a and b as the report prints them; note that they put m = 1
// at L_mes = 10^((1 - a)/b) = 4.998 cd/m² and m = 0 at 10^(-a/b) = 0.005005 cd/m², the ends of the
// mesopic range to the printed precision.
constexpr double kMesopicA = kMesopicAdaptationA;
constexpr double kMesopicB = kMesopicAdaptationB;
constexpr double kScotopicAt555 = kMesopicScotopicAt555;

// The standard's fixed-point iteration stops when m moves by less than this; m's own precision (the
// printed a and b have 4 decimals) is far coarser.
constexpr double kMTolerance = 1e-12;
// Iterations before the bracketed fallback below. For ordinary S/P ratios the iteration converges in a
// few tens of steps (a few hundred where m is near 0, e.g. S/P 0.25 at 0.02 cd/m²); for very high S/P
// ratios near the top of the range it need not converge at all ("Mathematical limitations of
// the CIE mesopic photometry system", Lighting Research & Technology, published online 21 August 2015).
constexpr int kMaxFixedPointIterations = 1000;

// CIE 191:2010's L_mes for a given m (mesopic cd/m²).
double mesopic_luminance_for(double m, double photopic_cd_m2, double scotopic_cd_m2) {
    return (m * photopic_cd_m2 + (1.0 - m) * scotopic_cd_m2 * kScotopicAt555) / (m + (1.0 - m) * kScotopicAt555);
}

// CIE 191:2010's m for a given L_mes, clamped to [0, 1]. L_mes is > 0 here (L_p > 0.005, S/P > 0).
double adaptation_for(double mesopic_cd_m2) {
    return std::clamp(kMesopicA + kMesopicB * std::log10(mesopic_cd_m2), 0.0, 1.0);
}

// Integral of spd against a luminous efficiency function with the spectrum's own step (a Riemann sum,
// as spectrum_to_xyz).
template <typename Efficiency>
double weighted_integral(const Spectrum& spd, Efficiency efficiency) {
    double sum = 0.0;
    for (std::size_t i = 0; i < spd.values.size(); ++i) {
        const double wavelength_nm = spd.first_nm + spd.step_nm * static_cast<double>(i);
        sum += spd.values[i] * efficiency(wavelength_nm);
    }
    return sum * spd.step_nm;
}

}  // namespace

double scotopic_to_photopic_ratio(const Spectrum& spd) {
    const double photopic = weighted_integral(spd, [](double nm) { return cie1931_cmf(nm).y; });
    const double scotopic = weighted_integral(spd, cie1951_scotopic_efficiency);
    if (!(photopic > 0.0) || !std::isfinite(photopic) || !std::isfinite(scotopic)) {
        throw InputError(
            "the spectrum has no photopic luminance between 360 and 830 nm, so it has no scotopic-to-photopic "
            "(S/P) ratio");
    }
    return (kScotopicEfficacyLmPerW * scotopic) / (kPhotopicEfficacyLmPerW * photopic);
}

double scotopic_luminance_cd_m2(const Spectrum& spd, double photopic_cd_m2) {
    return scotopic_to_photopic_ratio(spd) * photopic_cd_m2;
}

MesopicLuminance mesopic_luminance_cd_m2(double photopic_cd_m2, double s_p_ratio) {
    if (!std::isfinite(photopic_cd_m2) || photopic_cd_m2 < 0.0) {
        throw InputError(fmt::format("a mesopic luminance needs a finite photopic luminance >= 0 cd/m² (got {} cd/m²)",
                                     photopic_cd_m2));
    }
    if (!std::isfinite(s_p_ratio) || !(s_p_ratio > 0.0)) {
        throw InputError(fmt::format("a mesopic luminance needs a finite S/P ratio > 0 (got {})", s_p_ratio));
    }
    const double scotopic_cd_m2 = s_p_ratio * photopic_cd_m2;
    // CIE 191:2010 / CIE TN 007:2017: the system applies between 0.005 and 5 cd/m² photopic; above, vision
    // is photopic (m = 1), below, scotopic (m = 0).
    if (photopic_cd_m2 >= kMesopicUpperPhotopicCdM2) return {photopic_cd_m2, 1.0};
    if (photopic_cd_m2 <= kMesopicLowerPhotopicCdM2) return {scotopic_cd_m2, 0.0};

    // The standard's iteration: m_0 = 0.5, L_mes,n from m_(n-1), m_n from L_mes,n.
    double m = 0.5;
    for (int n = 0; n < kMaxFixedPointIterations; ++n) {
        const double next = adaptation_for(mesopic_luminance_for(m, photopic_cd_m2, scotopic_cd_m2));
        const bool converged = std::abs(next - m) < kMTolerance;
        m = next;
        if (converged) return {mesopic_luminance_for(m, photopic_cd_m2, scotopic_cd_m2), m};
    }
    // Not converged (an oscillating extreme S/P ratio): the fixed point is a root of
    // h(m) = m_of(L_mes(m)) − m, which is continuous with h(0) >= 0 and h(1) <= 0; bisect for it.
    double lo = 0.0;
    double hi = 1.0;
    for (int n = 0; n < 200 && hi - lo > kMTolerance; ++n) {
        const double mid = 0.5 * (lo + hi);
        const double h = adaptation_for(mesopic_luminance_for(mid, photopic_cd_m2, scotopic_cd_m2)) - mid;
        (h > 0.0 ? lo : hi) = mid;
    }
    m = 0.5 * (lo + hi);
    return {mesopic_luminance_for(m, photopic_cd_m2, scotopic_cd_m2), m};
}

}  // namespace atonlab::display
