#pragma once
// Interleaving several procedures in one block (PsychoPy's MultiStairHandler
// does the same for staircases): before each trial one of the unfinished
// procedures is chosen, at random (seeded) or in turn, and its proposal is
// shown; the answer goes back to the procedure that proposed it. The block is
// finished when all of them are. A procedure that is mid-trial (the method of
// adjustment between actions and Confirm) keeps the floor until the trial ends.
//
// The interleaver's own history is the sequence of answers in the order given;
// replaying it into an interleaver built from fresh copies of the same
// procedures with the same seed reproduces every choice and every child state.
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "atonlab/protocols/procedure.h"
#include "atonlab/protocols/rng.h"

namespace atonlab::protocols {

enum class InterleaveOrder : std::uint8_t {
    Random,      ///< uniform among the unfinished procedures, seeded
    Sequential,  ///< round robin over the unfinished procedures, starting at the first
};

/// "random", "sequential".
std::string_view to_string(InterleaveOrder o) noexcept;
/// Parses "random", "sequential"; throws ProcedureError("interleave") otherwise.
InterleaveOrder parse_interleave_order(std::string_view text);

class Interleaver : public Procedure {
public:
    /// `procedures` must be fresh (no history) and not null.
    Interleaver(std::vector<std::unique_ptr<Procedure>> procedures, InterleaveOrder order, std::uint64_t seed);
    Interleaver(const Interleaver& other);  ///< deep copy
    Interleaver& operator=(const Interleaver& other);
    Interleaver(Interleaver&&) noexcept = default;
    Interleaver& operator=(Interleaver&&) noexcept = default;
    ~Interleaver() override = default;

    std::string_view kind() const noexcept override { return "interleaved"; }
    bool finished() const override { return finished_; }
    /// The chosen procedure's proposal, with `stream` set to its index.
    std::optional<Proposal> next() const override;
    /// No pooled estimate (the procedures usually measure different
    /// conditions): value is NaN, n the number of finished procedures. Ask
    /// procedure(i).estimate().
    Estimate estimate() const override;
    std::unique_ptr<Procedure> clone() const override { return std::make_unique<Interleaver>(*this); }
    std::string state() const override;
    bool mid_trial() const override;

    std::size_t size() const noexcept { return procedures_.size(); }
    const Procedure& procedure(std::size_t i) const { return *procedures_.at(i); }
    /// Index of the procedure whose proposal next() returns.
    std::size_t current() const noexcept { return current_; }

protected:
    void do_record(Response r) override;

private:
    void choose();

    std::vector<std::unique_ptr<Procedure>> procedures_;
    InterleaveOrder order_;
    Rng rng_;
    std::size_t current_ = 0;
    bool finished_ = false;
};

}  // namespace atonlab::protocols
