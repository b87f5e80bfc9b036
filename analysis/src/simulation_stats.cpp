// The simulation report's statistics (simulation.h): per design and condition
// the truth, the estimates' mean, median, bias, SD and RMSE, interval
// coverage with its Clopper-Pearson interval, trials per session; and the
// power to detect a stated effect by the location-shift method.
#include <fmt/format.h>

#include <algorithm>
#include <boost/math/distributions/binomial.hpp>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include "atonlab/analysis/simulation.h"
#include "atonlab/common/input_error.h"

namespace atonlab::analysis {

namespace {

std::optional<double> median_of(std::vector<double> v) {
    if (v.empty()) return std::nullopt;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// z_{(1+level)/2}: the two-sided normal quantile of `level`.
double z_two_sided(double level) {
    return boost::math::quantile(boost::math::normal(), 0.5 * (1.0 + level));
}

/// The standard error an interval implies for a normal estimate: its width / (2 z).
std::optional<double> se_of(const SessionEstimate& e, double level) {
    if (!e.ci || !(e.ci->upper > e.ci->lower)) return std::nullopt;
    return (e.ci->upper - e.ci->lower) / (2.0 * z_two_sided(level));
}

const SessionEstimate* find(const SessionSummary& s, const std::string& condition) {
    for (const SessionEstimate& e : s.conditions)
        if (e.condition == condition) return &e;
    return nullptr;
}

std::string design_label(const SimulationManifest& m, int index) {
    return index >= 0 && static_cast<std::size_t>(index) < m.designs.size()
               ? m.designs[static_cast<std::size_t>(index)].label
               : std::string();
}

/// The summary of one design's condition from its sessions' estimates.
/// How much session e's interval must widen, each side by the same factor of
/// its own half-width, to hold its truth (<= 1: it holds it already); none
/// without an interval or a truth, +inf for a side of zero width.
std::optional<double> needed_widening(const SessionEstimate& e) {
    if (!e.ci || !e.estimate || !e.truth) return std::nullopt;
    const double est = *e.estimate, truth = *e.truth;
    const double side = truth >= est ? e.ci->upper - est : est - e.ci->lower;
    if (std::abs(truth - est) == 0.0) return 0.0;
    return side > 0.0 ? std::abs(truth - est) / side : std::numeric_limits<double>::infinity();
}

/// The calibrated intervals of summarize(): the factor from every session,
/// and the coverage held out between the two halves.
void calibrate(ConditionSummary& c, const std::vector<const SessionEstimate*>& es, double level) {
    std::vector<double> all, half[2];
    for (std::size_t i = 0; i < es.size(); ++i)
        if (const std::optional<double> r = needed_widening(*es[i])) {
            all.push_back(*r);
            half[i % 2].push_back(*r);
        }
    if (all.size() < 20 || half[0].empty() || half[1].empty()) return;  // too few to find a quantile
    for (std::vector<double>* v : {&all, &half[0], &half[1]}) std::sort(v->begin(), v->end());
    c.widen_factor = nearest_rank(all, level);
    for (int h = 0; h < 2; ++h) {
        const double k = *nearest_rank(half[1 - h], level);  // found on the other half
        for (double r : half[h]) c.n_calibrated_covered += r <= k ? 1 : 0;
        c.n_calibrated += static_cast<int>(half[h].size());
    }
    c.calibrated_coverage = static_cast<double>(c.n_calibrated_covered) / c.n_calibrated;
    c.calibrated_coverage_ci = clopper_pearson(c.n_calibrated_covered, c.n_calibrated, level);
}

ConditionSummary summarize(const std::vector<const SessionEstimate*>& es, double level) {
    ConditionSummary c;
    c.n_sessions = static_cast<int>(es.size());
    std::vector<double> truths, estimates, errors, widths, trials;
    for (const SessionEstimate* e : es) {
        trials.push_back(e->n_trials);
        if (e->truth) truths.push_back(*e->truth);
        if (!e->estimate || !e->truth) continue;
        ++c.n_estimates;
        if (!e->reliable) ++c.n_unreliable;
        estimates.push_back(*e->estimate);
        errors.push_back(*e->estimate - *e->truth);
        if (!e->ci) continue;
        ++c.n_intervals;
        if (e->ci->contains(*e->truth)) ++c.n_covered;
        if (e->ci_open) ++c.n_open;
        widths.push_back(e->ci->upper - e->ci->lower);
    }
    if (!truths.empty()) {
        const auto [lo, hi] = std::minmax_element(truths.begin(), truths.end());
        c.truth = std::accumulate(truths.begin(), truths.end(), 0.0) / static_cast<double>(truths.size());
        c.truth_min = *lo;
        c.truth_max = *hi;
        c.truth_differs = *hi - *lo > 1e-9;
    }
    if (!estimates.empty()) {
        const double n = static_cast<double>(estimates.size());
        c.mean = std::accumulate(estimates.begin(), estimates.end(), 0.0) / n;
        c.median = median_of(estimates);
        c.bias = std::accumulate(errors.begin(), errors.end(), 0.0) / n;
        double ss = 0.0, sq = 0.0;
        for (std::size_t i = 0; i < estimates.size(); ++i) {
            ss += (estimates[i] - *c.mean) * (estimates[i] - *c.mean);
            sq += errors[i] * errors[i];
        }
        if (estimates.size() > 1) c.sd = std::sqrt(ss / (n - 1.0));
        c.rmse = std::sqrt(sq / n);
    }
    if (c.n_intervals > 0) {
        c.coverage = static_cast<double>(c.n_covered) / c.n_intervals;
        c.coverage_ci = clopper_pearson(c.n_covered, c.n_intervals, level);
        c.width_median = median_of(widths);
    }
    calibrate(c, es, level);
    std::sort(trials.begin(), trials.end());
    c.trials_median = median_of(trials);
    c.trials_p90 = nearest_rank(trials, 0.9);
    return c;
}

}  // namespace

std::optional<Interval> clopper_pearson(int k, int n, double level) {
    if (n <= 0 || k < 0 || k > n) return std::nullopt;
    using boost::math::binomial_distribution;
    const double a = (1.0 - level) / 2.0;
    return Interval{binomial_distribution<>::find_lower_bound_on_p(n, k, a),
                    binomial_distribution<>::find_upper_bound_on_p(n, k, a), level};
}

std::optional<double> nearest_rank(const std::vector<double>& sorted, double p) {
    if (sorted.empty()) return std::nullopt;
    const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(sorted.size())));
    return sorted[std::clamp<std::size_t>(rank, 1, sorted.size()) - 1];
}

