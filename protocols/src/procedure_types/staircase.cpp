// What protocols and analysis know of the up/down staircase (procedures.h;
// the state machine: staircase.h). Its keys are PsychoPy StairHandler's
// arguments (docs/protocol-file.md).
#include <fmt/format.h>

#include <cmath>

#include "protocol_schema.h"
#include "type_helpers.h"

namespace atonlab::protocols {

namespace {

constexpr std::string_view kKeys[] = {
    "kind",        "start",    "step_sizes", "step_type", "n_up",      "n_down",        "apply_initial_rule",
    "n_reversals", "n_trials", "max_trials", "min_level", "max_level", "up_step_ratio", "estimate_reversals"};

ProcedureParams read(const detail::ProcedureReader& r, std::vector<double>& track_starts) {
    StaircaseParams p;
    r.starts("start", p.start, track_starts);
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
    return p;
}

const StaircaseParams& of(const ProcedureParams& params) {
    return std::get<StaircaseParams>(params);
}

std::unique_ptr<Procedure> make(const ProcedureParams& params, std::optional<double> start, std::uint64_t seed) {
    StaircaseParams p = of(params);
    if (start) p.start = *start;
    return std::make_unique<Staircase>(std::move(p), seed);
}

std::optional<double> target_p_yes(const ProcedureParams& params) {
    const StaircaseParams& p = of(params);
    if (p.up_step_ratio != 1.0) return std::nullopt;
    // Levitt 1971: 1-up/n-down converges on p^n = 0.5, n-up/1-down on (1 - p)^n = 0.5.
    if (p.n_up == 1) return std::pow(0.5, 1.0 / static_cast<double>(p.n_down));
    if (p.n_down == 1) return 1.0 - std::pow(0.5, 1.0 / static_cast<double>(p.n_up));
    return std::nullopt;
}

std::string describe(const ProcedureParams& params) {
    const StaircaseParams& p = of(params);
    return fmt::format("a {}-up/{}-down staircase with up_step_ratio {}", p.n_up, p.n_down, p.up_step_ratio);
}

}  // namespace

const ProcedureType& Staircase::type() {
    static const ProcedureType t{
        .kind = ProcedureKind::Staircase,
        .name = kName,
        .keys = kKeys,
        .read = read,
        .adjusts = false,
        .needs_log10 = {},
        .make = make,
        .target_p_yes = target_p_yes,
        .level_bounds = [](const ProcedureParams& p) { return detail::given_bounds(of(p)); },
        .search_range =
            [](const ProcedureParams& p, std::span<const double> starts) {
                return detail::starts_search_range(of(p), of(p).start, starts);
            },
        .max_trials_per_track = [](const ProcedureParams& p) { return detail::max_trials_cap(of(p)); },
        .bound_names = {"min_level", "max_level"},
        .track_estimate = TrackEstimate::Reversals,
        .guess_rate = detail::task_guess_rate,
        .describe = describe,
        .track_state = detail::reversal_state,
    };
    return t;
}

}  // namespace atonlab::protocols
