// What protocols and analysis know of the method of adjustment (procedures.h;
// the state machine: adjustment.h). Analysis summarises its confirmed matches
// (the task "adjust"), not tracks.
#include <fmt/format.h>

#include "protocol_schema.h"
#include "type_helpers.h"

namespace atonlab::protocols {

namespace {

constexpr std::string_view kKeys[] = {"kind",      "start_min", "start_max", "coarse_step",
                                      "fine_step", "min_level", "max_level", "n_trials"};

ProcedureParams read(const detail::ProcedureReader& r, std::vector<double>&) {
    AdjustmentParams p;
    for (const std::string_view key : {"start_min", "start_max"})
        if (!r.has(key))
            r.fail(key, fmt::format("the {} procedure has no '{}', which is required.", Adjustment::kName, key));
    r.number("start_min", p.start_min);
    r.number("start_max", p.start_max);
    r.number("coarse_step", p.coarse_step);
    r.number("fine_step", p.fine_step);
    r.number("min_level", p.min_level);
    r.number("max_level", p.max_level);
    r.integer("n_trials", p.n_trials);
    r.require_stop_rule({"n_trials"}, "n_trials (the matches to make)");
    return p;
}

const AdjustmentParams& of(const ProcedureParams& params) {
    return std::get<AdjustmentParams>(params);
}

}  // namespace

const ProcedureType& Adjustment::type() {
    static const ProcedureType t{
        .kind = ProcedureKind::Adjustment,
        .name = kName,
        .keys = kKeys,
        .read = read,
        .adjusts = true,
        .needs_log10 = {},
        .make = [](const ProcedureParams& p, std::optional<double>, std::uint64_t seed) -> std::unique_ptr<Procedure> {
            return std::make_unique<Adjustment>(of(p), seed);
        },
        .target_p_yes = [](const ProcedureParams&) -> std::optional<double> { return 0.5; },  // a match
        .level_bounds = [](const ProcedureParams& p) { return detail::given_bounds(of(p)); },
        .search_range = [](const ProcedureParams& params, std::span<const double>) -> std::pair<double, double> {
            const AdjustmentParams& p = of(params);
            return {p.min_level.value_or(p.start_min - 2.0), p.max_level.value_or(p.start_max + 2.0)};
        },
        .max_trials_per_track = [](const ProcedureParams&) -> std::optional<std::size_t> { return std::nullopt; },
        .bound_names = {"min_level", "max_level"},
        .track_estimate = TrackEstimate::None,
        .guess_rate = detail::task_guess_rate,
        .describe = [](const ProcedureParams& p) { return fmt::format("an adjustment of {} matches", of(p).n_trials); },
        .track_state = detail::no_track_state,
    };
    return t;
}

}  // namespace atonlab::protocols
