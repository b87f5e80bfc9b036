// Up/down staircase with PsychoPy StairHandler semantics (staircase.h). The
// order of operations in do_record() follows StairHandler.addResponse and
// calculateNextIntensity line by line (psychopy/data/staircase.py), because the
// order is what fixes reversals and step sizes: count the answer, decide the
// direction and whether it reverses, record the reversal, test the stop rule,
// advance the step size, then step.
#include "atonlab/protocols/staircase.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "checks.h"
#include "state_text.h"

namespace atonlab::protocols {

std::string_view to_string(StepType t) noexcept {
    switch (t) {
        case StepType::Db:
            return "db";
        case StepType::Log:
            return "log";
        case StepType::Lin:
            return "lin";
    }
    return "?";
}

StepType parse_step_type(std::string_view text) {
    if (text == "db") return StepType::Db;
    if (text == "log") return StepType::Log;
    if (text == "lin") return StepType::Lin;
    throw ProcedureError("step_type", fmt::format("must be \"db\", \"log\" or \"lin\", not \"{}\"", text));
}

namespace {

StaircaseParams validated(StaircaseParams p) {
    using detail::require;
    require(!p.step_sizes.empty(), "step_sizes", "needs at least one step size");
    for (double s : p.step_sizes) detail::require_positive(s, "step_sizes");
    require(p.n_up >= 1, "n_up", fmt::format("must be >= 1, not {}", p.n_up));
    require(p.n_down >= 1, "n_down", fmt::format("must be >= 1, not {}", p.n_down));
    require(p.n_trials >= 0, "n_trials", fmt::format("must be >= 0, not {}", p.n_trials));
    if (p.n_reversals) require(*p.n_reversals >= 0, "n_reversals", fmt::format("must be >= 0, not {}", *p.n_reversals));
    if (p.max_trials) {
        require(*p.max_trials >= 1, "max_trials", fmt::format("must be >= 1, not {}", *p.max_trials));
        require(*p.max_trials >= p.n_trials, "max_trials",
                fmt::format("({}) is smaller than n_trials ({})", *p.max_trials, p.n_trials));
    }
    require(!(p.n_reversals && *p.n_reversals == 0 && p.n_trials == 0 && !p.max_trials), "n_reversals",
            "is 0 and so are n_trials and max_trials: the staircase has no stop rule");
    detail::require_positive(p.up_step_ratio, "up_step_ratio");
    require(p.estimate_reversals >= 0, "estimate_reversals", fmt::format("must be >= 0, not {}", p.estimate_reversals));
    if (p.min_level) detail::require_finite(*p.min_level, "min_level");
    if (p.max_level) detail::require_finite(*p.max_level, "max_level");
    if (p.min_level && p.max_level)
        require(*p.min_level <= *p.max_level, "min_level",
                fmt::format("({}) is greater than max_level ({})", *p.min_level, *p.max_level));
    detail::require_finite(p.start, "start");
    if (p.step_type != StepType::Lin)
        require(
            p.start > 0.0, "start",
            fmt::format("must be > 0 with step_type \"{}\" (steps multiply), not {}", to_string(p.step_type), p.start));
    if (p.min_level)
        require(p.start >= *p.min_level, "start", fmt::format("({}) is below min_level ({})", p.start, *p.min_level));
    if (p.max_level)
        require(p.start <= *p.max_level, "start", fmt::format("({}) is above max_level ({})", p.start, *p.max_level));

    // PsychoPy: nReversals None -> len(stepSizes); smaller than len(stepSizes) -> raised to it.
    const int n_steps = static_cast<int>(p.step_sizes.size());
    p.n_reversals = p.n_reversals ? std::max(*p.n_reversals, n_steps) : n_steps;
    return p;
}

}  // namespace

Staircase::Staircase(StaircaseParams params, std::uint64_t /*seed*/)
    : params_(validated(std::move(params))), next_level_(params_.start) {}

double Staircase::current_step() const noexcept {
    const std::size_t i = std::min(reversal_levels_.size(), params_.step_sizes.size() - 1);
    return params_.step_sizes[i];
}

std::optional<Proposal> Staircase::next() const {
    if (finished_) return std::nullopt;
    Proposal p;
    p.level = next_level_;
    p.trial = levels_.size();
    return p;
}

// PsychoPy _intensityInc: step up by the current size, clamp to maxVal, reset the counter.
void Staircase::step_up() {
    const double step = params_.up_step_ratio * current_step();
    switch (params_.step_type) {
        case StepType::Db:
            next_level_ *= std::pow(10.0, step / 20.0);
            break;
        case StepType::Log:
            next_level_ *= std::pow(10.0, step);
            break;
        case StepType::Lin:
            next_level_ += step;
            break;
    }
    if (params_.max_level && next_level_ > *params_.max_level) next_level_ = *params_.max_level;
    counter_ = 0;
}

// PsychoPy _intensityDec: step down by the current size, clamp to minVal, reset the counter.
void Staircase::step_down() {
    const double step = current_step();
    switch (params_.step_type) {
        case StepType::Db:
            next_level_ /= std::pow(10.0, step / 20.0);
            break;
        case StepType::Log:
            next_level_ /= std::pow(10.0, step);
            break;
        case StepType::Lin:
            next_level_ -= step;
            break;
    }
    counter_ = 0;
    if (params_.min_level && next_level_ < *params_.min_level) next_level_ = *params_.min_level;
}

void Staircase::do_record(Response r) {
    const bool yes = detail::require_binary(r, kind());
    const std::size_t trial = levels_.size();  // PsychoPy thisTrialN
    levels_.push_back(next_level_);

    // addResponse: extend the run if this answer repeats the previous one, else restart it.
    const bool repeats = !history().empty() && history().back() == r;
    if (yes)
        counter_ = repeats ? counter_ + 1 : 1;
    else
        counter_ = repeats ? counter_ - 1 : -1;

    // calculateNextIntensity: direction and reversal.
    const bool initial_phase = reversal_levels_.empty() && params_.apply_initial_rule;
    bool reversal = false;
    if (initial_phase) {
        if (yes) {
            reversal = direction_ == Direction::Up;
            direction_ = Direction::Down;
        } else {
            reversal = direction_ == Direction::Down;
            direction_ = Direction::Up;
        }
    } else if (counter_ >= params_.n_down) {
        reversal = direction_ == Direction::Up;  // 'start' is not a reversal
        direction_ = Direction::Down;
    } else if (counter_ <= -params_.n_up) {
        reversal = direction_ == Direction::Down;
        direction_ = Direction::Up;
    }

    if (reversal) {
        reversal_trials_.push_back(trial);
        reversal_levels_.push_back(levels_.back());
    }

    // Stop rule: both minimums met (plus our optional hard cap).
    const int n_rev = static_cast<int>(reversal_levels_.size());
    const int n_trials = static_cast<int>(levels_.size());
    if ((n_rev >= *params_.n_reversals && n_trials >= params_.n_trials) ||
        (params_.max_trials && n_trials >= *params_.max_trials))
        finished_ = true;

    // The step size is current_step(), which already reflects the reversal just
    // recorded: PsychoPy sets stepSizeCurrent = stepSizes[min(len(reversals), len-1)].
    // The first reversal (initial_phase still true here) steps by the 1-up/1-down rule.
    if (initial_phase) {
        if (yes)
            step_down();
        else
            step_up();
    } else if (counter_ >= params_.n_down) {
        step_down();
    } else if (counter_ <= -params_.n_up) {
        step_up();
    }
}

Estimate Staircase::estimate() const {
    Estimate e;
    const std::size_t total = reversal_levels_.size();
    const std::size_t n =
        params_.estimate_reversals == 0 ? total : std::min(total, static_cast<std::size_t>(params_.estimate_reversals));
    e.n = n;
    e.method = params_.estimate_reversals == 0 ? "mean of all reversals"
                                               : fmt::format("mean of last {} reversals", params_.estimate_reversals);
    if (n == 0) return e;
    const auto first = reversal_levels_.end() - static_cast<std::ptrdiff_t>(n);
    const double mean = std::accumulate(first, reversal_levels_.end(), 0.0) / static_cast<double>(n);
    e.value = mean;
    if (n >= 2) {
        double ss = 0.0;
        for (auto it = first; it != reversal_levels_.end(); ++it) ss += (*it - mean) * (*it - mean);
        e.sd = std::sqrt(ss / static_cast<double>(n - 1));
    }
    return e;
}

std::string Staircase::state() const {
    const char* dir = direction_ == Direction::Start ? "start" : direction_ == Direction::Up ? "up" : "down";
    return fmt::format(
        "{} trials={} next={} dir={} counter={} reversals={} rev_levels={:016x} rev_trials={:016x} "
        "levels={:016x} finished={}",
        kind(), levels_.size(), detail::hex(next_level_), dir, counter_, reversal_levels_.size(),
        detail::hash_doubles(reversal_levels_), detail::hash_ints(reversal_trials_), detail::hash_doubles(levels_),
        finished_ ? 1 : 0);
}

}  // namespace atonlab::protocols