std::vector<ConditionSummary> summarize_conditions(const std::vector<SessionSummary>& sessions,
                                                   const SimulationManifest& manifest, double level) {
    // Per design, the conditions in the order first met.
    std::map<int, std::vector<std::string>> order;
    std::map<std::pair<int, std::string>, std::vector<const SessionEstimate*>> by;
    std::map<std::pair<int, std::string>, std::string> units;
    for (const SessionSummary& s : sessions) {
        for (const SessionEstimate& e : s.conditions) {
            auto& list = by[{s.design_index, e.condition}];
            if (list.empty()) order[s.design_index].push_back(e.condition);
            list.push_back(&e);
            units.try_emplace({s.design_index, e.condition}, s.level_unit);
        }
    }
    std::vector<ConditionSummary> out;
    for (const auto& [design, names] : order) {
        for (const std::string& name : names) {
            const auto& es = by[{design, name}];
            ConditionSummary c = summarize(es, level);
            c.design_index = design;
            c.design = design_label(manifest, design);
            c.condition = name;
            c.unit = units[{design, name}];
            c.truth_what = es.front()->truth_what;
            c.truth_p = es.front()->truth_p;
            out.push_back(std::move(c));
        }
    }
    return out;
}

PowerSummary power_of(const std::vector<DifferenceSample>& samples, double effect, double level) {
    PowerSummary p;
    p.effect = effect;
    const double z = z_two_sided(level);
    double sum = 0.0, sum_truth = 0.0;
    for (const DifferenceSample& s : samples) {
        if (!(s.se > 0.0) || !std::isfinite(s.estimate) || !std::isfinite(s.truth)) continue;
        ++p.n_sessions;
        sum += s.estimate;
        sum_truth += s.truth;
        // The location shift: the session's error, as if the true difference were `effect`.
        if (std::abs(effect + s.estimate - s.truth) / s.se > z) ++p.n_detected;
    }
    if (p.n_sessions == 0) return p;
    const double n = p.n_sessions;
    p.true_difference = sum_truth / n;
    double ss = 0.0;
    for (const DifferenceSample& s : samples)
        if (s.se > 0.0 && std::isfinite(s.estimate) && std::isfinite(s.truth))
            ss += (s.estimate - sum / n) * (s.estimate - sum / n);
    if (p.n_sessions > 1) p.sd_difference = std::sqrt(ss / (n - 1.0));
    p.power = p.n_detected / n;
    p.power_ci = clopper_pearson(p.n_detected, p.n_sessions, level);
    return p;
}

