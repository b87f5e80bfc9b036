#pragma once
// The method of constant stimuli: a fixed list of levels, each shown
// `repetitions` times, in an order fixed at construction from the seed:
//  - Blocked: each level's repetitions together; the order of the blocks shuffled;
//  - Passes: `repetitions` passes, each a fresh shuffle of all the levels;
//  - Random: all levels x repetitions shuffled together.
// The answers (Yes / No) are tallied per level; the psychometric fit belongs to
// analysis/, estimate() only interpolates the crossing of `criterion`.
#include <cstdint>
#include <string_view>
#include <vector>

#include "atonlab/protocols/procedure.h"

namespace atonlab::protocols {

enum class ConstantOrder : std::uint8_t { Blocked, Passes, Random };

/// "blocked", "passes", "random".
std::string_view to_string(ConstantOrder o) noexcept;
/// Parses "blocked", "passes", "random"; throws ProcedureError("order") otherwise.
ConstantOrder parse_constant_order(std::string_view text);

struct ConstantStimuliParams {
    std::vector<double> levels;  ///< distinct finite levels, procedure's units; at least one
    int repetitions = 10;        ///< >= 1
    ConstantOrder order = ConstantOrder::Random;
    double criterion = 0.5;  ///< estimate(): the P(Yes) whose crossing is interpolated, 0 < c < 1
};

/// Method of constant stimuli. Takes Yes / No.
class ConstantStimuli : public Procedure {
public:
    ConstantStimuli(ConstantStimuliParams params, std::uint64_t seed);

    /// Its name in protocol files, the store and analysis (procedures.h).
    static constexpr std::string_view kName = "constant-stimuli";
    /// What protocols and analysis know of the kind (procedures.h; protocols/src/procedure_types/).
    static const ProcedureType& type();

    std::string_view kind() const noexcept override { return kName; }
    bool finished() const override { return answered_ >= schedule_.size(); }
    std::optional<Proposal> next() const override;
    /// The first crossing of `criterion` by the proportion of Yes, going up the
    /// sorted levels, by linear interpolation between neighbouring levels (NaN
    /// when it is not crossed). A rough guide; fit the psychometric function in analysis.
    Estimate estimate() const override;
    std::unique_ptr<Procedure> clone() const override { return std::make_unique<ConstantStimuli>(*this); }
    std::string state() const override;

    const ConstantStimuliParams& params() const noexcept { return params_; }
    /// The whole presentation order, as indices into params().levels.
    const std::vector<std::size_t>& schedule() const noexcept { return schedule_; }
    /// Per level (same order as params().levels): trials shown and Yes answers.
    const std::vector<int>& shown() const noexcept { return shown_; }
    const std::vector<int>& yes() const noexcept { return yes_; }

protected:
    void do_record(Response r) override;

private:
    ConstantStimuliParams params_;
    std::vector<std::size_t> schedule_;
    std::vector<int> shown_;
    std::vector<int> yes_;
    std::size_t answered_ = 0;
};

}  // namespace atonlab::protocols
