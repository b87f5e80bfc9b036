// Parametric bootstrap and deviance goodness of fit (psychometric.h;
// Wichmann & Hill 2001a, 2001b; Palamedes PAL_PFML_BootstrapParametric and
// PAL_PFML_GoodnessOfFit).
#include <fmt/format.h>

#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>

#include "atonlab/analysis/psychometric.h"
#include "stats_policy.h"

namespace atonlab::analysis {

namespace {

/// A binomial(n, p) draw as the sum of n Bernoulli draws on uniform(): exact,
/// and identical on every platform (std::binomial_distribution is not).
int binomial_draw(protocols::Rng& rng, int n, double p) noexcept {
    int k = 0;
    for (int i = 0; i < n; ++i)
        if (rng.uniform() < p) ++k;
    return k;
}

struct Refit {
    bool ok = false;
    bool at_bound = false;
    PsychometricEstimate estimate;
};

}  // namespace

PsychometricBootstrap bootstrap_psychometric(std::span<const LevelCounts> data, const PsychometricFit& fit,
                                             const ResampleOptions& options) {
    PsychometricBootstrap out;
    out.n_requested = options.n_resamples;
    if (!fit.estimate) {
        out.reason = "no bootstrap: the fit has no estimate (" + fit.reason + ")";
        return out;
    }
    const PsychometricEstimate& est = *fit.estimate;
    out.goodness_of_fit.deviance = est.deviance;
    out.goodness_of_fit.dof = fit.n_rows - fit.n_free;
    if (out.goodness_of_fit.dof > 0) {
        const boost::math::chi_squared_distribution<double, detail::StatsPolicy> chi2(out.goodness_of_fit.dof);
        const double p = boost::math::cdf(boost::math::complement(chi2, est.deviance));
        if (std::isfinite(p)) out.goodness_of_fit.p_value_chi2 = p;
    }
    if (options.n_resamples <= 0) {
        out.reason = "no resamples requested";
        return out;
    }
    if (!(options.level > 0.0 && options.level < 1.0)) {
        out.reason = fmt::format("interval level {} is outside (0, 1)", options.level);
        return out;
    }

    // The rows the fit used, and the generating probabilities under the fit.
    std::vector<LevelCounts> rows;
    std::vector<double> p_gen;
    for (const LevelCounts& r : data) {
        if (r.n_trials <= 0) continue;
        rows.push_back(r);
        p_gen.push_back(psi(fit.options.family, r.level, est.params));
    }

    std::vector<Refit> refits(static_cast<std::size_t>(options.n_resamples));
    const FitOptions fit_options = fit.options;
    auto body = [&](int i) {
        protocols::Rng rng = resample_rng(options.seed, static_cast<std::uint64_t>(i));
        std::vector<LevelCounts> sim = rows;
        for (std::size_t j = 0; j < sim.size(); ++j) sim[j].n_yes = binomial_draw(rng, sim[j].n_trials, p_gen[j]);
        const PsychometricFit f = fit_psychometric(sim, fit_options);
        Refit& r = refits[static_cast<std::size_t>(i)];
        if (f.estimate) {
            r.ok = true;
            r.at_bound = f.at_bound;
            r.estimate = *f.estimate;
        }
    };
    out.n_done = run_resamples(options.n_resamples, std::max(1, options.n_threads), options.progress, body);
    out.cancelled = out.n_done < options.n_resamples;

    std::vector<double> alphas, betas;
    int n_ge = 0;
    for (int i = 0; i < out.n_done; ++i) {
        const Refit& r = refits[static_cast<std::size_t>(i)];
        if (!r.ok) {
            ++out.n_failed;
            continue;
        }
        if (r.at_bound) ++out.n_at_bound;
        out.threshold_samples.push_back(r.estimate.threshold);
        out.slope_samples.push_back(r.estimate.slope);
        out.width_samples.push_back(r.estimate.width);
        out.lambda_samples.push_back(r.estimate.params.lambda);
        out.gamma_samples.push_back(r.estimate.params.gamma);
        alphas.push_back(r.estimate.params.alpha);
        betas.push_back(r.estimate.params.beta);
        out.deviance_samples.push_back(r.estimate.deviance);
        if (r.estimate.deviance >= est.deviance) ++n_ge;
    }
    const double level = options.level;
    out.threshold = percentile_interval(out.threshold_samples, level);
    out.slope = percentile_interval(out.slope_samples, level);
    out.width = percentile_interval(out.width_samples, level);
    out.lambda = percentile_interval(out.lambda_samples, level);
    out.gamma = percentile_interval(out.gamma_samples, level);
    out.alpha = percentile_interval(alphas, level);
    out.beta = percentile_interval(betas, level);
    const auto n_ok = static_cast<double>(out.deviance_samples.size());
    if (n_ok > 0) out.goodness_of_fit.p_value = (1.0 + n_ge) / (1.0 + n_ok);

    std::vector<std::string> reasons;
    if (!fit.reliable) reasons.push_back("the fit itself is unreliable (" + fit.reason + ")");
    if (out.cancelled)
        reasons.push_back(fmt::format("cancelled after {} of {} resamples", out.n_done, out.n_requested));
    if (out.n_failed > 0.01 * out.n_done)
        reasons.push_back(
            fmt::format("{} of {} simulated datasets could not be fitted (all yes or all no) and were "
                        "left out of the intervals",
                        out.n_failed, out.n_done));
    if (!out.threshold) reasons.push_back("too few successful refits for an interval");
    out.reliable = reasons.empty();
    for (std::size_t i = 0; i < reasons.size(); ++i) out.reason += (i ? "; " : "") + reasons[i];
    return out;
}

}  // namespace atonlab::analysis
