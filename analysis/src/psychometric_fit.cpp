// Binomial maximum-likelihood fit of Psi (psychometric.h): a coarse grid over
// (alpha, ln beta), then NLopt's SLSQP (bounded, analytic gradient) from the
// best grid points. Palamedes' PAL_PFML_Fit does the same in spirit (a brute
// search grid, then Nelder-Mead); psignifit 4 integrates a posterior instead.
#include <fmt/format.h>
#include <nlopt.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "atonlab/analysis/psychometric.h"
#include "family_kernel.h"
#include "fit_problem.h"

namespace atonlab::analysis {

namespace {

constexpr double kPsiFloor = 1e-12;  // Psi clamped to [kPsiFloor, 1 - kPsiFloor] in ln

void check_rate(const RateConstraint& r, const char* name) {
    if (r.fixed) {
        if (!(*r.fixed >= 0.0 && *r.fixed < 1.0))
            throw std::invalid_argument(fmt::format("FitOptions: fixed {} {} is outside [0, 1)", name, *r.fixed));
        return;
    }
    if (!(r.lower >= 0.0 && r.upper < 1.0 && r.lower <= r.upper))
        throw std::invalid_argument(
            fmt::format("FitOptions: free {} needs 0 <= lower <= upper < 1, got [{}, {}]", name, r.lower, r.upper));
}

double rate_max(const RateConstraint& r) noexcept {
    return r.fixed ? *r.fixed : r.upper;
}

void validate(const FitOptions& o) {
    check_rate(o.guess, "guess rate gamma");
    check_rate(o.lapse, "lapse rate lambda");
    if (rate_max(o.guess) + rate_max(o.lapse) > 1.0)
        throw std::invalid_argument("FitOptions: the largest gamma + lambda must be <= 1");
    if (!(o.threshold_proportion > 0.0 && o.threshold_proportion < 1.0))
        throw std::invalid_argument(
            fmt::format("FitOptions: threshold_proportion {} is outside (0, 1)", o.threshold_proportion));
    if (!(o.width_alpha > 0.0 && o.width_alpha < 0.5))
        throw std::invalid_argument(fmt::format("FitOptions: width_alpha {} is outside (0, 0.5)", o.width_alpha));
    for (const auto& b : {o.alpha_min, o.alpha_max})
        if (b && (!std::isfinite(*b) || (o.family == Family::Weibull && *b <= 0.0)))
            throw std::invalid_argument("FitOptions: alpha bounds must be finite (and > 0 for the Weibull)");
    if (o.alpha_min && o.alpha_max && !(*o.alpha_min < *o.alpha_max))
        throw std::invalid_argument("FitOptions: alpha_min must be < alpha_max");
    for (const auto& b : {o.beta_min, o.beta_max})
        if (b && !(std::isfinite(*b) && *b > 0.0))
            throw std::invalid_argument("FitOptions: beta bounds must be finite and > 0");
    if (o.beta_min && o.beta_max && !(*o.beta_min < *o.beta_max))
        throw std::invalid_argument("FitOptions: beta_min must be < beta_max");
}

double internal_axis(Family f, double level) noexcept {
    if (f != Family::Weibull) return level;
    return level > 0.0 ? std::log10(level) : -std::numeric_limits<double>::infinity();
}

double nlopt_objective(unsigned n, const double* x, double* grad, void* data) {
    auto* problem = static_cast<detail::FitProblem*>(data);
    return problem->evaluate(std::span<const double>(x, n), grad ? std::span<double>(grad, n) : std::span<double>());
}

}  // namespace

FitOptions FitOptions::yes_no(Family f) noexcept {
    FitOptions o;
    o.family = f;
    return o;
}

FitOptions FitOptions::two_afc(Family f) noexcept {
    FitOptions o;
    o.family = f;
    o.guess = RateConstraint::fixed_at(0.5);
    return o;
}

namespace detail {

double FitProblem::evaluate(std::span<const double> x, std::span<double> grad) {
    ++evaluations;
    const double a = x[0];
    const double beta = std::exp(x[1]);
    const double g = gamma_index >= 0 ? x[static_cast<std::size_t>(gamma_index)] : gamma_fixed;
    const double l = lambda_index >= 0 ? x[static_cast<std::size_t>(lambda_index)] : lambda_fixed;
    const double scale = 1.0 - g - l;
    double nll = 0.0;
    std::fill(grad.begin(), grad.end(), 0.0);
    for (const Row& r : rows) {
        double G = 0.0, dG = 0.0, z = 0.0;
        if (std::isfinite(r.u)) {
            z = beta * (r.u - a);
            const KernelValue kv = kernel(kernel_kind, z);
            G = kv.value;
            dG = kv.derivative;
        } else {
            G = r.u > 0 ? 1.0 : 0.0;
        }
        double p = g + scale * G;
        bool clamped = false;
        if (p < kPsiFloor) {
            p = kPsiFloor;
            clamped = true;
        } else if (p > 1.0 - kPsiFloor) {
            p = 1.0 - kPsiFloor;
            clamped = true;
        }
        const double no = r.n - r.k;
        nll -= (r.k > 0.0 ? r.k * std::log(p) : 0.0) + (no > 0.0 ? no * std::log1p(-p) : 0.0);
        if (grad.empty() || clamped) continue;
        // d(-LL)/dPsi, then the chain rule through Psi = g + scale G(beta (u - a)).
        const double w = -(r.k / p - no / (1.0 - p));
        if (dG != 0.0) {
            grad[0] += w * scale * dG * (-beta);
            grad[1] += w * scale * dG * z;  // d z / d ln beta = z
        }
        if (gamma_index >= 0) grad[static_cast<std::size_t>(gamma_index)] += w * (1.0 - G);
        if (lambda_index >= 0) grad[static_cast<std::size_t>(lambda_index)] += w * (-G);
    }
    nll = (nll - objective_offset) * objective_scale;
    if (!std::isfinite(nll)) nll = std::numeric_limits<double>::max();
    for (double& v : grad) {
        v *= objective_scale;
        if (!std::isfinite(v)) v = 0.0;
    }
    if (nll < best_value) {
        best_value = nll;
        best_x.assign(x.begin(), x.end());
    }
    return nll;
}

}  // namespace detail

double log_likelihood(Family f, std::span<const LevelCounts> data, const PsiParams& p) noexcept {
    double ll = 0.0;
    for (const LevelCounts& r : data) {
        if (r.n_trials <= 0) continue;
        const double q = std::clamp(psi(f, r.level, p), kPsiFloor, 1.0 - kPsiFloor);
        const double k = r.n_yes;
        const double no = r.n_trials - r.n_yes;
        ll += (k > 0 ? k * std::log(q) : 0.0) + (no > 0 ? no * std::log1p(-q) : 0.0);
    }
    return ll;
}

namespace {

double saturated_log_likelihood(std::span<const LevelCounts> data) noexcept {
    double ll = 0.0;
    for (const LevelCounts& r : data) {
        if (r.n_trials <= 0) continue;
        const double n = r.n_trials;
        const double k = r.n_yes;
        if (k > 0) ll += k * std::log(k / n);
        if (n - k > 0) ll += (n - k) * std::log((n - k) / n);
    }
    return ll;
}

}  // namespace

double deviance(Family f, std::span<const LevelCounts> data, const PsiParams& p) noexcept {
    return std::max(0.0, 2.0 * (saturated_log_likelihood(data) - log_likelihood(f, data, p)));
}

std::vector<LevelCounts> pool_levels(std::span<const LevelCounts> data) {
    std::vector<LevelCounts> rows;
    for (const LevelCounts& r : data)
        if (r.n_trials > 0) rows.push_back(r);
    std::stable_sort(rows.begin(), rows.end(), [](const auto& a, const auto& b) { return a.level < b.level; });
    std::vector<LevelCounts> out;
    for (const LevelCounts& r : rows) {
        if (!out.empty() && out.back().level == r.level) {
            out.back().n_trials += r.n_trials;
            out.back().n_yes += r.n_yes;
        } else {
            out.push_back(r);
        }
    }
    return out;
}

std::vector<LevelCounts> tabulate(std::span<const double> levels, std::span<const bool> yes) {
    std::vector<LevelCounts> rows;
    const std::size_t n = std::min(levels.size(), yes.size());
    rows.reserve(n);
    for (std::size_t i = 0; i < n; ++i)
        if (std::isfinite(levels[i])) rows.push_back({levels[i], 1, yes[i] ? 1 : 0});
    return pool_levels(rows);
}

namespace {

/// The search region on the internal axis: a = alpha (log10 alpha for the
/// Weibull), b = ln beta.
struct SearchBounds {
    double a_lo, a_hi, b_lo, b_hi;
};

/// A point of the starting grid and the objective there.
struct Candidate {
    double value;
    double a, b;
    int i, j;  // grid indices
};

/// Where the local searches start: the best point of a grid over a (7 points
/// over the tested range plus a quarter on each side) and b (5 widths from
/// range/20 to 2 range, log-spaced), within the bounds, and the best one that
/// is not its neighbour on the grid (a second basin, e.g. a steep fit with a
/// large lapse against a shallow one without).
std::vector<Candidate> grid_starts(detail::FitProblem& problem, const std::vector<double>& start, const SearchBounds& s,
                                   double u_min, double u_max, double z_width) {
    const double range = u_max - u_min;
    std::vector<Candidate> grid;
    {
        double ga_lo = std::max(s.a_lo, u_min - 0.25 * range);
        double ga_hi = std::min(s.a_hi, u_max + 0.25 * range);
        if (!(ga_lo < ga_hi)) {
            ga_lo = s.a_lo;
            ga_hi = s.a_hi;
        }
        double gb_lo = std::clamp(std::log(z_width / (2.0 * range)), s.b_lo, s.b_hi);
        double gb_hi = std::clamp(std::log(z_width / (range / 20.0)), s.b_lo, s.b_hi);
        if (!(gb_lo < gb_hi)) {
            gb_lo = s.b_lo;
            gb_hi = s.b_hi;
        }
        constexpr int na = 7;
        constexpr int nb = 5;
        std::vector<double> x = start;
        grid.reserve(na * nb);
        for (int i = 0; i < na; ++i) {
            x[0] = ga_lo + (ga_hi - ga_lo) * i / (na - 1);
            for (int j = 0; j < nb; ++j) {
                x[1] = gb_lo + (gb_hi - gb_lo) * j / (nb - 1);
                grid.push_back({problem.evaluate(x, {}), x[0], x[1], i, j});
            }
        }
    }
    std::sort(grid.begin(), grid.end(), [](const Candidate& p, const Candidate& q) { return p.value < q.value; });
    std::vector<Candidate> starts{grid.front()};
    for (const Candidate& c : grid) {
        if (std::abs(c.i - grid.front().i) > 1 || std::abs(c.j - grid.front().j) > 1) {
            starts.push_back(c);
            break;
        }
    }
    return starts;
}

/// SLSQP within [lower, upper] from each start (a, b; the rates as in
/// `start`); the problem keeps the best point it evaluated. True when a
/// search reported convergence.
bool minimise(detail::FitProblem& problem, const std::vector<double>& lower, const std::vector<double>& upper,
              const std::vector<double>& start, const std::vector<Candidate>& starts) {
    nlopt_opt opt = nlopt_create(NLOPT_LD_SLSQP, static_cast<unsigned>(lower.size()));
    nlopt_set_lower_bounds(opt, lower.data());
    nlopt_set_upper_bounds(opt, upper.data());
    nlopt_set_min_objective(opt, nlopt_objective, &problem);
    // The objective is deviance / (2 N): 1e-13 per trial is far below any
    // difference that matters, and far above rounding.
    nlopt_set_ftol_abs(opt, 1e-13);
    nlopt_set_xtol_rel(opt, 1e-8);
    nlopt_set_maxeval(opt, 500);
    bool converged = false;
    for (const Candidate& c : starts) {
        std::vector<double> x = start;
        x[0] = c.a;
        x[1] = c.b;
        double value = 0.0;
        const nlopt_result rc = nlopt_optimize(opt, x.data(), &value);
        if (rc > 0) converged = true;
    }
    nlopt_destroy(opt);
    return converged;
}

/// Sets fit.at_bound, fit.reliable and fit.reason from the minimum `x` (on
/// the internal axis) and the fitted beta.
void judge_reliability(PsychometricFit& fit, const std::vector<double>& x, const SearchBounds& s, double range,
                       double min_spacing, double z_width, double beta) {
    const double a_tol = 1e-6 * std::max(1.0, range);
    const bool a_bound = x[0] <= s.a_lo + a_tol || x[0] >= s.a_hi - a_tol;
    const bool b_bound = x[1] <= s.b_lo + 1e-6 || x[1] >= s.b_hi - 1e-6;
    fit.at_bound = a_bound || b_bound;
    std::vector<std::string> reasons;
    if (a_bound)
        reasons.push_back(
            fmt::format("alpha ended on its search bound ({}): the threshold is outside the levels tested",
                        x[0] <= s.a_lo + a_tol ? "lower" : "upper"));
    if (b_bound)
        reasons.push_back(x[1] >= s.b_hi - 1e-6
                              ? "beta ended on its upper bound: the data do not constrain the slope (responses "
                                "perfectly separated between two levels?)"
                              : "beta ended on its lower bound: the responses hardly change with the level");
    const double internal_width = z_width / beta;
    if (!b_bound && internal_width < min_spacing)
        reasons.push_back(
            fmt::format("the fitted rise (width {:.3g}{}) is narrower than the closest spacing of the levels ({:.3g}): "
                        "the slope is "
                        "not constrained by the data (responses separating perfectly between neighbouring levels?)",
                        internal_width, fit.options.family == Family::Weibull ? " log10 units" : "", min_spacing));
    if (fit.n_levels < fit.n_free)
        reasons.push_back(
            fmt::format("{} distinct levels for {} free parameters: underdetermined", fit.n_levels, fit.n_free));
    if (!fit.converged) reasons.push_back("the minimiser did not report convergence");
    fit.reliable = reasons.empty();
    for (std::size_t i = 0; i < reasons.size(); ++i) fit.reason += (i ? "; " : "") + reasons[i];
}

}  // namespace

PsychometricFit fit_psychometric(std::span<const LevelCounts> data, const FitOptions& options) {
    validate(options);
    PsychometricFit fit;
    fit.options = options;
    const Family f = options.family;
    fit.n_free = 2 + (options.guess.is_free() ? 1 : 0) + (options.lapse.is_free() ? 1 : 0);

    auto fail = [&](std::string reason) {
        fit.estimate.reset();
        fit.reliable = false;
        fit.reason = std::move(reason);
        return fit;
    };

    // The data: valid rows, counts, distinct levels on the internal axis.
    detail::FitProblem problem;
    problem.kernel_kind = detail::kernel_of(f);
    long long total_yes = 0;
    long long total = 0;
    std::vector<double> finite_u;
    std::vector<double> distinct_levels;
    for (std::size_t i = 0; i < data.size(); ++i) {
        const LevelCounts& r = data[i];
        if (r.n_trials < 0 || r.n_yes < 0 || r.n_yes > r.n_trials)
            return fail(fmt::format("row {} (level {}): counts must satisfy 0 <= n_yes <= n_trials, got {} of {}", i,
                                    r.level, r.n_yes, r.n_trials));
        if (r.n_trials == 0) continue;
        if (!std::isfinite(r.level)) return fail(fmt::format("row {}: the level is not a finite number", i));
        ++fit.n_rows;
        total += r.n_trials;
        total_yes += r.n_yes;
        const double u = internal_axis(f, r.level);
        problem.rows.push_back({u, static_cast<double>(r.n_trials), static_cast<double>(r.n_yes)});
        if (std::isfinite(u)) finite_u.push_back(u);
        distinct_levels.push_back(r.level);
    }
    std::sort(distinct_levels.begin(), distinct_levels.end());
    distinct_levels.erase(std::unique(distinct_levels.begin(), distinct_levels.end()), distinct_levels.end());
    fit.n_levels = static_cast<int>(distinct_levels.size());
    fit.n_trials = static_cast<int>(total);

    if (total == 0) return fail("no trials");
    if (total == 1) return fail("a single trial: nothing can be estimated");
    std::sort(finite_u.begin(), finite_u.end());
    finite_u.erase(std::unique(finite_u.begin(), finite_u.end()), finite_u.end());
    if (finite_u.size() < 2) {
        if (f == Family::Weibull)
            return fail("fewer than two distinct levels above 0: the Weibull's threshold and slope are not identified");
        return fail(fmt::format("all trials at a single level ({}): threshold and slope are not identified",
                                distinct_levels.front()));
    }
    if (total_yes == total)
        return fail("every response was yes/correct: the threshold lies below the lowest level tested");
    if (total_yes == 0)
        return fail("every response was no/incorrect: the threshold lies above the highest level tested");

    problem.objective_offset = -saturated_log_likelihood(data);
    problem.objective_scale = 1.0 / static_cast<double>(total);

    // Bounds on the internal axis: a = alpha (log10 alpha for the Weibull), b = ln beta.
    const double u_min = finite_u.front();
    const double u_max = finite_u.back();
    const double range = u_max - u_min;
    double min_spacing = range;
    for (std::size_t i = 1; i < finite_u.size(); ++i)
        min_spacing = std::min(min_spacing, finite_u[i] - finite_u[i - 1]);
    const double a_lo = options.alpha_min ? internal_axis(f, *options.alpha_min) : u_min - range;
    const double a_hi = options.alpha_max ? internal_axis(f, *options.alpha_max) : u_max + range;
    const auto z_lo = detail::kernel_quantile(problem.kernel_kind, options.width_alpha);
    const auto z_hi = detail::kernel_quantile(problem.kernel_kind, 1.0 - options.width_alpha);
    const double z_width = *z_hi - *z_lo;  // the width of F in z units; beta = z_width / width
    const double b_lo = std::log(options.beta_min ? *options.beta_min : z_width / (100.0 * range));
    const double b_hi = std::log(options.beta_max ? *options.beta_max : z_width / (range / 1000.0));

    // Parameter layout: a, b, [gamma], [lambda].
    std::vector<double> lower{a_lo, b_lo};
    std::vector<double> upper{a_hi, b_hi};
    if (options.guess.is_free()) {
        problem.gamma_index = static_cast<int>(lower.size());
        lower.push_back(options.guess.lower);
        upper.push_back(options.guess.upper);
    } else {
        problem.gamma_fixed = *options.guess.fixed;
    }
    if (options.lapse.is_free()) {
        problem.lambda_index = static_cast<int>(lower.size());
        lower.push_back(options.lapse.lower);
        upper.push_back(options.lapse.upper);
    } else {
        problem.lambda_fixed = *options.lapse.fixed;
    }
    const std::size_t dim = lower.size();

    // Starting rates: the observed proportion at the extreme levels, clamped.
    std::vector<double> start(dim);
    {
        const auto lowest = std::min_element(problem.rows.begin(), problem.rows.end(),
                                             [](const auto& p, const auto& q) { return p.u < q.u; });
        const auto highest = std::max_element(problem.rows.begin(), problem.rows.end(),
                                              [](const auto& p, const auto& q) { return p.u < q.u; });
        if (problem.gamma_index >= 0)
            start[static_cast<std::size_t>(problem.gamma_index)] =
                std::clamp(lowest->k / lowest->n, options.guess.lower, options.guess.upper);
        if (problem.lambda_index >= 0)
            start[static_cast<std::size_t>(problem.lambda_index)] = std::clamp(
                1.0 - highest->k / highest->n, options.lapse.lower, 0.5 * (options.lapse.lower + options.lapse.upper));
    }

    const SearchBounds bounds{a_lo, a_hi, b_lo, b_hi};
    const std::vector<Candidate> starts = grid_starts(problem, start, bounds, u_min, u_max, z_width);
    fit.converged = minimise(problem, lower, upper, start, starts);
    fit.n_evaluations = problem.evaluations;

    if (problem.best_x.size() != dim) return fail("the likelihood could not be evaluated");
    const std::vector<double>& x = problem.best_x;
    PsiParams p;
    p.alpha = f == Family::Weibull ? std::pow(10.0, x[0]) : x[0];
    p.beta = std::exp(x[1]);
    p.gamma = problem.gamma_index >= 0 ? x[static_cast<std::size_t>(problem.gamma_index)] : problem.gamma_fixed;
    p.lambda = problem.lambda_index >= 0 ? x[static_cast<std::size_t>(problem.lambda_index)] : problem.lambda_fixed;

    PsychometricEstimate e;
    e.params = p;
    const auto threshold = sigmoid_inverse(f, options.threshold_proportion, p.alpha, p.beta);
    const auto width = sigmoid_width(f, p.alpha, p.beta, options.width_alpha);
    if (!threshold || !width) return fail("the fitted function has no finite threshold or width");
    e.threshold = *threshold;
    e.width = *width;
    e.psi_at_threshold = psi(f, e.threshold, p);
    e.slope = psi_derivative(f, e.threshold, p);
    e.log_likelihood = log_likelihood(f, data, p);
    e.deviance = deviance(f, data, p);
    for (double v : {p.alpha, p.beta, p.gamma, p.lambda, e.threshold, e.width, e.psi_at_threshold, e.slope,
                     e.log_likelihood, e.deviance})
        if (!std::isfinite(v)) return fail("the fit produced a non-finite value");
    fit.estimate = e;

    judge_reliability(fit, x, bounds, range, min_spacing, z_width, p.beta);
    return fit;
}

}  // namespace atonlab::analysis
