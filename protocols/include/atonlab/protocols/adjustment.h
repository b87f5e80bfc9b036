#pragma once
// The method of adjustment: the observer moves the level up and down in coarse
// and fine steps until the stimulus matches, then confirms. Each trial starts
// at a random level, uniform in [start_min, start_max] (seeded), so that the
// observer cannot match by counting key presses. Levels are log10 intensities
// and the steps are log10 units (a coarse step of 0.1 is a factor 1.26).
//
// As a state machine: one Response is one ACTION (CoarseUp, CoarseDown, FineUp,
// FineDown, Confirm). Up/down actions move the level (clamped to
// [min_level, max_level]); Confirm ends the trial, records the level as that
// trial's match and draws the next trial's start. Replaying the actions
// therefore reproduces every level shown, every match and every start.
#include <cstdint>
#include <optional>
#include <vector>

#include "atonlab/protocols/procedure.h"
#include "atonlab/protocols/rng.h"

namespace atonlab::protocols {

struct AdjustmentParams {
    double start_min = -1.0;  ///< random starts are uniform in [start_min, start_max], log10 intensity
    double start_max = 1.0;
    double coarse_step = 0.1;         ///< log10 units, > 0
    double fine_step = 0.01;          ///< log10 units, > 0, <= coarse_step
    std::optional<double> min_level;  ///< adjustments stop here (log10 intensity)
    std::optional<double> max_level;  ///< adjustments stop here (log10 intensity)
    int n_trials = 1;                 ///< matches to collect, >= 1
};

/// Method of adjustment. Takes CoarseUp, CoarseDown, FineUp, FineDown, Confirm.
class Adjustment : public Procedure {
public:
    Adjustment(AdjustmentParams params, std::uint64_t seed);

    /// Its name in protocol files, the store and analysis (procedures.h).
    static constexpr std::string_view kName = "adjustment";
    /// What protocols and analysis know of the kind (procedures.h; protocols/src/procedure_types/).
    static const ProcedureType& type();

    std::string_view kind() const noexcept override { return kName; }
    bool finished() const override { return static_cast<int>(matches_.size()) >= params_.n_trials; }
    /// The level to show now; `trial` is the match being made.
    std::optional<Proposal> next() const override;
    /// Mean and sample sd of the matched levels.
    Estimate estimate() const override;
    std::unique_ptr<Procedure> clone() const override { return std::make_unique<Adjustment>(*this); }
    std::string state() const override;
    bool mid_trial() const override { return actions_in_trial_ > 0; }

    const AdjustmentParams& params() const noexcept { return params_; }
    /// The confirmed level of each finished trial, log10 intensity.
    const std::vector<double>& matches() const noexcept { return matches_; }
    /// The random start of each trial begun so far (the current one included).
    const std::vector<double>& starts() const noexcept { return starts_; }
    /// The level being shown now.
    double level() const noexcept { return level_; }

protected:
    void do_record(Response r) override;

private:
    void begin_trial();

    AdjustmentParams params_;
    Rng rng_;
    double level_ = 0.0;
    std::vector<double> starts_;
    std::vector<double> matches_;
    int actions_in_trial_ = 0;
};

}  // namespace atonlab::protocols
