// Staircase reversal means and QUEST posterior summaries (thresholds.h).
#include "atonlab/analysis/thresholds.h"

#include <fmt/format.h>

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <cmath>

#include "stats_policy.h"

namespace atonlab::analysis {

ReversalSummary summarize_reversals(std::span<const double> levels, std::span<const bool> reversal, int last_k) {
    ReversalSummary s;
    const std::size_t n = std::min(levels.size(), reversal.size());
    s.n_trials = static_cast<int>(n);
    std::vector<double> at_reversals;
    for (std::size_t i = 0; i < n; ++i)
        if (reversal[i]) at_reversals.push_back(levels[i]);
    s.n_reversals = static_cast<int>(at_reversals.size());
    const std::size_t k =
        last_k <= 0 ? at_reversals.size() : std::min(at_reversals.size(), static_cast<std::size_t>(last_k));
    std::vector<double> used;
    int n_bad = 0;
    for (std::size_t i = at_reversals.size() - k; i < at_reversals.size(); ++i) {
        if (std::isfinite(at_reversals[i]))
            used.push_back(at_reversals[i]);
        else
            ++n_bad;
    }
    s.n_used = static_cast<int>(used.size());

    std::vector<std::string> reasons;
    if (n != levels.size() || n != reversal.size())
        reasons.push_back(fmt::format("{} levels but {} reversal flags", levels.size(), reversal.size()));
    if (s.n_reversals == 0) reasons.push_back("no reversals");
    if (last_k > 0 && s.n_reversals < last_k)
        reasons.push_back(fmt::format("only {} reversals of the {} asked for", s.n_reversals, last_k));
    if (n_bad > 0) reasons.push_back(fmt::format("{} reversal levels were not finite numbers", n_bad));
    if (!used.empty()) {
        double sum = 0.0;
        for (double v : used) sum += v;
        const double mean = sum / static_cast<double>(used.size());
        s.mean = mean;
        if (used.size() >= 2) {
            double ss = 0.0;
            for (double v : used) ss += (v - mean) * (v - mean);
            const double sd = std::sqrt(ss / static_cast<double>(used.size() - 1));
            s.sd = sd;
            s.sem = sd / std::sqrt(static_cast<double>(used.size()));
        } else {
            reasons.push_back("a single reversal: no spread");
        }
    }
    s.reliable = reasons.empty();
    for (std::size_t i = 0; i < reasons.size(); ++i) s.reason += (i ? "; " : "") + reasons[i];
    return s;
}

namespace {

/// QuestQuantile's interpolation (Psychtoolbox Quest/QuestQuantile.m): the
/// cumulative posterior at the grid points, strictly increasing points only,
/// linearly interpolated at order * total; below the first point, the first
/// grid value (as protocols::Quest::quantile).
double posterior_quantile(const std::vector<double>& grid, const std::vector<double>& pdf, double order) {
    std::vector<double> c, xs;
    double cum = 0.0, prev = -1.0;
    for (std::size_t i = 0; i < grid.size(); ++i) {
        cum += pdf[i];
        if (cum > prev) {
            c.push_back(cum);
            xs.push_back(grid[i]);
        }
        prev = cum;
    }
    const double target = order * cum;
    if (target <= c.front() || c.size() < 2) return xs.front();
    const auto it = std::lower_bound(c.begin(), c.end(), target);
    if (it == c.end()) return xs.back();
    const auto j = static_cast<std::size_t>(it - c.begin());
    const double t = (target - c[j - 1]) / (c[j] - c[j - 1]);
    return xs[j - 1] + t * (xs[j] - xs[j - 1]);
}

}  // namespace

PosteriorSummary summarize_posterior(const StoredPosterior& q, double level) {
    PosteriorSummary s;
    std::vector<std::string> reasons;
    const bool level_ok = level > 0.0 && level < 1.0;
    if (!level_ok) reasons.push_back(fmt::format("interval level {} is outside (0, 1)", level));

    bool grid_ok = !q.grid.empty() && q.grid.size() == q.posterior.size();
    if (!q.grid.empty() || !q.posterior.empty()) {
        double total = 0.0;
        for (std::size_t i = 0; grid_ok && i < q.grid.size(); ++i) {
            if (!std::isfinite(q.grid[i]) || !std::isfinite(q.posterior[i]) || q.posterior[i] < 0.0) grid_ok = false;
            if (i > 0 && !(q.grid[i] > q.grid[i - 1])) grid_ok = false;
            if (grid_ok) total += q.posterior[i];
        }
        if (!(total > 0.0) || !std::isfinite(total)) grid_ok = false;
        if (!grid_ok)
            reasons.push_back(
                "the posterior grid was unusable (sizes differ, not ascending, negative or no mass); "
                "the stored values were used");
    }

    if (grid_ok) {
        s.from_posterior = true;
        double total = 0.0;
        for (double p : q.posterior) total += p;
        double mean = 0.0;
        for (std::size_t i = 0; i < q.grid.size(); ++i) mean += q.grid[i] * q.posterior[i] / total;
        double var = 0.0;
        for (std::size_t i = 0; i < q.grid.size(); ++i)
            var += (q.grid[i] - mean) * (q.grid[i] - mean) * q.posterior[i] / total;
        s.mean = mean;
        s.sd = std::sqrt(std::max(0.0, var));
        const auto mode_it = std::max_element(q.posterior.begin(), q.posterior.end());
        s.mode = q.grid[static_cast<std::size_t>(mode_it - q.posterior.begin())];
        if (level_ok)
            s.interval = Interval{posterior_quantile(q.grid, q.posterior, 0.5 * (1.0 - level)),
                                  posterior_quantile(q.grid, q.posterior, 0.5 * (1.0 + level)), level};
    } else {
        if (q.mean && std::isfinite(*q.mean)) s.mean = q.mean;
        if (q.sd && std::isfinite(*q.sd) && *q.sd >= 0.0) s.sd = q.sd;
        if (level_ok) {
            std::optional<double> lo, hi;
            for (const auto& [order, value] : q.quantiles) {
                if (!std::isfinite(value)) continue;
                if (std::abs(order - 0.5 * (1.0 - level)) < 1e-9) lo = value;
                if (std::abs(order - 0.5 * (1.0 + level)) < 1e-9) hi = value;
            }
            if (lo && hi && *lo <= *hi) {
                s.interval = Interval{*lo, *hi, level};
            } else if (s.mean && s.sd) {
                const boost::math::normal_distribution<double, detail::StatsPolicy> n;
                const double z = boost::math::quantile(n, 0.5 * (1.0 + level));
                s.interval = Interval{*s.mean - z * *s.sd, *s.mean + z * *s.sd, level};
                s.interval_is_normal_approximation = true;
            }
        }
        if (!s.mean) reasons.push_back("no posterior mean stored");
        if (!s.sd) reasons.push_back("no posterior SD stored");
    }
    s.reliable = reasons.empty() && s.mean && s.sd;
    for (std::size_t i = 0; i < reasons.size(); ++i) s.reason += (i ? "; " : "") + reasons[i];
    return s;
}

}  // namespace atonlab::analysis