std::vector<PowerSummary> power_analyses(const std::vector<SessionSummary>& sessions,
                                         const SimulationManifest& manifest, const SimulationOptions& options,
                                         std::vector<std::string>& warnings) {
    std::vector<PowerSummary> out;
    if (!options.effect_log10) return out;
    const double level = options.ci_level;
    std::map<int, std::vector<const SessionSummary*>> by_design;
    for (const SessionSummary& s : sessions) by_design[s.design_index].push_back(&s);

    if (options.effect_between) {
        const auto& [a, b] = *options.effect_between;
        bool seen_a = false, seen_b = false;
        for (const auto& [design, list] : by_design) {
            std::vector<DifferenceSample> samples;
            for (const SessionSummary* s : list) {
                const SessionEstimate* ea = find(*s, a);
                const SessionEstimate* eb = find(*s, b);
                seen_a = seen_a || ea;
                seen_b = seen_b || eb;
                if (!ea || !eb || !ea->estimate || !eb->estimate || !ea->truth || !eb->truth) continue;
                const auto sa = se_of(*ea, level), sb = se_of(*eb, level);
                if (!sa || !sb) continue;
                samples.push_back({*ea->estimate - *eb->estimate, *ea->truth - *eb->truth, std::hypot(*sa, *sb)});
            }
            PowerSummary p = power_of(samples, *options.effect_log10, level);
            p.design_index = design;
            p.design = design_label(manifest, design);
            p.condition_a = a;
            p.condition_b = b;
            p.what = fmt::format("{} − {}", a, b);
            out.push_back(std::move(p));
        }
        if (!sessions.empty() && (!seen_a || !seen_b))
            throw InputError(SourceLocation::command_line("--effect-between"),
                             fmt::format("no session has a condition \"{}\"", !seen_a ? a : b));
        return out;
    }
    // Each glare condition's enhancement log10(PSE / test intensity), as the analysis computes it.
    for (const auto& [design, list] : by_design) {
        std::vector<std::string> names;
        std::map<std::string, std::vector<DifferenceSample>> samples;
        std::map<std::string, std::string> labels;
        for (const SessionSummary* s : list) {
            for (const SessionEstimate& e : s->conditions) {
                if (!e.test_log10) continue;
                if (!samples.count(e.condition)) names.push_back(e.condition);
                auto& list_of = samples[e.condition];
                labels[e.condition] = e.difference_label;
                const auto se = se_of(e, level);
                if (!e.estimate || !e.truth || !se) continue;
                list_of.push_back({*e.estimate - *e.test_log10, *e.truth - *e.test_log10, *se});
            }
        }
        for (const std::string& name : names) {
            PowerSummary p = power_of(samples[name], *options.effect_log10, level);
            p.design_index = design;
            p.design = design_label(manifest, design);
            p.condition_a = name;
            p.what = labels[name];
            out.push_back(std::move(p));
        }
    }
    if (out.empty())
        warnings.push_back(
            "--effect was given but no condition compares glare on log10 levels of the reference (the analysis's "
            "enhancement), so no power was computed; name two conditions with --effect-between A,B");
    return out;
}

}  // namespace atonlab::analysis
