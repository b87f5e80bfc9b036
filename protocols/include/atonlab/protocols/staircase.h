#pragma once
// The transformed up/down staircase (Levitt 1971) with the exact rules of
// PsychoPy's StairHandler (psychopy/data/staircase.py, StairHandler.addResponse,
// calculateNextIntensity, _intensityInc, _intensityDec), so that a protocol
// written for PsychoPy behaves the same here:
//  - Yes ("correct", 1) counts towards going DOWN, No towards going UP;
//  - n_down consecutive Yes lower the level, n_up consecutive No raise it; the
//    run counter restarts after every step and whenever the answer changes;
//  - until the first reversal a 1-up/1-down rule applies (apply_initial_rule),
//    and the trial that makes the first reversal also steps by that rule;
//  - a reversal is a step in the direction opposite to the previous step; its
//    level is the level of the trial whose answer caused it;
//  - at each reversal the step size advances along step_sizes (the step taken
//    at that reversal already uses the new size) and stays at the last entry;
//  - steps are in dB (level *= 10^(+-step/20)), log10 units (level *=
//    10^(+-step)) or linear units (level += -step); a step up is clamped to
//    max_level, a step down to min_level;
//  - the staircase is finished when BOTH reversals >= n_reversals AND trials
//    >= n_trials (checked after each answer). n_reversals defaults to the number
//    of step sizes and is raised to it when smaller (PsychoPy does the same,
//    with a warning).
// Additions to PsychoPy's rules (off by default): max_trials, a hard cap for an
// observer who never reverses; up_step_ratio, the Kaernbach (1991) weighting
// used by WeightedStaircase.
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "atonlab/protocols/procedure.h"

namespace atonlab::protocols {

/// How a step changes the level (PsychoPy stepType).
enum class StepType : std::uint8_t {
    Db,   ///< level *= 10^(step/20) up, /= down: the level must stay > 0
    Log,  ///< level *= 10^step up, /= down: the level must stay > 0
    Lin,  ///< level += step up, -= down
};

/// "db", "log", "lin".
std::string_view to_string(StepType t) noexcept;
/// Parses "db", "log", "lin"; throws ProcedureError("step_type") otherwise.
StepType parse_step_type(std::string_view text);

/// StairHandler's arguments, with its defaults. Levels are in the procedure's
/// units (the protocol maps them, e.g. to the reference light's intensity in cd).
struct StaircaseParams {
    double start = 0.0;                   ///< startVal: the first level
    std::vector<double> step_sizes{4.0};  ///< stepSizes, each > 0; advances at each reversal
    StepType step_type = StepType::Db;    ///< stepType
    int n_up = 1;                         ///< nUp: consecutive No answers before the level goes up (>= 1)
    int n_down = 3;                       ///< nDown: consecutive Yes answers before the level goes down (>= 1)
    bool apply_initial_rule = true;       ///< applyInitialRule: 1-up/1-down until the first reversal
    std::optional<int> n_reversals;       ///< nReversals: minimum reversals; default step_sizes.size()
    int n_trials = 0;                     ///< nTrials: minimum trials
    std::optional<int> max_trials;        ///< hard cap on trials (not in PsychoPy)
    std::optional<double> min_level;      ///< minVal: steps down stop here
    std::optional<double> max_level;      ///< maxVal: steps up stop here
    double up_step_ratio = 1.0;           ///< step up = ratio * step down (1 in PsychoPy)
    int estimate_reversals = 0;           ///< estimate(): mean of the last N reversal levels; 0 = all
};

/// An up/down staircase. Takes Yes / No. Deterministic: the seed is accepted
/// for the common constructor shape and not used.
class Staircase : public Procedure {
public:
    explicit Staircase(StaircaseParams params, std::uint64_t seed = 0);

    /// Its name in protocol files, the store and analysis (procedures.h).
    static constexpr std::string_view kName = "staircase";
    /// What protocols and analysis know of the kind (procedures.h; protocols/src/procedure_types/).
    static const ProcedureType& type();

    std::string_view kind() const noexcept override { return kName; }
    bool finished() const override { return finished_; }
    std::optional<Proposal> next() const override;
    /// Mean (and sample sd) of the last estimate_reversals reversal levels (all
    /// when 0); NaN before the first reversal.
    Estimate estimate() const override;
    std::unique_ptr<Procedure> clone() const override { return std::make_unique<Staircase>(*this); }
    std::string state() const override;

    /// The parameters in force (n_reversals resolved).
    const StaircaseParams& params() const noexcept { return params_; }
    /// Levels of the trials answered so far (PsychoPy `intensities`).
    const std::vector<double>& levels() const noexcept { return levels_; }
    /// 0-based trials at which a reversal happened (PsychoPy `reversalPoints`).
    const std::vector<std::size_t>& reversal_trials() const noexcept { return reversal_trials_; }
    /// Levels at those reversals (PsychoPy `reversalIntensities`).
    const std::vector<double>& reversal_levels() const noexcept { return reversal_levels_; }
    /// The step size the next step will use (before any change a reversal makes).
    double current_step() const noexcept;

protected:
    void do_record(Response r) override;

private:
    enum class Direction : std::uint8_t { Start, Up, Down };
    void step_up();
    void step_down();

    StaircaseParams params_;
    double next_level_;
    std::vector<double> levels_;
    std::vector<std::size_t> reversal_trials_;
    std::vector<double> reversal_levels_;
    Direction direction_ = Direction::Start;
    int counter_ = 0;  ///< PsychoPy correctCounter: + run of Yes, - run of No since the last step
    bool finished_ = false;
};

}  // namespace atonlab::protocols
