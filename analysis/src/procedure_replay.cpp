#include "procedure_replay.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <memory>

#include "atonlab/protocols/procedures.h"
#include "atonlab/protocols/protocol_file.h"

namespace atonlab::analysis::detail {

namespace p = atonlab::protocols;

namespace {

ConditionDesign condition_design(const p::Condition& c) {
    ConditionDesign d;
    d.condition = &c;
    const p::ProcedureType& type = c.procedure.type();
    d.procedure = std::string(type.name);
    // The outcome is "chose the level stimulus" (2AFC) or "yes" (yes-no); the
    // procedure's Yes is the protocol's `choice`. They agree when the choice
    // names the stimulus the level is on.
    const bool yes_is_outcome = c.yes_means_level();
    const std::optional<double> p_yes = c.procedure.target_p_yes();
    if (p_yes) {
        d.target_p = yes_is_outcome ? *p_yes : 1.0 - *p_yes;
    } else {
        d.note = fmt::format("condition \"{}\": {} has no simple target probability; its thresholds are given at P = 0.5",
                             c.name, type.describe(c.procedure.params));
    }
    // Guess rate of the outcome: QUEST states its own; a 2AFC scored as "chose
    // the test" with the level on the test and a target above 0.5 is a
    // detection or discrimination (correct / incorrect, gamma = 0.5); every
    // comparison whose target is 0.5 (a PSE) runs from 0 to 1.
    if (const std::optional<double> own = type.guess_rate(c.procedure.params); own && yes_is_outcome) {
        d.guess_rate = *own;
    } else if (c.task == p::Task::TwoAfc && c.level_on == p::Role::Test && c.choice == p::ChoiceMapping::ChoseTest &&
               d.target_p > 0.5 + 1e-9) {
        d.guess_rate = 0.5;
    }
    return d;
}

}  // namespace

ProtocolDesign design_of(std::string_view protocol_text, std::string_view protocol_name) {
    ProtocolDesign out;
    try {
        out.protocol = p::parse_protocol(protocol_text, protocol_name.empty() ? "protocol.toml" : protocol_name);
    } catch (const std::exception& e) {
        out.error = e.what();
        return out;
    }
    for (const p::Block& b : out.protocol->blocks) {
        for (const p::Condition& c : b.conditions) {
            out.conditions.emplace(c.name, condition_design(c));
            out.order.push_back(c.name);
        }
    }
    return out;
}

std::optional<std::size_t> track_number(std::string_view procedure_id) {
    const auto slash = procedure_id.rfind("/t");
    if (slash == std::string_view::npos) return std::nullopt;
    const std::string_view digits = procedure_id.substr(slash + 2);
    std::size_t t = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), t);
    if (ec != std::errc() || end != digits.data() + digits.size() || digits.empty()) return std::nullopt;
    return t;
}

std::string replay_track(const ConditionDesign& design, std::size_t track, const std::vector<Trial*>& trials) {
    const p::Condition& c = *design.condition;
    const p::ProcedureType& type = c.procedure.type();
    if (!type.adaptive()) return {};
    if (track >= c.procedure.tracks()) return fmt::format("the protocol's condition has no track {}", track);
    // The inner procedure alone (a yes-no copy of the condition is not wrapped
    // in a ForcedChoice); the 2AFC answers are mapped as ForcedChoice maps them.
    p::Condition inner_condition = c;
    inner_condition.task = p::Task::YesNo;
    std::unique_ptr<p::Procedure> proc;
    try {
        proc = p::make_track(inner_condition, track, 0);
    } catch (const std::exception& e) {
        return fmt::format("its procedure could not be built: {}", e.what());
    }
    p::TrackState state;
    for (std::size_t i = 0; i < trials.size(); ++i) {
        Trial& t = *trials[i];
        const std::optional<p::Proposal> next = proc->next();
        if (!next) return fmt::format("the procedure finished before trial {} of the session", t.trial_index);
        if (std::abs(next->level - t.level) > 1e-9 * std::max(1.0, std::abs(t.level)))
            return fmt::format(
                "trial {} of the session was logged at level {} where the protocol's procedure "
                "proposes {}",
                t.trial_index, t.level, next->level);
        p::Response r{};
        const std::optional<p::Response> answer = p::parse_response_word(t.response);
        if (c.task == p::Task::TwoAfc) {
            if ((answer != p::Response::Left && answer != p::Response::Right) || !t.test_on_left)
                return fmt::format("trial {} has no side answer (response \"{}\")", t.trial_index, t.response);
            r = p::ForcedChoice::inner_response(*answer, *t.test_on_left, c.choice);
        } else if (answer == p::Response::Yes || answer == p::Response::No) {
            r = *answer;
        } else {
            return fmt::format("trial {} has no yes/no answer (response \"{}\")", t.trial_index, t.response);
        }
        try {
            proc->record(r);
        } catch (const std::exception& e) {
            return fmt::format("trial {} could not be replayed: {}", t.trial_index, e.what());
        }
        // The procedure's own state after the answer (procedures.h TrackState):
        // a posterior per trial; the reversals are marked once the track is done.
        state = type.track_state(*proc);
        if (type.track_estimate == p::TrackEstimate::Posterior) {
            t.posterior_mean = state.mean;
            t.posterior_sd = state.sd;
            t.posterior_lower = state.lower;
            t.posterior_upper = state.upper;
        }
    }
    if (type.track_estimate == p::TrackEstimate::Reversals) {
        for (Trial* t : trials) t->reversal = false;
        for (const std::size_t r : state.reversal_trials)
            if (r < trials.size()) trials[r]->reversal = true;
    }
    return {};
}

}  // namespace atonlab::analysis::detail
