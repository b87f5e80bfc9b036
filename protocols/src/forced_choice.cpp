// Two-alternative forced choice (forced_choice.h).
#include "atonlab/protocols/forced_choice.h"

#include <fmt/format.h>

#include "checks.h"

namespace atonlab::protocols {

std::string_view to_string(ChoiceMapping m) noexcept {
    switch (m) {
        case ChoiceMapping::ChoseTest:
            return "chose-test";
        case ChoiceMapping::ChoseReference:
            return "chose-reference";
    }
    return "?";
}

ChoiceMapping parse_choice_mapping(std::string_view text) {
    if (text == "chose-test") return ChoiceMapping::ChoseTest;
    if (text == "chose-reference") return ChoiceMapping::ChoseReference;
    throw ProcedureError("mapping", fmt::format("must be \"chose-test\" or \"chose-reference\", not \"{}\"", text));
}

ForcedChoice::ForcedChoice(std::unique_ptr<Procedure> inner, ChoiceMapping mapping, std::uint64_t seed)
    : inner_(std::move(inner)), mapping_(mapping), rng_(seed) {
    detail::require(inner_ != nullptr, "procedure", "a forced choice needs a procedure to drive");
    detail::require(inner_->history().empty(), "procedure",
                    fmt::format("the {} already has responses; wrap a fresh procedure", inner_->kind()));
    test_on_left_ = rng_.coin();
}

ForcedChoice::ForcedChoice(const ForcedChoice& other)
    : Procedure(other),
      inner_(other.inner_->clone()),
      mapping_(other.mapping_),
      rng_(other.rng_),
      test_on_left_(other.test_on_left_) {}

ForcedChoice& ForcedChoice::operator=(const ForcedChoice& other) {
    if (this != &other) {
        ForcedChoice copy(other);
        *this = std::move(copy);
    }
    return *this;
}

Response ForcedChoice::inner_response(Response chosen_side, bool test_on_left, ChoiceMapping mapping) {
    if (chosen_side != Response::Left && chosen_side != Response::Right)
        throw ProcedureError("response",
                             fmt::format("a forced choice takes Left or Right, not {}", to_string(chosen_side)));
    const bool chose_test = (chosen_side == Response::Left) == test_on_left;
    return binary(mapping == ChoiceMapping::ChoseTest ? chose_test : !chose_test);
}

std::optional<Proposal> ForcedChoice::next() const {
    std::optional<Proposal> p = inner_->next();
    if (p) p->test_on_left = test_on_left_;
    return p;
}

void ForcedChoice::do_record(Response r) {
    inner_->record(inner_response(r, test_on_left_, mapping_));  // throws, unchanged, if the inner cannot take it
    test_on_left_ = rng_.coin();                                 // the side of the next trial
}

std::string ForcedChoice::state() const {
    const auto w = rng_.raw();
    return fmt::format("{} mapping={} test_on_left={} rng={:016x}{:016x}{:016x}{:016x} [{}]", kind(),
                       to_string(mapping_), test_on_left_ ? 1 : 0, w[0], w[1], w[2], w[3], inner_->state());
}

}  // namespace atonlab::protocols
