// The CIE glare spread function (Vos & van den Berg, CIE 135/1-1999) and its
// energy-conserving form, and the CIE 146:2002 General Disability Glare equation
// that the eye validation compares with (cie_glare.h has both and the definition).
#include "atonlab/stimuli/cie_glare.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "atonlab/stimuli/error.h"

namespace atonlab::stimuli {

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
// Below this angle the GSF's energy (∝ θ²) is under 1e-10 of the light's.
constexpr double kSmallestDeg = 1e-7;

/// ∫ density(θ) 2π sin θ dθ (θ in rad) over [θ0, θ1] degrees, by Simpson's rule
/// in u = ln θ: dθ = θ du, so the integrand is density · 2π sin θ · θ.
template <class Density>
double ring_integral(const Density& density, double theta0_deg, double theta1_deg) {
    const double a = std::max(theta0_deg, kSmallestDeg), b = std::min(theta1_deg, 180.0);
    if (!(b > a)) return 0.0;
    const double u0 = std::log(a), u1 = std::log(b);
    // ~3000 intervals per unit of ln θ: the steepest term (0.0046°) changes
    // over about one unit, so Simpson's error is far below 1e-9.
    int intervals = static_cast<int>(std::ceil((u1 - u0) * 3000.0));
    intervals += intervals % 2;
    intervals = std::max(intervals, 2);
    const double h = (u1 - u0) / intervals;
    double sum = 0;
    for (int i = 0; i <= intervals; ++i) {
        const double theta_deg = std::exp(u0 + i * h);
        const double theta = theta_deg * kDegToRad;
        const double w = (i == 0 || i == intervals) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
        sum += w * density(theta_deg) * 2.0 * std::numbers::pi * std::sin(theta) * theta;
    }
    return sum * h / 3.0;
}

}  // namespace

double cie_gsf_veil_per_lux(double theta_deg, const CieObserver& o) {
    // CIE 135/1-1999 glare spread function (Vos & van den Berg; θ in degrees, A in years, p pigmentation).
    const double t = std::abs(theta_deg);
    const double age4 = std::pow(o.age_years / 70.0, 4);
    const double p = o.pigmentation;
    auto lorentz = [t](double width_deg) { return 1.0 + (t / width_deg) * (t / width_deg); };
    const double core = 9.2e6 / std::pow(lorentz(0.0046), 1.5) + 1.5e5 / std::pow(lorentz(0.045), 1.5);
    const double u = lorentz(0.1);
    const double wide = 400.0 / u + 3e-8 * t * t + p * (1300.0 / std::pow(u, 1.5) + 0.8 / std::sqrt(u));
    return (1.0 - 0.08 * age4) * core + (1.0 + 1.6 * age4) * wide + 2.5e-3 * p;
}

double cie146_general_veil_per_lux(double theta_deg, const CieObserver& o) {
    // CIE 146:2002, General Disability Glare equation (valid 0.1° ≤ θ ≤ 100°).
    const double t = std::abs(theta_deg);
    const double p = o.pigmentation;
    return 10.0 / (t * t * t) + (5.0 / (t * t) + 0.1 * p / t) * (1.0 + std::pow(o.age_years / 62.5, 4)) + 0.0025 * p;
}

double CieGlareSpread::density_sr(double theta_deg) const {
    const double f = cie_gsf_veil_per_lux(theta_deg, observer);
    if (std::abs(theta_deg) >= kCieInnerDeg) return f;
    return at_inner_sr + (1.0 - kappa) * (f - at_inner_sr);
}

double cie_gsf_energy_between(const CieObserver& observer, double theta0_deg, double theta1_deg) {
    return ring_integral([&](double t) { return cie_gsf_veil_per_lux(t, observer); }, theta0_deg, theta1_deg);
}

double cie_energy_between(const CieGlareSpread& gsf, double theta0_deg, double theta1_deg) {
    // Split at 0.1°, where the GSF has a kink, so Simpson's rule sees two smooth pieces.
    double e = 0;
    if (theta0_deg < kCieInnerDeg)
        e += ring_integral([&](double t) { return gsf.density_sr(t); }, theta0_deg, std::min(theta1_deg, kCieInnerDeg));
    if (theta1_deg > kCieInnerDeg)
        e += ring_integral([&](double t) { return gsf.density_sr(t); }, std::max(theta0_deg, kCieInnerDeg), theta1_deg);
    return e;
}

CieGlareSpread cie_glare_spread(const CieObserver& observer) {
    if (!(observer.age_years >= 0.0 && observer.age_years <= 100.0))
        throw InputError(SourceLocation{"", 0, 0, "cie_age_years"},
                         fmt::format("cie_age_years must be an age from 0 to 100 years (the CIE glare "
                                     "equations' observers), got {}.",
                                     observer.age_years));
    if (!(observer.pigmentation >= 0.0 && observer.pigmentation <= 1.2))
        throw InputError(SourceLocation{"", 0, 0, "cie_pigmentation"},
                         fmt::format("cie_pigmentation must be from 0 (very dark eyes) to 1.2 (very light blue "
                                     "eyes), as the CIE defines it, got {}.",
                                     observer.pigmentation));
    CieGlareSpread g;
    g.observer = observer;
    g.at_inner_sr = cie_gsf_veil_per_lux(kCieInnerDeg, observer);
    // Energy of the equation outside 0.1°, and of its excess over f(0.1°) inside.
    const double outside = cie_gsf_energy_between(observer, kCieInnerDeg, 180.0);
    const double inner_total = cie_gsf_energy_between(observer, 0.0, kCieInnerDeg);
    const double inner_floor = g.at_inner_sr * 2.0 * std::numbers::pi * (1.0 - std::cos(kCieInnerDeg * kDegToRad));
    const double inner_excess = inner_total - inner_floor;
    // Σ = outside + inner_floor + (1 − κ) inner_excess = 1.
    g.kappa = 1.0 - (1.0 - outside - inner_floor) / inner_excess;
    if (!(g.kappa <= 1.0))
        throw InputError(SourceLocation{"", 0, 0, "cie_age_years"},
                         fmt::format("the CIE glare spread function for age {} and pigmentation {} scatters {:.3f} "
                                     "of the light beyond 0.1°, more than all of it, so no glare spread function "
                                     "can conserve energy; choose a younger age or a lower pigmentation.",
                                     observer.age_years, observer.pigmentation, outside + inner_floor));
    return g;
}

}  // namespace atonlab::stimuli
