// A condition's procedure table, merged over [defaults], its block and the
// condition itself, and read into a ProcedureSpec (protocol_schema.h).
#include <fmt/format.h>

#include <set>

#include "protocol_schema.h"

namespace atonlab::protocols::detail {

KeyList keys_of(ProcedureKind k) {
    switch (k) {
        case ProcedureKind::Staircase:
            return kStaircaseKeys;
        case ProcedureKind::WeightedStaircase:
            return kWeightedKeys;
        case ProcedureKind::Quest:
            return kQuestKeys;
        case ProcedureKind::Adjustment:
            return kAdjustmentKeys;
        case ProcedureKind::ConstantStimuli:
            return kConstantKeys;
    }
    return {};
}

const std::vector<std::string_view>& all_procedure_keys() {
    static const std::vector<std::string_view> all = [] {
        std::set<std::string_view> s;
        for (auto list : {KeyList(kStaircaseKeys), KeyList(kWeightedKeys), KeyList(kQuestKeys),
                          KeyList(kAdjustmentKeys), KeyList(kConstantKeys)})
            s.insert(list.begin(), list.end());
        return std::vector<std::string_view>(s.begin(), s.end());
    }();
    return all;
}

ProcedureSpec read_procedure(const ProcedureReader& r) {
    ProcedureSpec spec;
    spec.kind = *r.kind();
    switch (spec.kind) {
        case ProcedureKind::Staircase: {
            StaircaseParams p;
            r.starts("start", p.start, spec.track_starts);
            if (auto v = r.numbers("step_sizes", true)) p.step_sizes = *v;
            if (auto s = r.string("step_type")) p.step_type = parse_step_type(*s);
            r.integer("n_up", p.n_up);
            r.integer("n_down", p.n_down);
            r.boolean("apply_initial_rule", p.apply_initial_rule);
            r.integer("n_reversals", p.n_reversals);
            r.integer("n_trials", p.n_trials);
            r.integer("max_trials", p.max_trials);
            r.number("min_level", p.min_level);
            r.number("max_level", p.max_level);
            r.number("up_step_ratio", p.up_step_ratio);
            r.integer("estimate_reversals", p.estimate_reversals);
            r.require_stop_rule({"n_reversals", "n_trials", "max_trials"}, "n_reversals, n_trials or max_trials");
            spec.params = std::move(p);
            break;
        }
        case ProcedureKind::WeightedStaircase: {
            WeightedStaircaseParams p;
            r.starts("start", p.start, spec.track_starts);
            r.number("target", p.target);
            if (auto v = r.numbers("step_sizes", true)) p.step_sizes = *v;
            if (auto s = r.string("step_type")) p.step_type = parse_step_type(*s);
            r.integer("n_reversals", p.n_reversals);
            r.integer("n_trials", p.n_trials);
            r.integer("max_trials", p.max_trials);
            r.number("min_level", p.min_level);
            r.number("max_level", p.max_level);
            r.integer("estimate_reversals", p.estimate_reversals);
            r.require_stop_rule({"n_reversals", "n_trials", "max_trials"}, "n_reversals, n_trials or max_trials");
            spec.params = std::move(p);
            break;
        }
        case ProcedureKind::Quest: {
            QuestParams p;
            r.starts("t_guess", p.t_guess, spec.track_starts);
            r.number("t_guess_sd", p.t_guess_sd);
            r.number("p_threshold", p.p_threshold);
            r.number("beta", p.beta);
            r.number("delta", p.delta);
            r.number("gamma", p.gamma);
            r.number("grain", p.grain);
            r.number("range", p.range);
            if (auto s = r.string("method")) p.method = parse_quest_method(*s);
            r.number("quantile_order", p.quantile_order);
            r.integer("n_trials", p.n_trials);
            r.number("stop_interval", p.stop_interval);
            r.number("min_level", p.min_level);
            r.number("max_level", p.max_level);
            r.boolean("first_at_guess", p.first_at_guess);
            r.require_stop_rule({"n_trials"}, "n_trials (and, if you like, stop_interval)");
            spec.params = std::move(p);
            break;
        }
        case ProcedureKind::Adjustment: {
            AdjustmentParams p;
            if (!r.has("start_min"))
                r.fail("start_min", "the adjustment procedure has no 'start_min', which is required.");
            if (!r.has("start_max"))
                r.fail("start_max", "the adjustment procedure has no 'start_max', which is required.");
            r.number("start_min", p.start_min);
            r.number("start_max", p.start_max);
            r.number("coarse_step", p.coarse_step);
            r.number("fine_step", p.fine_step);
            r.number("min_level", p.min_level);
            r.number("max_level", p.max_level);
            r.integer("n_trials", p.n_trials);
            r.require_stop_rule({"n_trials"}, "n_trials (the matches to make)");
            spec.params = std::move(p);
            break;
        }
        case ProcedureKind::ConstantStimuli: {
            ConstantStimuliParams p;
            auto levels = r.numbers("levels", false);
            if (!levels) r.fail("levels", "the constant-stimuli procedure has no 'levels', which is required.");
            p.levels = std::move(*levels);
            r.integer("repetitions", p.repetitions);
            if (auto s = r.string("order")) p.order = parse_constant_order(*s);
            r.number("criterion", p.criterion);
            spec.params = std::move(p);
            break;
        }
    }
    return spec;
}

}  // namespace atonlab::protocols::detail
