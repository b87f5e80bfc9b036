// profile_threshold_interval (profile_interval.h): the threshold is walked
// outward from its estimate on the fit's own axis (log10 levels for the
// Weibull) in doubling steps until the profile log-likelihood falls below the
// cut-off, then the crossing is bisected. At each threshold the other free
// parameters (ln beta, a free lambda or gamma) are maximised by NLopt's
// Subplex, warm-started from the neighbouring threshold's optimum.
#include "atonlab/analysis/profile_interval.h"

#include <nlopt.h>

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <limits>
#include <vector>

namespace atonlab::analysis {

namespace {

/// The profile problem: for a threshold s on the fit's axis, alpha follows
/// from beta (F(threshold) = p), and x = (ln beta, [gamma], [lambda]) is free.
struct Profile {
    std::span<const LevelCounts> data;
    Family family = Family::CumulativeNormal;
    double p = 0.5;  ///< threshold_proportion
    RateConstraint guess, lapse;
    std::vector<double> lower, upper;  ///< bounds of x
    int evaluations = 0;
    double s = 0.0;  ///< the threshold being profiled, fit axis

    /// alpha with F(threshold) = p for this beta (psychometric.h's families:
    /// location families on x, the Weibull a scale family on linear levels).
    std::optional<double> alpha_at(double beta) const {
        if (family == Family::Weibull) {
            const auto unit = sigmoid_inverse(family, p, 1.0, beta);
            if (!unit || !(*unit > 0.0)) return std::nullopt;
            return std::pow(10.0, s) / *unit;
        }
        const auto offset = sigmoid_inverse(family, p, 0.0, beta);
        if (!offset) return std::nullopt;
        return s - *offset;
    }

    PsiParams params(const double* x) const {
        PsiParams q;
        q.beta = std::exp(x[0]);
        std::size_t i = 1;
        q.gamma = guess.is_free() ? x[i++] : *guess.fixed;
        q.lambda = lapse.is_free() ? x[i++] : *lapse.fixed;
        q.alpha = alpha_at(q.beta).value_or(std::numeric_limits<double>::quiet_NaN());
        return q;
    }

    double negative_ll(const double* x) {
        ++evaluations;
        const PsiParams q = params(x);
        if (!std::isfinite(q.alpha) || q.gamma + q.lambda >= 1.0) return std::numeric_limits<double>::max();
        const double ll = log_likelihood(family, data, q);
        return std::isfinite(ll) ? -ll : std::numeric_limits<double>::max();
    }

    static double objective(unsigned, const double* x, double*, void* self) {
        return static_cast<Profile*>(self)->negative_ll(x);
    }

    /// The profile log-likelihood at threshold `at`; x is the start and, on
    /// return, the optimum.
    double at(double threshold, std::vector<double>& x) {
        s = threshold;
        nlopt_opt opt = nlopt_create(NLOPT_LN_SBPLX, static_cast<unsigned>(x.size()));
        nlopt_set_min_objective(opt, &Profile::objective, this);
        nlopt_set_lower_bounds(opt, lower.data());
        nlopt_set_upper_bounds(opt, upper.data());
        nlopt_set_xtol_abs1(opt, 1e-7);
        nlopt_set_ftol_abs(opt, 1e-9);
        nlopt_set_maxeval(opt, 600);
        for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::clamp(x[i], lower[i], upper[i]);
        double value = negative_ll(x.data());
        std::vector<double> y = x;
        double found = value;
        if (nlopt_optimize(opt, y.data(), &found) > 0 && found <= value) {
            x = y;
            value = found;
        }
        nlopt_destroy(opt);
        return -value;
    }
};

double internal_axis(Family f, double level) {
    return f == Family::Weibull ? std::log10(level) : level;
}

}  // namespace

ProfileInterval profile_threshold_interval(std::span<const LevelCounts> data, const PsychometricFit& fit,
                                           double level) {
    ProfileInterval out;
    if (!fit.estimate) {
        out.reason = fit.reason.empty() ? "no fit" : fit.reason;
        return out;
    }
    const FitOptions& o = fit.options;
    const PsychometricEstimate& e = *fit.estimate;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const LevelCounts& r : data) {
        if (r.n_trials <= 0 || (o.family == Family::Weibull && !(r.level > 0.0))) continue;
        lo = std::min(lo, internal_axis(o.family, r.level));
        hi = std::max(hi, internal_axis(o.family, r.level));
    }
    const double range = hi - lo;
    if (!(range > 0.0) || !(e.params.beta > 0.0) || (o.family == Family::Weibull && !(e.threshold > 0.0))) {
        out.reason = "the levels tested span no range";
        return out;
    }
    Profile prof;
    prof.data = data;
    prof.family = o.family;
    prof.p = o.threshold_proportion;
    prof.guess = o.guess;
    prof.lapse = o.lapse;
    std::vector<double> x_hat{std::log(e.params.beta)};
    // ln beta within e^7 (a factor of about 1100) of its estimate: far past
    // any slope the data could support at an interval's end.
    prof.lower.push_back(x_hat[0] - 7.0);
    prof.upper.push_back(x_hat[0] + 7.0);
    for (const auto& [rate, value] : {std::pair{o.guess, e.params.gamma}, std::pair{o.lapse, e.params.lambda}}) {
        if (!rate.is_free()) continue;
        x_hat.push_back(value);
        prof.lower.push_back(rate.lower);
        prof.upper.push_back(std::max(rate.upper, rate.lower + 1e-12));
    }
    const double s_hat = internal_axis(o.family, e.threshold);
    std::vector<double> x0 = x_hat;
    const double ll_max = std::max(e.log_likelihood, prof.at(s_hat, x0));
    const boost::math::chi_squared chi2(1.0);
    const double cut = ll_max - 0.5 * boost::math::quantile(chi2, level);

    // Each end: doubling steps outward from the estimate, then bisection.
    const double limits[2] = {lo - range, hi + range};
    double ends[2] = {0.0, 0.0};
    for (int side = 0; side < 2; ++side) {
        const double dir = side == 0 ? -1.0 : 1.0;
        const double limit = limits[side];
        double inner = s_hat, step = range / 64.0;
        std::vector<double> x_in = x0;
        bool open = true;
        double outer = inner;
        std::vector<double> x_out;
        while (dir * (limit - inner) > 0.0) {
            outer = dir > 0 ? std::min(inner + step, limit) : std::max(inner - step, limit);
            x_out = x_in;
            if (prof.at(outer, x_out) < cut) {
                open = false;
                break;
            }
            inner = outer;
            x_in = x_out;
            step *= 2.0;
        }
        if (open) {
            ends[side] = limit;
            (side == 0 ? out.lower_open : out.upper_open) = true;
            continue;
        }
        for (int i = 0; i < 40 && std::abs(outer - inner) > 1e-9 * std::max(1.0, range); ++i) {
            const double mid = 0.5 * (inner + outer);
            std::vector<double> x_mid = x_in;
            if (prof.at(mid, x_mid) >= cut) {
                inner = mid;
                x_in = x_mid;
            } else {
                outer = mid;
            }
        }
        ends[side] = 0.5 * (inner + outer);
    }
    const auto level_of = [&](double s) { return o.family == Family::Weibull ? std::pow(10.0, s) : s; };
    out.ci = Interval{level_of(ends[0]), level_of(ends[1]), level};
    out.n_evaluations = prof.evaluations;
    return out;
}

}  // namespace atonlab::analysis
