// What protocols and analysis know of the method of constant stimuli
// (procedures.h; the state machine: constant_stimuli.h). Analysis fits the
// psychometric function to all its trials; it has no tracks to follow.
#include <fmt/format.h>

#include <algorithm>

#include "protocol_schema.h"
#include "type_helpers.h"

namespace atonlab::protocols {

namespace {

constexpr std::string_view kKeys[] = {"kind", "levels", "repetitions", "order", "criterion"};

ProcedureParams read(const detail::ProcedureReader& r, std::vector<double>&) {
    ConstantStimuliParams p;
    auto levels = r.numbers("levels", false);
    if (!levels)
        r.fail("levels", fmt::format("the {} procedure has no 'levels', which is required.", ConstantStimuli::kName));
    p.levels = std::move(*levels);
    r.integer("repetitions", p.repetitions);
    if (auto s = r.string("order")) p.order = parse_constant_order(*s);
    r.number("criterion", p.criterion);
    return p;
}

const ConstantStimuliParams& of(const ProcedureParams& params) {
    return std::get<ConstantStimuliParams>(params);
}

/// Its lowest and highest level.
std::vector<double> level_bounds(const ProcedureParams& params) {
    const ConstantStimuliParams& p = of(params);
    if (p.levels.empty()) return {};
    const auto [lo, hi] = std::minmax_element(p.levels.begin(), p.levels.end());
    return {*lo, *hi};
}

std::pair<double, double> search_range(const ProcedureParams& params, std::span<const double>) {
    const ConstantStimuliParams& p = of(params);
    if (p.levels.empty()) return {-1.0, 1.0};
    const auto [lo, hi] = std::minmax_element(p.levels.begin(), p.levels.end());
    return {*lo - 1.0, *hi + 1.0};
}

}  // namespace

const ProcedureType& ConstantStimuli::type() {
    static const ProcedureType t{
        .kind = ProcedureKind::ConstantStimuli,
        .name = kName,
        .keys = kKeys,
        .read = read,
        .adjusts = false,
        .needs_log10 = {},
        .make = [](const ProcedureParams& p, std::optional<double>, std::uint64_t seed) -> std::unique_ptr<Procedure> {
            return std::make_unique<ConstantStimuli>(of(p), seed);
        },
        .target_p_yes = [](const ProcedureParams& p) -> std::optional<double> { return of(p).criterion; },
        .level_bounds = level_bounds,
        .search_range = search_range,
        .max_trials_per_track = [](const ProcedureParams& params) -> std::optional<std::size_t> {
            const ConstantStimuliParams& p = of(params);
            return p.levels.size() * static_cast<std::size_t>(p.repetitions);
        },
        .bound_names = {"the lowest of its levels", "the highest of its levels"},
        .track_estimate = TrackEstimate::None,
        .guess_rate = detail::task_guess_rate,
        .describe =
            [](const ProcedureParams& p) {
                return fmt::format("constant stimuli at {} levels with criterion {}", of(p).levels.size(),
                                   of(p).criterion);
            },
        .track_state = detail::no_track_state,
    };
    return t;
}

}  // namespace atonlab::protocols
