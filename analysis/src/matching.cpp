// Method of adjustment, brightness enhancement and paired comparisons (matching.h).
#include "atonlab/analysis/matching.h"

#include <fmt/format.h>

#include <algorithm>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <limits>

#include "stats_policy.h"

namespace atonlab::analysis {

namespace {

double mean_of(std::span<const double> v) noexcept {
    double s = 0.0;
    for (double x : v) s += x;
    return s / static_cast<double>(v.size());
}

double sd_of(std::span<const double> v, double mean) noexcept {
    double ss = 0.0;
    for (double x : v) ss += (x - mean) * (x - mean);
    return std::sqrt(ss / static_cast<double>(v.size() - 1));
}

/// Median of v (midpoint of the middle two for even sizes); v is reordered.
double median_of(std::vector<double>& v) noexcept {
    const std::size_t n = v.size();
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(n / 2);
    std::nth_element(v.begin(), mid, v.end());
    if (n % 2 == 1) return *mid;
    const double upper = *mid;
    const double lower = *std::max_element(v.begin(), mid);
    return 0.5 * (lower + upper);
}

std::string join(const std::vector<std::string>& reasons) {
    std::string out;
    for (std::size_t i = 0; i < reasons.size(); ++i) out += (i ? "; " : "") + reasons[i];
    return out;
}

/// Nonparametric bootstrap of the mean and median of `v` (values resampled
/// with replacement; resample i draws indices from resample_rng(seed, i)).
struct MeanMedianBoot {
    std::vector<double> means, medians;
    int done = 0;
};

MeanMedianBoot bootstrap_mean_median(const std::vector<double>& v, const ResampleOptions& o, bool want_median) {
    MeanMedianBoot b;
    if (o.n_resamples <= 0) return b;
    const auto B = static_cast<std::size_t>(o.n_resamples);
    b.means.assign(B, 0.0);
    if (want_median) b.medians.assign(B, 0.0);
    b.done = run_resamples(o.n_resamples, std::max(1, o.n_threads), o.progress, [&](int i) {
        protocols::Rng rng = resample_rng(o.seed, static_cast<std::uint64_t>(i));
        std::vector<double> s(v.size());
        for (double& x : s) x = v[static_cast<std::size_t>(rng.below(v.size()))];
        b.means[static_cast<std::size_t>(i)] = mean_of(s);
        if (want_median) b.medians[static_cast<std::size_t>(i)] = median_of(s);
    });
    b.means.resize(static_cast<std::size_t>(b.done));
    if (want_median) b.medians.resize(static_cast<std::size_t>(b.done));
    return b;
}

}  // namespace

AdjustmentSummary summarize_log_ratios(std::span<const double> log10_ratios, const ResampleOptions& options) {
    AdjustmentSummary s;
    std::vector<double> v;
    for (double x : log10_ratios) {
        if (std::isfinite(x))
            v.push_back(x);
        else
            ++s.n_excluded;
    }
    s.n = static_cast<int>(v.size());
    std::vector<std::string> reasons;
    if (s.n_excluded > 0) reasons.push_back(fmt::format("{} settings excluded (not a finite ratio)", s.n_excluded));
    if (v.empty()) {
        reasons.push_back("no settings");
        s.reason = join(reasons);
        return s;
    }
    const double m = mean_of(v);
    s.mean_log10_ratio = m;
    std::vector<double> tmp = v;
    s.median_log10_ratio = median_of(tmp);
    if (v.size() < 2) {
        reasons.push_back("a single setting: no spread, no intervals");
        s.reason = join(reasons);
        return s;
    }
    s.sd_log10_ratio = sd_of(v, m);
    if (!(options.level > 0.0 && options.level < 1.0)) {
        reasons.push_back(fmt::format("interval level {} is outside (0, 1)", options.level));
    } else {
        const MeanMedianBoot b = bootstrap_mean_median(v, options, true);
        s.mean_ci = percentile_interval(b.means, options.level);
        s.median_ci = percentile_interval(b.medians, options.level);
        if (b.done < options.n_resamples)
            reasons.push_back(fmt::format("bootstrap cancelled after {} of {}", b.done, options.n_resamples));
        if (!s.mean_ci) reasons.push_back("too few resamples for an interval");
    }
    s.reliable = reasons.empty();
    s.reason = join(reasons);
    return s;
}

AdjustmentSummary summarize_adjustment(std::span<const double> match_cd, std::span<const double> test_cd,
                                       const ResampleOptions& options) {
    const std::size_t n = std::min(match_cd.size(), test_cd.size());
    std::vector<double> ratios(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double m = match_cd[i];
        const double t = test_cd[i];
        const bool ok = std::isfinite(m) && std::isfinite(t) && m > 0.0 && t > 0.0;
        ratios[i] = ok ? std::log10(m / t) : std::numeric_limits<double>::quiet_NaN();  // NaN: excluded below
    }
    AdjustmentSummary s = summarize_log_ratios(ratios, options);
    if (match_cd.size() != test_cd.size()) {
        s.reliable = false;
        s.reason += (s.reason.empty() ? "" : "; ") +
                    fmt::format("{} match values but {} test values", match_cd.size(), test_cd.size());
    }
    return s;
}

Enhancement brightness_enhancement(double pse_log10, std::span<const double> pse_bootstrap_log10, double test_log10,
                                   double level) {
    Enhancement e;
    if (!std::isfinite(pse_log10) || !std::isfinite(test_log10)) {
        e.reason = "the PSE or the test intensity is not a finite number";
        return e;
    }
    e.log10_enhancement = pse_log10 - test_log10;
    e.ratio = std::pow(10.0, *e.log10_enhancement);
    if (!std::isfinite(*e.ratio)) e.ratio.reset();
    std::vector<double> shifted;
    shifted.reserve(pse_bootstrap_log10.size());
    for (double p : pse_bootstrap_log10) shifted.push_back(p - test_log10);
    e.ci = percentile_interval(std::move(shifted), level);
    if (!e.ci) e.reason = "no interval: fewer than two finite bootstrap PSEs (or a level outside (0, 1))";
    e.reliable = e.ci.has_value();
    return e;
}

PairedComparison compare_paired(std::span<const double> a, std::span<const double> b, const ResampleOptions& options) {
    PairedComparison c;
    std::vector<std::string> reasons;
    const std::size_t n = std::min(a.size(), b.size());
    if (a.size() != b.size()) reasons.push_back(fmt::format("{} values in A but {} in B", a.size(), b.size()));
    std::vector<double> d;
    for (std::size_t i = 0; i < n; ++i) {
        if (std::isfinite(a[i]) && std::isfinite(b[i]))
            d.push_back(a[i] - b[i]);
        else
            ++c.n_excluded;
    }
    c.n = static_cast<int>(d.size());
    if (c.n_excluded > 0) reasons.push_back(fmt::format("{} observers excluded (a value missing)", c.n_excluded));
    if (d.empty()) {
        reasons.push_back("no observers with both values");
        c.reason = join(reasons);
        return c;
    }
    const double m = mean_of(d);
    c.mean_difference = m;
    if (d.size() < 2) {
        reasons.push_back("a single observer: no test");
        c.reason = join(reasons);
        return c;
    }
    const double sd = sd_of(d, m);
    c.sd_difference = sd;
    c.dof = c.n - 1;
    const bool level_ok = options.level > 0.0 && options.level < 1.0;
    if (!level_ok) reasons.push_back(fmt::format("interval level {} is outside (0, 1)", options.level));
    if (sd > 0.0) {
        const double se = sd / std::sqrt(static_cast<double>(d.size()));
        const double t = m / se;
        const boost::math::students_t_distribution<double, detail::StatsPolicy> st(c.dof);
        const double p = 2.0 * boost::math::cdf(boost::math::complement(st, std::abs(t)));
        c.t = t;
        if (std::isfinite(p)) c.p_value = std::min(1.0, p);
        if (level_ok) {
            const double q = boost::math::quantile(st, 0.5 * (1.0 + options.level));
            c.t_ci = Interval{m - q * se, m + q * se, options.level};
        }
    } else {
        reasons.push_back("all differences are equal: no spread, no t-test");
    }
    if (level_ok) {
        const MeanMedianBoot boot = bootstrap_mean_median(d, options, false);
        c.ci = percentile_interval(boot.means, options.level);
        if (boot.done < options.n_resamples)
            reasons.push_back(fmt::format("bootstrap cancelled after {} of {}", boot.done, options.n_resamples));
    }
    c.reliable = reasons.empty();
    c.reason = join(reasons);
    return c;
}

}  // namespace atonlab::analysis
