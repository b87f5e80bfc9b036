// Weighted up/down (Kaernbach 1991) on the Staircase engine (weighted_staircase.h).
#include "atonlab/protocols/weighted_staircase.h"

#include <fmt/format.h>

#include <cmath>

#include "checks.h"

namespace atonlab::protocols {

StaircaseParams to_staircase_params(const WeightedStaircaseParams& p) {
    detail::require(std::isfinite(p.target) && p.target > 0.0 && p.target < 1.0, "target",
                    fmt::format("must lie strictly between 0 and 1, not {}", p.target));
    StaircaseParams s;
    s.start = p.start;
    s.step_sizes = p.step_sizes;
    s.step_type = p.step_type;
    s.n_up = 1;
    s.n_down = 1;
    s.apply_initial_rule = true;  // with 1-up/1-down the initial rule changes nothing
    s.n_reversals = p.n_reversals;
    s.n_trials = p.n_trials;
    s.max_trials = p.max_trials;
    s.min_level = p.min_level;
    s.max_level = p.max_level;
    s.up_step_ratio = p.target / (1.0 - p.target);  // Kaernbach 1991: S_up / S_down = p / (1 - p)
    s.estimate_reversals = p.estimate_reversals;
    return s;
}

WeightedStaircase::WeightedStaircase(const WeightedStaircaseParams& params, std::uint64_t seed)
    : Staircase(to_staircase_params(params), seed), target_(params.target) {}

}  // namespace atonlab::protocols
