// The method of adjustment as a replayable state machine (adjustment.h).
#include "atonlab/protocols/adjustment.h"

#include <fmt/format.h>

#include <cmath>
#include <numeric>

#include "checks.h"
#include "state_text.h"

namespace atonlab::protocols {

namespace {

void validate(const AdjustmentParams& p) {
    using detail::require;
    detail::require_finite(p.start_min, "start_min");
    detail::require_finite(p.start_max, "start_max");
    require(p.start_min <= p.start_max, "start_min",
            fmt::format("({}) is greater than start_max ({})", p.start_min, p.start_max));
    detail::require_positive(p.coarse_step, "coarse_step");
    detail::require_positive(p.fine_step, "fine_step");
    require(p.fine_step <= p.coarse_step, "fine_step",
            fmt::format("({}) is larger than coarse_step ({})", p.fine_step, p.coarse_step));
    require(p.n_trials >= 1, "n_trials", fmt::format("must be >= 1, not {}", p.n_trials));
    if (p.min_level) detail::require_finite(*p.min_level, "min_level");
    if (p.max_level) detail::require_finite(*p.max_level, "max_level");
    if (p.min_level && p.max_level)
        require(*p.min_level <= *p.max_level, "min_level",
                fmt::format("({}) is greater than max_level ({})", *p.min_level, *p.max_level));
    if (p.min_level)
        require(p.start_min >= *p.min_level, "start_min",
                fmt::format("({}) is below min_level ({})", p.start_min, *p.min_level));
    if (p.max_level)
        require(p.start_max <= *p.max_level, "start_max",
                fmt::format("({}) is above max_level ({})", p.start_max, *p.max_level));
}

}  // namespace

Adjustment::Adjustment(AdjustmentParams params, std::uint64_t seed) : params_(std::move(params)), rng_(seed) {
    validate(params_);
    begin_trial();
}

void Adjustment::begin_trial() {
    level_ = rng_.uniform(params_.start_min, params_.start_max);
    starts_.push_back(level_);
    actions_in_trial_ = 0;
}

std::optional<Proposal> Adjustment::next() const {
    if (finished()) return std::nullopt;
    Proposal p;
    p.level = level_;
    p.trial = matches_.size();
    return p;
}

void Adjustment::do_record(Response r) {
    double step = 0.0;
    switch (r) {
        case Response::CoarseUp:
            step = params_.coarse_step;
            break;
        case Response::CoarseDown:
            step = -params_.coarse_step;
            break;
        case Response::FineUp:
            step = params_.fine_step;
            break;
        case Response::FineDown:
            step = -params_.fine_step;
            break;
        case Response::Confirm:
            matches_.push_back(level_);
            if (!finished())
                begin_trial();
            else
                actions_in_trial_ = 0;
            return;
        default:
            throw ProcedureError("response", fmt::format("the method of adjustment takes CoarseUp, CoarseDown, FineUp, "
                                                         "FineDown or Confirm, not {}",
                                                         to_string(r)));
    }
    level_ += step;
    if (params_.max_level && level_ > *params_.max_level) level_ = *params_.max_level;
    if (params_.min_level && level_ < *params_.min_level) level_ = *params_.min_level;
    ++actions_in_trial_;
}

Estimate Adjustment::estimate() const {
    Estimate e;
    e.n = matches_.size();
    e.method = "mean of matches";
    if (matches_.empty()) return e;
    const double n = static_cast<double>(matches_.size());
    e.value = std::accumulate(matches_.begin(), matches_.end(), 0.0) / n;
    if (matches_.size() >= 2) {
        double ss = 0.0;
        for (double m : matches_) ss += (m - e.value) * (m - e.value);
        e.sd = std::sqrt(ss / (n - 1.0));
    }
    return e;
}

std::string Adjustment::state() const {
    const auto w = rng_.raw();
    return fmt::format(
        "{} trial={} level={} actions={} matches={:016x} starts={:016x} rng={:016x}{:016x}{:016x}{:016x}", kind(),
        matches_.size(), detail::hex(level_), actions_in_trial_, detail::hash_doubles(matches_),
        detail::hash_doubles(starts_), w[0], w[1], w[2], w[3]);
}

}  // namespace atonlab::protocols
