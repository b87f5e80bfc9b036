#pragma once
// Two-alternative forced choice around any Yes/No procedure. Each trial the
// test stimulus goes on the left or on the right at random (seeded, drawn when
// the previous answer is recorded, so next() is fixed); the proposal carries
// test_on_left. The observer answers with the side chosen (Left / Right; for a
// temporal 2IFC, Left = the first interval); the wrapped procedure is told Yes
// or No according to the mapping:
//
//  - ChoseTest: Yes = "the observer chose the test side". For detection or
//    discrimination ("which side has the light?"), that is "correct": a
//    staircase on the test level goes down after correct answers and converges
//    on a point above 50% (e.g. 1-up/3-down: 79.4%); QUEST runs with gamma = 0.5.
//
//  - ChoseReference: Yes = "the observer chose the reference side". For
//    brightness matching ("which light is brighter?") with the procedure
//    running on the REFERENCE level: choosing the reference means the
//    reference looked brighter, so the reference should go DOWN, which is what
//    Yes does to a staircase. A 1-up/1-down staircase then converges on the
//    reference level judged brighter half the time: the point of subjective
//    equality (PSE) with the test. Constant stimuli on the reference level give
//    P(reference judged brighter) per level, whose 50% point is the PSE.
#include <cstdint>
#include <memory>
#include <string_view>

#include "atonlab/protocols/procedure.h"
#include "atonlab/protocols/rng.h"

namespace atonlab::protocols {

enum class ChoiceMapping : std::uint8_t {
    ChoseTest,       ///< Yes = chose the test side ("correct" in detection / discrimination)
    ChoseReference,  ///< Yes = chose the reference side ("reference judged brighter" in matching)
};

/// "chose-test", "chose-reference".
std::string_view to_string(ChoiceMapping m) noexcept;
/// Parses "chose-test", "chose-reference"; throws ProcedureError("mapping") otherwise.
ChoiceMapping parse_choice_mapping(std::string_view text);

class ForcedChoice : public Procedure {
public:
    /// `inner` must be fresh and take Yes / No.
    ForcedChoice(std::unique_ptr<Procedure> inner, ChoiceMapping mapping, std::uint64_t seed);
    ForcedChoice(const ForcedChoice& other);  ///< deep copy
    ForcedChoice& operator=(const ForcedChoice& other);
    ForcedChoice(ForcedChoice&&) noexcept = default;
    ForcedChoice& operator=(ForcedChoice&&) noexcept = default;
    ~ForcedChoice() override = default;

    std::string_view kind() const noexcept override { return "2afc"; }
    bool finished() const override { return inner_->finished(); }
    /// The inner proposal with test_on_left set.
    std::optional<Proposal> next() const override;
    Estimate estimate() const override { return inner_->estimate(); }
    std::unique_ptr<Procedure> clone() const override { return std::make_unique<ForcedChoice>(*this); }
    std::string state() const override;

    const Procedure& inner() const noexcept { return *inner_; }
    ChoiceMapping mapping() const noexcept { return mapping_; }
    /// What the inner procedure is told for an answer, given where the test was.
    static Response inner_response(Response chosen_side, bool test_on_left, ChoiceMapping mapping);

protected:
    void do_record(Response r) override;

private:
    std::unique_ptr<Procedure> inner_;
    ChoiceMapping mapping_;
    Rng rng_;
    bool test_on_left_ = false;
};

}  // namespace atonlab::protocols
