// What protocols and analysis know of the weighted up/down staircase
// (procedures.h; the state machine: weighted_staircase.h, Kaernbach 1991).
#include <fmt/format.h>

#include "protocol_schema.h"
#include "type_helpers.h"

namespace atonlab::protocols {

namespace {

constexpr std::string_view kKeys[] = {
    "kind",     "start",      "target",    "step_sizes", "step_type",         "n_reversals",
    "n_trials", "max_trials", "min_level", "max_level",  "estimate_reversals"};

ProcedureParams read(const detail::ProcedureReader& r, std::vector<double>& track_starts) {
    WeightedStaircaseParams p;
    r.starts("start", p.start, track_starts);
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
    return p;
}

const WeightedStaircaseParams& of(const ProcedureParams& params) {
    return std::get<WeightedStaircaseParams>(params);
}

std::unique_ptr<Procedure> make(const ProcedureParams& params, std::optional<double> start, std::uint64_t seed) {
    WeightedStaircaseParams p = of(params);
    if (start) p.start = *start;
    return std::make_unique<WeightedStaircase>(p, seed);
}

}  // namespace

const ProcedureType& WeightedStaircase::type() {
    static const ProcedureType t{
        .kind = ProcedureKind::WeightedStaircase,
        .name = kName,
        .keys = kKeys,
        .read = read,
        .adjusts = false,
        .needs_log10 = {},
        .make = make,
        .target_p_yes = [](const ProcedureParams& p) -> std::optional<double> {
            return of(p).target;
        },  // Kaernbach 1991
        .level_bounds = [](const ProcedureParams& p) { return detail::given_bounds(of(p)); },
        .search_range =
            [](const ProcedureParams& p, std::span<const double> starts) {
                return detail::starts_search_range(of(p), of(p).start, starts);
            },
        .max_trials_per_track = [](const ProcedureParams& p) { return detail::max_trials_cap(of(p)); },
        .bound_names = {"min_level", "max_level"},
        .track_estimate = TrackEstimate::Reversals,
        .guess_rate = detail::task_guess_rate,
        .describe =
            [](const ProcedureParams& p) { return fmt::format("a weighted staircase with target {}", of(p).target); },
        .track_state = detail::reversal_state,
    };
    return t;
}

}  // namespace atonlab::protocols
