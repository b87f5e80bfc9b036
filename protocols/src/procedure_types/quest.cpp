// What protocols and analysis know of QUEST (procedures.h; the state machine:
// quest.h, Watson & Pelli 1983). Its keys are QuestCreate's arguments and the
// stop rule (docs/protocol-file.md).
#include <fmt/format.h>

#include "protocol_schema.h"
#include "type_helpers.h"

namespace atonlab::protocols {

namespace {

constexpr std::string_view kKeys[] = {
    "kind",  "t_guess", "t_guess_sd",     "p_threshold", "beta",          "delta",     "gamma",     "grain",
    "range", "method",  "quantile_order", "n_trials",    "stop_interval", "min_level", "max_level", "first_at_guess"};

ProcedureParams read(const detail::ProcedureReader& r, std::vector<double>& track_starts) {
    QuestParams p;
    r.starts("t_guess", p.t_guess, track_starts);
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
    return p;
}

const QuestParams& of(const ProcedureParams& params) {
    return std::get<QuestParams>(params);
}

std::unique_ptr<Procedure> make(const ProcedureParams& params, std::optional<double> start, std::uint64_t seed) {
    QuestParams p = of(params);
    if (start) p.t_guess = *start;
    return std::make_unique<Quest>(std::move(p), seed);
}

/// QuestDemo's final estimate (mean +- sd) and the 95% credible interval by
/// QuestQuantile (analysis: thresholds.h summarize_posterior reads them back).
TrackState posterior_state(const Procedure& p) {
    TrackState s;
    if (const auto* quest = dynamic_cast<const Quest*>(&p)) {
        s.mean = quest->mean();
        s.sd = quest->sd();
        s.lower = quest->quantile(0.025);
        s.upper = quest->quantile(0.975);
    }
    return s;
}

}  // namespace

const ProcedureType& Quest::type() {
    static const ProcedureType t{
        .kind = ProcedureKind::Quest,
        .name = kName,
        .keys = kKeys,
        .read = read,
        .adjusts = false,
        .needs_log10 = "QUEST works in log10 units (its Weibull is a function of log intensity)",
        .make = make,
        .target_p_yes = [](const ProcedureParams& p) -> std::optional<double> { return of(p).p_threshold; },
        .level_bounds = [](const ProcedureParams& p) { return detail::given_bounds(of(p)); },
        .search_range =
            [](const ProcedureParams& p, std::span<const double> starts) {
                return detail::starts_search_range(of(p), of(p).t_guess, starts);
            },
        .max_trials_per_track = [](const ProcedureParams& p) -> std::optional<std::size_t> {
            return static_cast<std::size_t>(of(p).n_trials);
        },
        .bound_names = {"min_level", "max_level"},
        .track_estimate = TrackEstimate::Posterior,
        .guess_rate = [](const ProcedureParams& p) -> std::optional<double> { return of(p).gamma; },
        .describe =
            [](const ProcedureParams& p) { return fmt::format("QUEST with p_threshold {}", of(p).p_threshold); },
        .track_state = posterior_state,
    };
    return t;
}

}  // namespace atonlab::protocols
