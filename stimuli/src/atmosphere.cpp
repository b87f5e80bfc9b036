// Allard's law (K2012 eq 2.1, IALA E200-2) and Bouguer's law (K2012 eq 4.14).
//
// Allard's 0.05^(-d/V) is Bouguer's transmittance with the Koschmieder
// extinction sigma = -ln(0.05) / V: 0.05^(d/V) = exp(-sigma d). The constant
// 3.43e6 is 1852^2 (= 3 429 904) rounded: it turns lux at d nmi into cd.
#include "atonlab/stimuli/atmosphere.h"

#include <algorithm>
#include <cassert>
#include <climits>
#include <cmath>
#include <limits>

namespace atonlab::stimuli {
namespace {

constexpr double allard_constant = 3.43e6;  // IALA E200-2; ~ metres_per_nautical_mile^2
const double ln_twenty = std::log(20.0);    // -ln(0.05): the 5% contrast threshold of V

}  // namespace

double allard_intensity_cd(double range_nmi, double threshold_lux, double visibility_nmi, double background_factor) {
    assert(range_nmi >= 0 && threshold_lux > 0 && visibility_nmi > 0 && background_factor > 0);
    // K2012 eq 2.1: I = 3.43e6 * E_t * d^2 * 0.05^(-d/V), E_t scaled by the background factor.
    // 0.05^(-d/V) is written exp(d ln20 / V); V = +inf gives 1 (no extinction).
    return allard_constant * threshold_lux * background_factor * range_nmi * range_nmi *
           std::exp(range_nmi * ln_twenty / visibility_nmi);
}

double allard_range_nmi(double intensity_cd, double threshold_lux, double visibility_nmi, double background_factor) {
    assert(threshold_lux > 0 && visibility_nmi > 0 && background_factor > 0);
    // Domain ends: no light (I <= 0, or NaN) is seen at no range; an infinite one at any.
    if (!(intensity_cd > 0)) return 0;
    if (std::isinf(intensity_cd)) return std::numeric_limits<double>::infinity();

    // Solve h(u) = ln A + 2u + k e^u - ln I = 0 for u = ln d, where A = 3.43e6 E_t f
    // and k = ln20 / V. In u, h is increasing (h' = 2 + k e^u > 0) and convex, so
    // Newton from the right of the root moves monotonically onto it; working in
    // logs keeps every intensity from denormals to 1e308 finite.
    const double log_a = std::log(allard_constant * threshold_lux * background_factor);
    const double log_i = std::log(intensity_cd);
    const double k = ln_twenty / visibility_nmi;  // 1/nmi; 0 when V = inf

    // Upper bracket: without extinction d0 = sqrt(I / A) >= root; with d >= 1,
    // k d <= ln I - ln A bounds the root too. The smaller keeps k e^u finite.
    double d_hi = std::exp(0.5 * (log_i - log_a));
    if (k > 0) d_hi = std::min(d_hi, std::max(1.0, (log_i - log_a) / k));
    double hi = std::log(d_hi);
    // Lower bracket: e^root <= d_hi, so 2 root >= ln I - ln A - k d_hi.
    double lo = 0.5 * (log_i - log_a - k * d_hi);
    auto h = [&](double u) { return log_a + 2 * u + k * std::exp(u) - log_i; };

    double u = hi;
    for (int iter = 0; iter < 200; ++iter) {
        const double hu = h(u);
        if (hu == 0) break;
        if (hu > 0)
            hi = u;
        else
            lo = u;
        double next = u - hu / (2 + k * std::exp(u));
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // safeguard: bisect
        if (std::abs(next - u) <= 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(u))) break;
        u = next;
    }
    return std::exp(u);
}

int nominal_range_nmi(double intensity_cd) {
    // IALA E200-2 tabulates n nmi for intensities from I(n - 0.5) to I(n + 0.5):
    // e.g. I(5.5) = 107.80 cd, I(6.5) = 203.15 cd, I(7.5) = 364.94 cd give the
    // published 108..203 cd -> 6 nmi and 204..364 cd -> 7 nmi. So the range is
    // rounded to the nearest whole nmi (halves up), not down.
    const double d = allard_range_nmi(intensity_cd, allard_threshold_night_lux, 10.0);
    const double n = std::floor(d + 0.5);
    if (!(n < static_cast<double>(INT_MAX))) return INT_MAX;
    return static_cast<int>(n);
}

double allard_illuminance_lux(double intensity_cd, double range_nmi, double visibility_nmi) {
    assert(range_nmi >= 0 && visibility_nmi > 0);
    // K2012 eq 2.1 solved for E_t: E = I * 0.05^(d/V) / (3.43e6 d^2).
    return intensity_cd * std::exp(-range_nmi * ln_twenty / visibility_nmi) / (allard_constant * range_nmi * range_nmi);
}

double allard_transmissivity_per_nmi(double visibility_nmi) {
    assert(visibility_nmi > 0);
    return std::exp(-ln_twenty / visibility_nmi);  // 0.05^(1/V)
}

double visibility_nmi_from_transmissivity(double transmissivity_per_nmi) {
    assert(transmissivity_per_nmi > 0 && transmissivity_per_nmi < 1);
    return -ln_twenty / std::log(transmissivity_per_nmi);  // T^V = 0.05
}

IntensityBand nominal_range_band_cd(int range_nmi) {
    assert(range_nmi >= 0);
    const double n = range_nmi;
    return {range_nmi == 0 ? 0.0 : allard_intensity_cd(n - 0.5, allard_threshold_night_lux, 10.0),
            allard_intensity_cd(n + 0.5, allard_threshold_night_lux, 10.0)};
}

double extinction_per_m_from_visibility_m(double visibility_m) {
    assert(visibility_m > 0);
    // Koschmieder with the 5% contrast threshold of Allard's law: exp(-sigma V) = 0.05.
    return ln_twenty / visibility_m;
}

double bouguer_transmittance(double extinction_per_m, double distance_m) {
    assert(extinction_per_m >= 0 && distance_m >= 0);
    // No path, no extinction: T(0) = 1 even for sigma = inf (visibility 0), where
    // exp(-inf * 0) would be NaN (docs/numerical-behaviour.md).
    if (distance_m == 0) return 1.0;
    return std::exp(-extinction_per_m * distance_m);  // K2012 eq 4.14
}

}  // namespace atonlab::stimuli
