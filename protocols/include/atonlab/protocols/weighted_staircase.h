#pragma once
// Weighted up/down (Kaernbach 1991, "Simple adaptive testing with the weighted
// up-down method", Percept. Psychophys. 49:227-229): every answer steps, down by
// S_down after Yes ("correct") and up by S_up after No, with
//     S_up / S_down = p / (1 - p),
// so that at the level where P(Yes) = p the expected drift p*S_down -
// (1-p)*S_up is zero and the track converges on the p point (e.g. p = 0.75:
// S_up = 3 S_down). It is the Staircase engine with n_up = n_down = 1 and
// up_step_ratio = p / (1 - p): reversals, step-size lists (of S_down), step
// types, clamps and stop rules are exactly the staircase's (staircase.h).
#include <cstdint>
#include <optional>
#include <vector>

#include "atonlab/protocols/staircase.h"

namespace atonlab::protocols {

struct WeightedStaircaseParams {
    double start = 0.0;                   ///< first level
    double target = 0.75;                 ///< p: the P(Yes) the track converges on, 0 < p < 1
    std::vector<double> step_sizes{1.0};  ///< S_down, each > 0; advances at each reversal; S_up = S_down p/(1-p)
    StepType step_type = StepType::Db;
    std::optional<int> n_reversals;  ///< as StaircaseParams::n_reversals
    int n_trials = 0;
    std::optional<int> max_trials;
    std::optional<double> min_level;
    std::optional<double> max_level;
    int estimate_reversals = 0;
};

/// The staircase parameters a weighted staircase runs with.
StaircaseParams to_staircase_params(const WeightedStaircaseParams& p);

class WeightedStaircase : public Staircase {
public:
    explicit WeightedStaircase(const WeightedStaircaseParams& params, std::uint64_t seed = 0);

    /// Its name in protocol files, the store and analysis (procedures.h).
    static constexpr std::string_view kName = "weighted-staircase";
    /// What protocols and analysis know of the kind (procedures.h; protocols/src/procedure_types/).
    static const ProcedureType& type();

    std::string_view kind() const noexcept override { return kName; }
    std::unique_ptr<Procedure> clone() const override { return std::make_unique<WeightedStaircase>(*this); }

    double target() const noexcept { return target_; }

private:
    double target_;
};

}  // namespace atonlab::protocols
