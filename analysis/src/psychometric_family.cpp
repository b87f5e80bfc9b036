// The four sigmoids F(x; alpha, beta) and Psi built on them (psychometric.h).
// Distributions from Boost.Math: normal, logistic, extreme value (Gumbel as the
// minimum extreme-value law on log10 levels) and Weibull.
#include <boost/math/distributions/extreme_value.hpp>
#include <boost/math/distributions/logistic.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/weibull.hpp>
#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <numbers>

#include "atonlab/analysis/psychometric.h"
#include "family_kernel.h"
#include "stats_policy.h"

namespace atonlab::analysis {

using detail::StatsPolicy;

std::string_view to_string(Family f) noexcept {
    switch (f) {
        case Family::CumulativeNormal:
            return "normal";
        case Family::Logistic:
            return "logistic";
        case Family::Weibull:
            return "weibull";
        case Family::Gumbel:
            return "gumbel";
    }
    return "normal";
}

std::optional<Family> parse_family(std::string_view text) noexcept {
    if (text == "normal" || text == "cumulative-normal" || text == "gaussian") return Family::CumulativeNormal;
    if (text == "logistic") return Family::Logistic;
    if (text == "weibull") return Family::Weibull;
    if (text == "gumbel" || text == "log-weibull") return Family::Gumbel;
    return std::nullopt;
}

namespace detail {

// The standard sigmoid G(z) of each kernel and its derivative g(z) = dG/dz.
// The Gumbel kernel is written in z = beta (u - alpha), u in log10 units:
// G(z) = 1 - exp(-10^z) = 1 - H(-z ln10), H the (maximum) extreme-value cdf.
KernelValue kernel(Kernel k, double z) noexcept {
    if (std::isnan(z)) return {0.0, 0.0};
    if (std::isinf(z)) return {z > 0 ? 1.0 : 0.0, 0.0};
    switch (k) {
        case Kernel::Normal: {
            const boost::math::normal_distribution<double, StatsPolicy> n;
            return {boost::math::cdf(n, z), boost::math::pdf(n, z)};
        }
        case Kernel::Logistic: {
            const boost::math::logistic_distribution<double, StatsPolicy> l;
            return {boost::math::cdf(l, z), boost::math::pdf(l, z)};
        }
        case Kernel::Gumbel: {
            constexpr double ln10 = std::numbers::ln10;
            const boost::math::extreme_value_distribution<double, StatsPolicy> ev;
            const double w = -z * ln10;
            if (w > 700.0) return {0.0, 0.0};   // 10^z underflows: F = 0 (Boost's exp(exp) would overflow)
            if (w < -700.0) return {1.0, 0.0};  // F = 1 to double precision
            return {boost::math::cdf(boost::math::complement(ev, w)), ln10 * boost::math::pdf(ev, w)};
        }
    }
    return {0.0, 0.0};
}

std::optional<double> kernel_quantile(Kernel k, double p) noexcept {
    if (!(p > 0.0 && p < 1.0)) return std::nullopt;
    double z = 0.0;
    switch (k) {
        case Kernel::Normal:
            z = boost::math::quantile(boost::math::normal_distribution<double, StatsPolicy>(), p);
            break;
        case Kernel::Logistic:
            z = boost::math::quantile(boost::math::logistic_distribution<double, StatsPolicy>(), p);
            break;
        case Kernel::Gumbel: {
            // 1 - H(w) = p  <=>  w = H^-1 complement(p); z = -w / ln10.
            const boost::math::extreme_value_distribution<double, StatsPolicy> ev;
            z = -boost::math::quantile(boost::math::complement(ev, p)) / std::numbers::ln10;
            break;
        }
    }
    if (!std::isfinite(z)) return std::nullopt;
    return z;
}

Kernel kernel_of(Family f) noexcept {
    switch (f) {
        case Family::CumulativeNormal:
            return Kernel::Normal;
        case Family::Logistic:
            return Kernel::Logistic;
        case Family::Weibull:
        case Family::Gumbel:
            return Kernel::Gumbel;
    }
    return Kernel::Normal;
}

}  // namespace detail

namespace {

bool valid_ab(Family f, double alpha, double beta) noexcept {
    if (!std::isfinite(alpha) || !std::isfinite(beta) || beta <= 0.0) return false;
    return f != Family::Weibull || alpha > 0.0;
}

}  // namespace

double sigmoid(Family f, double x, double alpha, double beta) noexcept {
    if (!valid_ab(f, alpha, beta) || std::isnan(x)) return 0.0;
    if (f == Family::Weibull) {
        if (x <= 0.0) return 0.0;
        if (std::isinf(x)) return 1.0;
        const boost::math::weibull_distribution<double, StatsPolicy> w(beta, alpha);
        return boost::math::cdf(w, x);
    }
    return detail::kernel(detail::kernel_of(f), beta * (x - alpha)).value;
}

double sigmoid_derivative(Family f, double x, double alpha, double beta) noexcept {
    if (!valid_ab(f, alpha, beta) || !std::isfinite(x)) return 0.0;
    if (f == Family::Weibull) {
        if (x <= 0.0) return 0.0;
        const boost::math::weibull_distribution<double, StatsPolicy> w(beta, alpha);
        const double d = boost::math::pdf(w, x);
        return std::isfinite(d) ? d : 0.0;
    }
    return beta * detail::kernel(detail::kernel_of(f), beta * (x - alpha)).derivative;
}

std::optional<double> sigmoid_inverse(Family f, double p, double alpha, double beta) noexcept {
    if (!valid_ab(f, alpha, beta) || !(p > 0.0 && p < 1.0)) return std::nullopt;
    if (f == Family::Weibull) {
        const boost::math::weibull_distribution<double, StatsPolicy> w(beta, alpha);
        const double x = boost::math::quantile(w, p);
        if (!std::isfinite(x)) return std::nullopt;
        return x;
    }
    const auto z = detail::kernel_quantile(detail::kernel_of(f), p);
    if (!z) return std::nullopt;
    const double x = alpha + *z / beta;
    if (!std::isfinite(x)) return std::nullopt;
    return x;
}

double psi(Family f, double x, const PsiParams& p) noexcept {
    return p.gamma + (1.0 - p.gamma - p.lambda) * sigmoid(f, x, p.alpha, p.beta);
}

double psi_derivative(Family f, double x, const PsiParams& p) noexcept {
    return (1.0 - p.gamma - p.lambda) * sigmoid_derivative(f, x, p.alpha, p.beta);
}

std::optional<double> psi_inverse(Family f, double target, const PsiParams& p) noexcept {
    const double scale = 1.0 - p.gamma - p.lambda;
    if (!(scale > 0.0) || !(target > p.gamma && target < 1.0 - p.lambda)) return std::nullopt;
    return sigmoid_inverse(f, (target - p.gamma) / scale, p.alpha, p.beta);
}

std::optional<double> sigmoid_width(Family f, double alpha, double beta, double width_alpha) noexcept {
    if (!(width_alpha > 0.0 && width_alpha < 0.5)) return std::nullopt;
    const auto lo = sigmoid_inverse(f, width_alpha, alpha, beta);
    const auto hi = sigmoid_inverse(f, 1.0 - width_alpha, alpha, beta);
    if (!lo || !hi) return std::nullopt;
    return *hi - *lo;
}

std::optional<PsiParams> from_threshold_width(Family f, double threshold, double width, double threshold_proportion,
                                              double width_alpha) noexcept {
    if (!std::isfinite(threshold) || !std::isfinite(width) || width <= 0.0) return std::nullopt;
    if (!(threshold_proportion > 0.0 && threshold_proportion < 1.0)) return std::nullopt;
    if (!(width_alpha > 0.0 && width_alpha < 0.5)) return std::nullopt;
    if (f != Family::Weibull) {
        const detail::Kernel k = detail::kernel_of(f);
        const auto z_lo = detail::kernel_quantile(k, width_alpha);
        const auto z_hi = detail::kernel_quantile(k, 1.0 - width_alpha);
        const auto z_t = detail::kernel_quantile(k, threshold_proportion);
        if (!z_lo || !z_hi || !z_t) return std::nullopt;
        const double beta = (*z_hi - *z_lo) / width;
        return PsiParams{threshold - *z_t / beta, beta, 0.0, 0.0};
    }
    // Weibull on linear levels: with c(q) = -ln(1 - q), x(q) = alpha c(q)^(1/beta),
    // so width / threshold = A^s - B^s, s = 1/beta, A = c(1-a)/c(p), B = c(a)/c(p).
    // That ratio rises monotonically from 0 (s -> 0) when A > 1 > B, i.e. a < p < 1 - a.
    if (threshold <= 0.0 || !(threshold_proportion > width_alpha && threshold_proportion < 1.0 - width_alpha))
        return std::nullopt;
    const double c_t = -std::log1p(-threshold_proportion);
    const double A = -std::log(width_alpha) / c_t;  // c(1 - a) = -ln(a)
    const double B = -std::log1p(-width_alpha) / c_t;
    const double target = width / threshold;
    auto r = [&](double s) { return std::pow(A, s) - std::pow(B, s) - target; };
    double hi = 1.0;
    for (int i = 0; i < 200 && r(hi) < 0.0; ++i) hi *= 2.0;
    if (r(hi) < 0.0) return std::nullopt;
    double lo = hi;
    for (int i = 0; i < 2000 && r(lo) > 0.0; ++i) lo *= 0.5;
    if (r(lo) > 0.0) return std::nullopt;
    if (lo == hi) lo = 0.5 * hi;
    boost::math::tools::eps_tolerance<double> tol(52);
    std::uintmax_t iterations = 200;
    const auto [s_lo, s_hi] = boost::math::tools::toms748_solve(r, lo, hi, tol, iterations, StatsPolicy());
    const double s = 0.5 * (s_lo + s_hi);
    if (!(s > 0.0) || !std::isfinite(s)) return std::nullopt;
    const double beta = 1.0 / s;
    const double alpha = threshold / std::pow(c_t, s);
    if (!std::isfinite(alpha) || !std::isfinite(beta)) return std::nullopt;
    return PsiParams{alpha, beta, 0.0, 0.0};
}

}  // namespace atonlab::analysis
