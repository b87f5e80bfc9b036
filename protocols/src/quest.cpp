// QUEST after Psychtoolbox-3's Quest package (quest.h); each step cites the .m
// file it follows.
#include "atonlab/protocols/quest.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "checks.h"
#include "state_text.h"

namespace atonlab::protocols {

std::string_view to_string(QuestMethod m) noexcept {
    switch (m) {
        case QuestMethod::Quantile:
            return "quantile";
        case QuestMethod::Mean:
            return "mean";
        case QuestMethod::Mode:
            return "mode";
    }
    return "?";
}

QuestMethod parse_quest_method(std::string_view text) {
    if (text == "quantile") return QuestMethod::Quantile;
    if (text == "mean") return QuestMethod::Mean;
    if (text == "mode") return QuestMethod::Mode;
    throw ProcedureError("method", fmt::format("must be \"quantile\", \"mean\" or \"mode\", not \"{}\"", text));
}

namespace {

constexpr std::ptrdiff_t kMaxDim = 2'000'000;  // 2M grid points: 16 MB per table; more is a units mistake

void validate(const QuestParams& p) {
    using detail::require;
    detail::require_finite(p.t_guess, "t_guess");
    detail::require_positive(p.t_guess_sd, "t_guess_sd");
    detail::require_positive(p.beta, "beta");
    require(std::isfinite(p.delta) && p.delta >= 0.0 && p.delta < 1.0, "delta",
            fmt::format("must lie in [0, 1), not {}", p.delta));
    require(std::isfinite(p.gamma) && p.gamma >= 0.0 && p.gamma < 1.0, "gamma",
            fmt::format("must lie in [0, 1), not {}", p.gamma));
    require(std::isfinite(p.p_threshold) && p.p_threshold > p.gamma && p.p_threshold < 1.0, "p_threshold",
            fmt::format("must lie strictly between gamma ({}) and 1, not {}", p.gamma, p.p_threshold));
    detail::require_positive(p.grain, "grain");
    if (p.range) detail::require_positive(*p.range, "range");
    if (p.quantile_order)
        require(std::isfinite(*p.quantile_order) && *p.quantile_order >= 0.0 && *p.quantile_order <= 1.0,
                "quantile_order", fmt::format("must lie in [0, 1], not {}", *p.quantile_order));
    require(p.n_trials >= 1, "n_trials", fmt::format("must be >= 1 (QUEST's stop rule), not {}", p.n_trials));
    if (p.stop_interval) detail::require_positive(*p.stop_interval, "stop_interval");
    if (p.min_level) detail::require_finite(*p.min_level, "min_level");
    if (p.max_level) detail::require_finite(*p.max_level, "max_level");
    if (p.min_level && p.max_level)
        require(*p.min_level <= *p.max_level, "min_level",
                fmt::format("({}) is greater than max_level ({})", *p.min_level, *p.max_level));
}

// QuestCreate: dim = range/grain rounded up to an even integer; 500 without a range.
std::ptrdiff_t grid_dim(const QuestParams& p) {
    if (!p.range) return 500;
    const double d = 2.0 * std::ceil(*p.range / p.grain / 2.0);
    detail::require(d <= static_cast<double>(kMaxDim), "grain",
                    fmt::format("range / grain = {} grid steps is more than {}", d, kMaxDim));
    return static_cast<std::ptrdiff_t>(d);
}

// The Weibull of QuestRecompute at x (log10 units, x_threshold already added).
double weibull(const QuestParams& p, double x) {
    return p.delta * p.gamma + (1.0 - p.delta) * (1.0 - (1.0 - p.gamma) * std::exp(-std::pow(10.0, p.beta * x)));
}

// interp1(xs, ys, at) for strictly increasing xs, `at` inside [xs.front(), xs.back()].
double interp1(const std::vector<double>& xs, const std::vector<double>& ys, double at) {
    const auto hi = std::upper_bound(xs.begin(), xs.end(), at);
    if (hi == xs.begin()) return ys.front();
    const std::size_t k = static_cast<std::size_t>(hi - xs.begin()) - 1;
    if (xs[k] == at || k + 1 == xs.size()) return ys[k];
    return ys[k] + (at - xs[k]) / (xs[k + 1] - xs[k]) * (ys[k + 1] - ys[k]);
}

}  // namespace

Quest::Quest(QuestParams params, std::uint64_t /*seed*/) : params_(std::move(params)) {
    validate(params_);
    const std::ptrdiff_t dim = grid_dim(params_);
    half_dim_ = dim / 2;
    const QuestParams& p = params_;

    // QuestRecompute: the unshifted Weibull on x2 = i2*grain, i2 = -dim..dim.
    const std::size_t n2 = static_cast<std::size_t>(2 * dim + 1);
    std::vector<double> x2(n2), p2(n2);
    for (std::size_t k = 0; k < n2; ++k) {
        x2[k] = static_cast<double>(static_cast<std::ptrdiff_t>(k) - dim) * p.grain;
        p2[k] = weibull(p, x2[k]);
    }
    const double lo = std::min(p2.front(), p2.back()), hi = std::max(p2.front(), p2.back());
    detail::require(lo <= p.p_threshold && p.p_threshold <= hi, "p_threshold",
                    fmt::format("{} is outside the range [{}, {}] that the psychometric function reaches on the "
                                "grid; widen range or check beta, gamma, delta",
                                p.p_threshold, lo, hi));
    // index = find(diff(p2)): the strictly monotonic subset; xThreshold = interp1(p2(index), x2(index), pThreshold).
    std::vector<double> pm, xm;
    for (std::size_t k = 0; k + 1 < n2; ++k) {
        if (p2[k + 1] != p2[k]) {
            pm.push_back(p2[k]);
            xm.push_back(x2[k]);
        }
    }
    detail::require(
        pm.size() >= 2, "beta",
        fmt::format("the psychometric function has only {} strictly monotonic point(s) on the grid", pm.size()));
    detail::require(pm.front() <= p.p_threshold && p.p_threshold <= pm.back(), "p_threshold",
                    fmt::format("the psychometric function has no {} threshold on the grid", p.p_threshold));
    x_threshold_ = interp1(pm, xm, p.p_threshold);

    // The shifted function, plain (as Psychtoolbox) and as logs that cannot underflow:
    //   p     = gamma + (1-delta)(1-gamma)(1 - e^-u),  u = 10^(beta (x + xThreshold))
    //   1 - p = (1-gamma)(delta + (1-delta) e^-u)
    p2_.resize(n2);
    log_p2_.resize(n2);
    log_q2_.resize(n2);
    for (std::size_t k = 0; k < n2; ++k) {
        const double s = p.beta * (x2[k] + x_threshold_);  // log10 u
        const double u = std::pow(10.0, s);
        const double one_minus_e = -std::expm1(-u);  // 1 - e^-u, accurate for small u
        p2_[k] = weibull(p, x2[k] + x_threshold_);
        if (p.gamma > 0.0)
            log_p2_[k] = std::log(p.gamma + (1.0 - p.delta) * (1.0 - p.gamma) * one_minus_e);
        else if (u > 0.0)
            log_p2_[k] = std::log1p(-p.delta) + std::log(one_minus_e);
        else  // u underflowed: 1 - e^-u = u, log u = s ln 10
            log_p2_[k] = std::log1p(-p.delta) + s * std::numbers::ln10;
        log_q2_[k] = std::log1p(-p.gamma) + (p.delta > 0.0 ? std::log(p.delta + (1.0 - p.delta) * std::exp(-u)) : -u);
    }

    // QuestRecompute: best quantile order from the floor and ceiling of the function (Pelli 1987).
    if (p.quantile_order) {
        quantile_order_ = *p.quantile_order;
    } else {
        const double eps = std::numeric_limits<double>::epsilon();  // MATLAB eps
        const double pL = p2_.front(), pH = p2_.back();
        double pE = pH * std::log(pH + eps) - pL * std::log(pL + eps) + (1 - pH + eps) * std::log(1 - pH + eps) -
                    (1 - pL + eps) * std::log(1 - pL + eps);
        pE = 1 / (1 + std::exp(pE / (pL - pH)));
        quantile_order_ = (pE - pL) / (pH - pL);
    }

    // The Gaussian prior, as a log (normalisation is irrelevant).
    log_pdf_.resize(static_cast<std::size_t>(dim + 1));
    for (std::ptrdiff_t i = -half_dim_; i <= half_dim_; ++i) {
        const double z = x_at(i) / p.t_guess_sd;
        log_pdf_[static_cast<std::size_t>(i + half_dim_)] = -0.5 * z * z;
    }

    next_level_ = p.first_at_guess ? p.t_guess : propose();
}

std::vector<double> Quest::grid() const {
    std::vector<double> g(log_pdf_.size());
    for (std::ptrdiff_t i = -half_dim_; i <= half_dim_; ++i)
        g[static_cast<std::size_t>(i + half_dim_)] = params_.t_guess + x_at(i);
    return g;
}

std::vector<double> Quest::posterior() const {
    std::vector<double> w(log_pdf_.size());
    double sum = 0.0;
    for (std::size_t j = 0; j < w.size(); ++j) sum += (w[j] = std::exp(log_pdf_[j]));
    for (double& v : w) v /= sum;
    return w;
}

double Quest::p_yes(double x) const {
    const double dim = static_cast<double>(2 * half_dim_);
    const double k = std::clamp(std::round(x / params_.grain), -dim, dim);
    return p2_[static_cast<std::size_t>(static_cast<std::ptrdiff_t>(k) + 2 * half_dim_)];
}

// QuestMean: t = tGuess + sum(pdf .* x) / sum(pdf).
double Quest::mean() const {
    double sw = 0.0, swx = 0.0;
    for (std::ptrdiff_t i = -half_dim_; i <= half_dim_; ++i) {
        const double w = std::exp(log_pdf_[static_cast<std::size_t>(i + half_dim_)]);
        sw += w;
        swx += w * x_at(i);
    }
    return params_.t_guess + swx / sw;
}

// QuestSd: sqrt(sum(pdf .* x.^2)/p - (sum(pdf .* x)/p)^2); clamped at 0 because
// a posterior collapsed onto one grid point can round the difference below zero.
double Quest::sd() const {
    double sw = 0.0, swx = 0.0, swxx = 0.0;
    for (std::ptrdiff_t i = -half_dim_; i <= half_dim_; ++i) {
        const double w = std::exp(log_pdf_[static_cast<std::size_t>(i + half_dim_)]);
        const double x = x_at(i);
        sw += w;
        swx += w * x;
        swxx += w * x * x;
    }
    const double m = swx / sw;
    return std::sqrt(std::max(0.0, swxx / sw - m * m));
}

// QuestMode: [p, iMode] = max(pdf) (the first maximum); t = x(iMode) + tGuess.
double Quest::mode() const {
    const auto it = std::max_element(log_pdf_.begin(), log_pdf_.end());
    return params_.t_guess + x_at(static_cast<std::ptrdiff_t>(it - log_pdf_.begin()) - half_dim_);
}

// QuestQuantile: p = cumsum(pdf); below p(1) -> the first grid point; otherwise
// interp1 over the points where the cumulative sum strictly increases.
double Quest::quantile(double order) const {
    if (!(order >= 0.0 && order <= 1.0))
        throw ProcedureError("quantile_order", fmt::format("must lie in [0, 1], not {}", order));
    std::vector<double> c, xs;
    c.reserve(log_pdf_.size());
    xs.reserve(log_pdf_.size());
    double cum = 0.0, prev = -1.0;  // diff([-1 p]) > 0 keeps the first point
    for (std::ptrdiff_t i = -half_dim_; i <= half_dim_; ++i) {
        cum += std::exp(log_pdf_[static_cast<std::size_t>(i + half_dim_)]);
        if (cum > prev) {
            c.push_back(cum);
            xs.push_back(x_at(i));
        }
        prev = cum;
    }
    const double target = order * cum;
    if (target < c.front()) return params_.t_guess + x_at(-half_dim_);
    if (c.size() < 2) return params_.t_guess + xs.front();  // Psychtoolbox errors; one point is its own quantile
    return params_.t_guess + interp1(c, xs, target);
}

double Quest::propose() const {
    double t = 0.0;
    switch (params_.method) {
        case QuestMethod::Quantile:
            t = quantile();
            break;
        case QuestMethod::Mean:
            t = mean();
            break;
        case QuestMethod::Mode:
            t = mode();
            break;
    }
    // PsychoPy QuestHandler.calculateNextIntensity: clamp to [minVal, maxVal].
    if (params_.max_level && t > *params_.max_level) t = *params_.max_level;
    if (params_.min_level && t < *params_.min_level) t = *params_.min_level;
    return t;
}

std::optional<Proposal> Quest::next() const {
    if (finished_) return std::nullopt;
    Proposal p;
    p.level = next_level_;
    p.trial = levels_.size();
    return p;
}

// QuestUpdate, in the log domain.
void Quest::do_record(Response r) {
    const bool yes = detail::require_binary(r, kind());
    const double intensity = next_level_;
    levels_.push_back(intensity);

    // ii = size(pdf,2) + i - round((inten - tGuess)/grain), shifted back inside the
    // table when out of range: the rounded offset k is clamped to [-dim/2, dim/2] and
    // candidate i sees the psychometric function at x2 index k - i.
    const double inten = std::clamp(intensity, -1e10, 1e10);
    const double half = static_cast<double>(half_dim_);
    const auto k =
        static_cast<std::ptrdiff_t>(std::clamp(std::round((inten - params_.t_guess) / params_.grain), -half, half));
    const std::vector<double>& table = yes ? log_p2_ : log_q2_;
    const std::ptrdiff_t dim = 2 * half_dim_;
    for (std::ptrdiff_t i = -half_dim_; i <= half_dim_; ++i)
        log_pdf_[static_cast<std::size_t>(i + half_dim_)] += table[static_cast<std::size_t>(k - i + dim)];

    // Renormalise: the maximum of the log posterior back to 0 (Psychtoolbox's
    // normalizePdf, which keeps the pdf from underflowing, in log form).
    const double top = *std::max_element(log_pdf_.begin(), log_pdf_.end());
    // The log-likelihood tables are finite except log(1-p) with delta = 0 where
    // 10^(beta (x + xThreshold)) overflows; a No answer always leaves the largest
    // threshold candidate (x <= 0 there) finite, so the maximum stays finite.
    if (!std::isfinite(top)) throw std::logic_error("quest: the posterior vanished everywhere");
    for (double& v : log_pdf_) v -= top;

    const bool enough_trials = static_cast<int>(levels_.size()) >= params_.n_trials;
    const bool narrow = params_.stop_interval && quantile(0.95) - quantile(0.05) < *params_.stop_interval;
    finished_ = enough_trials || narrow;
    if (!finished_) next_level_ = propose();
}

Estimate Quest::estimate() const {
    Estimate e;
    e.value = mean();
    e.sd = sd();
    e.n = levels_.size();
    e.method = "posterior mean +- sd (QuestMean, QuestSd)";
    return e;
}

std::string Quest::state() const {
    return fmt::format("{} trials={} next={} mean={} posterior={:016x} finished={}", kind(), levels_.size(),
                       detail::hex(next_level_), detail::hex(mean()), detail::hash_doubles(log_pdf_),
                       finished_ ? 1 : 0);
}

}  // namespace atonlab::protocols
