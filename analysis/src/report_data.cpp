// summary.json and fits.csv (report.h); the HTML page is report_html.cpp.
#include <fmt/format.h>

#include <cstdio>
#include <fstream>
#include <map>

#include "atonlab/analysis/display_losses.h"
#include "atonlab/analysis/report.h"
#include "atonlab/common/atomic_file.h"
#include "atonlab/store/json.h"
#include "csv.h"

namespace atonlab::analysis {

namespace {

using Json = nlohmann::ordered_json;  // summary.json keeps its members in the order written here

/// An absent value is null (as a non-finite one is: store::dump_json).
Json or_null(const std::optional<double>& v) {
    return v ? Json(*v) : Json(nullptr);
}

/// [lower, upper], or null without an interval.
Json interval(const std::optional<Interval>& ci) {
    return ci ? Json::array({ci->lower, ci->upper}) : Json(nullptr);
}

Json headline_json(const HeadlineEstimate& h) {
    Json j;
    j["value"] = or_null(h.value);
    j["ci"] = interval(h.ci);
    j["method"] = h.method;
    j["reliable"] = h.reliable;
    j["reason"] = h.reason;
    return j;
}

Json bootstrap_json(const PsychometricBootstrap& b) {
    Json j;
    j["requested"] = b.n_requested;
    j["done"] = b.n_done;
    j["failed"] = b.n_failed;
    j["at_bound"] = b.n_at_bound;
    j["reliable"] = b.reliable;
    j["reason"] = b.reason;
    j["ci"] = Json{{"threshold", interval(b.threshold)},
                   {"slope", interval(b.slope)},
                   {"width", interval(b.width)},
                   {"lambda", interval(b.lambda)}};
    j["goodness_of_fit"] = Json{{"deviance", b.goodness_of_fit.deviance},
                                {"dof", b.goodness_of_fit.dof},
                                {"p_value", or_null(b.goodness_of_fit.p_value)},
                                {"p_value_chi2", or_null(b.goodness_of_fit.p_value_chi2)}};
    return j;
}

Json fit_json(const GroupResult& g, const ConditionInfo& c) {
    if (!g.fit) return nullptr;
    const PsychometricFit& f = *g.fit;
    Json j;
    j["family"] = std::string(to_string(g.family));
    j["family_note"] = g.family_note;
    j["guess_rate"] = c.guess_rate;
    j["target_p"] = c.target_p;
    j["threshold_proportion"] = or_null(g.threshold_proportion);
    j["reliable"] = f.reliable;
    j["reason"] = f.reason;
    j["n_trials"] = f.n_trials;
    j["n_levels"] = f.n_levels;
    j["n_free"] = f.n_free;
    j["converged"] = f.converged;
    j["at_bound"] = f.at_bound;
    if (f.estimate) {
        const PsychometricEstimate& e = *f.estimate;
        j["alpha"] = e.params.alpha;
        j["beta"] = e.params.beta;
        j["gamma"] = e.params.gamma;
        j["lambda"] = e.params.lambda;
        j["threshold"] = or_null(e.threshold);
        j["psi_at_threshold"] = or_null(e.psi_at_threshold);
        j["slope"] = or_null(e.slope);
        j["width"] = or_null(e.width);
        j["log_likelihood"] = e.log_likelihood;
        j["deviance"] = e.deviance;
    } else {
        for (const char* k : {"alpha", "beta", "gamma", "lambda", "threshold", "psi_at_threshold", "slope", "width",
                              "log_likelihood", "deviance"})
            j[k] = nullptr;
    }
    j["bootstrap"] = g.bootstrap ? bootstrap_json(*g.bootstrap) : Json(nullptr);
    return j;
}

Json track_json(const TrackResult& t) {
    Json j;
    j["session"] = t.session;
    j["observer"] = t.observer;
    j["track"] = t.track;
    j["procedure"] = t.procedure;
    j["n_trials"] = static_cast<int>(t.levels.size());
    j["reversals"] = nullptr;
    if (t.reversals) {
        const ReversalSummary& r = *t.reversals;
        j["reversals"] = Json{
            {"n_reversals", r.n_reversals}, {"n_used", r.n_used},     {"mean", or_null(r.mean)}, {"sd", or_null(r.sd)},
            {"sem", or_null(r.sem)},        {"reliable", r.reliable}, {"reason", r.reason}};
    }
    j["posterior"] = nullptr;
    if (t.posterior) {
        const PosteriorSummary& q = *t.posterior;
        j["posterior"] = Json{{"mean", or_null(q.mean)},
                          {"sd", or_null(q.sd)},
                          {"interval", interval(q.interval)},
                          {"interval_is_normal_approximation", q.interval_is_normal_approximation},
                          {"reliable", q.reliable},
                          {"reason", q.reason}};
    }
    return j;
}

/// The light a session's display took from each condition's judged lights (display_losses.h): the
/// largest share lost at white and to display.out_of_gamut, and whether it is over the limit the
/// session ran under; null where the record does not hold it.
Json display_losses_json(const SessionInfo& s) {
    const auto loss = [](const std::optional<LightLoss>& l) {
        return l ? Json{{"share", l->share}, {"role", l->role}, {"light", l->light}, {"level", l->level}}
                 : Json(nullptr);
    };
    const auto flag = [](const std::optional<bool>& b) { return b ? Json(*b) : Json(nullptr); };
    Json out = Json::array();
    for (const DisplayLoss& c : s.display_losses)
        out.push_back(Json{{"condition", c.condition},
                           {"white_loss", loss(c.white)},
                           {"white_loss_over_warning", flag(white_over_warning(s, c))},
                           {"gamut_loss", loss(c.gamut)},
                           {"out_of_gamut", c.gamut ? Json(c.out_of_gamut) : Json(nullptr)},
                           {"gamut_loss_over_limit", flag(gamut_over_limit(s, c))},
                           {"warnings", c.warnings}});
    return out;
}

/// A judged light as the stored scene gives it, with the glare it was drawn with.
Json light_json(const LightLook& l, const std::string& glare) {
    const auto text = [](const std::string& v) { return v.empty() ? Json(nullptr) : Json(v); };
    return Json{
        {"colour", text(l.colour)}, {"rhythm", text(l.rhythm)}, {"spectrum", text(l.spectrum)}, {"glare", text(glare)}};
}

Json group_json(const GroupResult& g, const ConditionInfo& c) {
    Json j;
    j["observer"] = g.observer;
    j["n_trials"] = g.n_trials;
    j["n_scored"] = g.n_scored;
    j["n_sessions"] = g.n_sessions;
    j["headline"] = headline_json(g.headline);
    j["counts"] = Json::array();
    for (const LevelCounts& k : g.counts)
        j["counts"].push_back(Json{{"level", k.level}, {"n", k.n_trials}, {"yes", k.n_yes}});
    j["psychometric"] = fit_json(g, c);
    j["tracks"] = Json::array();
    for (const TrackResult& t : g.tracks) j["tracks"].push_back(track_json(t));
    j["reversal_mean"] = or_null(g.reversal_mean);
    j["posterior_mean"] = or_null(g.posterior_mean);
    j["adjustment"] = nullptr;
    if (g.matches) {
        const AdjustmentSummary& m = *g.matches;
        j["adjustment"] = Json{{"n", m.n},
                               {"mean", or_null(m.mean_log10_ratio)},
                               {"median", or_null(m.median_log10_ratio)},
                               {"sd", or_null(m.sd_log10_ratio)},
                               {"mean_ci", interval(m.mean_ci)},
                               {"median_ci", interval(m.median_ci)},
                               {"reliable", m.reliable},
                               {"reason", m.reason}};
    }
    j["match_ratio"] = nullptr;
    if (g.match_ratio) {
        const MatchRatio& m = *g.match_ratio;
        j["match_ratio"] = Json{{"label", c.difference_label()}, {"log10_ratio", or_null(m.value)},
                                {"ci", interval(m.ci)},          {"method", m.method},
                                {"reliable", m.reliable},        {"reason", m.reason}};
    }
    return j;
}

std::string opt(const std::optional<double>& v) {
    return v ? detail::number_text(*v) : std::string();
}

/// A setting's TOML value as a typed CSV field: a number, true / false, or text.
std::string setting_csv(const std::string& toml_value) {
    const SettingValue v = setting_value(toml_value);
    if (v.number) return detail::number_text(*v.number);
    if (v.boolean) return *v.boolean ? "true" : "false";
    return csv_field(v.text);
}

/// The same as a JSON value.
Json setting_json(const std::string& toml_value) {
    const SettingValue v = setting_value(toml_value);
    if (v.number) return *v.number;
    if (v.boolean) return *v.boolean;
    if (v.numbers) return *v.numbers;  // a position as an array of numbers
    return v.text;
}

/// One display calibration the sessions used, with its checks over time.
Json calibration_json(const CalibrationInfo& c) {
    Json checks = Json::array();
    for (const DriftPoint& p : c.drift)
        checks.push_back(Json{{"check_id", p.check_id},
                              {"checked_at", p.checked_at},
                              {"passed", p.passed},
                              {"peak_cd_m2", p.peak_cd_m2},
                              {"peak_predicted_cd_m2", p.peak_predicted_cd_m2},
                              {"black_cd_m2", p.black_cd_m2},
                              {"black_predicted_cd_m2", p.black_predicted_cd_m2},
                              {"gamma_measured", p.gamma_measured},
                              {"gamma_predicted", p.gamma_predicted},
                              {"worst_error_percent", p.worst_error_percent},
                              {"worst_patch", p.worst_patch},
                              {"tol_peak_percent", p.tol_peak_percent},
                              {"tol_black_cd_m2", p.tol_black_cd_m2},
                              {"tol_gamma", p.tol_gamma},
                              {"tol_luminance_percent", p.tol_luminance_percent}});
    return Json{{"source", c.source},
                {"id", c.id},
                {"display", c.display_name},
                {"width_px", c.width_px},
                {"height_px", c.height_px},
                {"width_m", c.width_m},
                {"height_m", c.height_m},
                {"viewing_distance_m", c.viewing_distance_m},
                {"how", c.how},
                {"measured_at", c.measured_at},
                {"readings", static_cast<int>(c.readings.size())},
                {"fit_json", c.fit_json},
                {"checks", std::move(checks)}};
}

}  // namespace

const std::vector<std::string>& fits_csv_columns() {
    static const std::vector<std::string> cols{"condition",
                                               "observer",
                                               "analysis",
                                               "track",
                                               "task",
                                               "procedure",
                                               "level_unit",
                                               "n_trials",
                                               "n_levels",
                                               "estimate",
                                               "ci_lower",
                                               "ci_upper",
                                               "sd",
                                               "family",
                                               "alpha",
                                               "beta",
                                               "gamma",
                                               "lambda",
                                               "slope",
                                               "slope_ci_lower",
                                               "slope_ci_upper",
                                               "width",
                                               "width_ci_lower",
                                               "width_ci_upper",
                                               "lambda_ci_lower",
                                               "lambda_ci_upper",
                                               "deviance",
                                               "dof",
                                               "gof_p",
                                               "bootstrap_n",
                                               "reliable",
                                               "reason",
                                               "method",
                                               "adaptation_cd_m2",
                                               "tone_operator",
                                               "glare_test",
                                               "glare_reference",
                                               "test_intensity_cd",
                                               "test_colour",
                                               "test_rhythm",
                                               "test_spectrum",
                                               "reference_colour",
                                               "reference_rhythm",
                                               "reference_spectrum",
                                               "difference"};
    return cols;
}

void write_summary_json(const std::filesystem::path& file, const ReportContext& ctx) {
    const StudyResults& r = *ctx.results;
    const Dataset& d = *ctx.data;
    Json j;
    j["format"] = "atonlab-analysis-summary";
    j["format_version"] = 1;
    // First, so a reader cannot miss it: inputs that were damaged and salvaged.
    j["damaged_inputs"] = Json::array();
    for (const DamagedInput& x : d.damaged)
        j["damaged_inputs"].push_back(Json{{"file", x.file},
                                           {"problem", x.problem},
                                           {"schema_altered", x.schema_altered},
                                           {"sessions_read", static_cast<std::int64_t>(x.sessions_read)},
                                           {"trials_read", static_cast<std::int64_t>(x.trials_read)},
                                           {"sessions_unreadable", x.sessions_unreadable},
                                           {"trials_unreadable", x.trials_unreadable},
                                           {"skipped_rows", x.skipped_rows}});
    j["software_version"] = ctx.software_version;
    j["inputs"] = d.sources;
    j["options"] = Json{{"bootstrap", r.options.bootstrap},
                        {"seed", std::to_string(r.options.seed)},
                        {"family", std::string(to_string(r.options.family))},
                        {"ci_level", r.options.ci_level},
                        {"last_reversals", r.options.last_reversals}};
    j["factor_columns"] = r.factor_columns;
    j["observers"] = r.observers;
    j["sessions"] = Json::array();
    for (const SessionInfo& s : d.sessions) {
        Json o{{"session", s.key},
               {"source", s.source},
               {"id", s.id},
               {"observer", s.observer},
               {"protocol_name", s.protocol_name},
               {"protocol_sha256", s.protocol_sha256},
               {"scene_name", s.scene_sha256.empty() ? Json(nullptr) : Json(s.scene_name)},
               {"scene_sha256", s.scene_sha256.empty() ? Json(nullptr) : Json(s.scene_sha256)},
               {"software_version", s.software_version},
               {"seed", std::to_string(s.seed)},
               {"status", s.status},
               {"started_at", s.started_at},
               {"ended_at", s.ended_at},
               {"trials", s.trial_count}};
        if (s.displayable) {
            o["displayable"] = *s.displayable;
            o["allowed_undisplayable"] = s.allowed_undisplayable;
            o["undisplayable_conditions"] = s.undisplayable;
            o["display_thresholds"] = Json{{"white_loss_warning_share", or_null(s.white_loss_warning_share)},
                                           {"max_out_of_gamut_loss", or_null(s.max_out_of_gamut_loss)}};
            o["display_losses"] = display_losses_json(s);
        }
        o["presentation_margin"] = s.presentation_margin ? Json(*s.presentation_margin) : Json(nullptr);
        o["stops"] = s.stops;
        o["stop_reason"] = s.stop_reason.empty() ? Json(nullptr) : Json(s.stop_reason);
        j["sessions"].push_back(std::move(o));
    }
    j["conditions"] = Json::array();
    for (const ConditionInfo& c : r.conditions) {
        Json o{{"condition", c.condition},
               {"task", std::string(to_string(c.task))},
               {"procedure", c.procedure},
               {"level_key", c.level_key},
               {"level_scale", c.level_scale},
               {"level_unit", c.level_unit()},
               {"level_on", c.level_on},
               {"adaptation_cd_m2", or_null(c.adaptation_cd_m2)},
               {"tone_operator", c.tone_operator},
               {"glare_test", c.glare_test},
               {"glare_reference", c.glare_reference},
               {"test_intensity_cd", or_null(c.test_intensity_cd)},
               {"test_light", light_json(c.test_look, c.glare_test)},
               {"reference_light", light_json(c.reference_look, c.glare_reference)},
               {"lights_known", c.lights_known()},
               {"differences", c.differences},
               {"difference", c.difference_label()},
               {"guess_rate", c.guess_rate},
               {"target_p", c.target_p},
               {"n_trials", c.n_trials}};
        // The design's other factors (StudyResults::factor_columns), typed; null where the condition has none.
        Json factors = Json::object();
        for (const std::string& key : r.factor_columns) {
            const auto it = c.settings.find(key);
            factors[key] = it == c.settings.end() ? Json(nullptr) : setting_json(it->second);
        }
        o["factors"] = std::move(factors);
        o["mixed"] = c.mixed;
        o["groups"] = Json::array();
        for (const GroupResult& g : r.groups)
            if (g.condition == c.condition) o["groups"].push_back(group_json(g, c));
        j["conditions"].push_back(std::move(o));
    }
    j["paired_comparisons"] = Json::array();
    for (const PairedResult& p : r.paired) {
        const PairedComparison& c = p.comparison;
        j["paired_comparisons"].push_back(Json{{"condition_a", p.condition_a},
                                               {"condition_b", p.condition_b},
                                               {"factor", p.factor},
                                               {"observers", p.observers},
                                               {"n", c.n},
                                               {"mean_difference", or_null(c.mean_difference)},
                                               {"sd_difference", or_null(c.sd_difference)},
                                               {"ci", interval(c.ci)},
                                               {"t", or_null(c.t)},
                                               {"dof", c.dof},
                                               {"p_value", or_null(c.p_value)},
                                               {"t_ci", interval(c.t_ci)},
                                               {"reliable", c.reliable},
                                               {"reason", c.reason}});
    }
    j["frame_timing"] = Json::array();
    for (const SessionTiming& s : r.timing)
        j["frame_timing"].push_back(Json{{"session", s.session},
                                         {"observer", s.observer},
                                         {"trials", s.n_trials},
                                         {"dropped_frames", s.dropped_frames},
                                         {"trials_with_drops", s.trials_with_drops},
                                         {"missed_deadlines", s.missed_deadlines}});
    j["calibrations"] = Json::array();
    for (const CalibrationInfo& c : d.calibrations) j["calibrations"].push_back(calibration_json(c));
    j["figures"] = Json::array();
    if (ctx.plots)
        for (const Figure& f : ctx.plots->figures)
            j["figures"].push_back(Json{{"id", f.id},
                                        {"kind", f.kind},
                                        {"condition", f.condition},
                                        {"title", f.title},
                                        {"caption", f.caption},
                                        {"png", f.png.generic_string()},
                                        {"svg", f.svg.generic_string()}});
    j["snapshots"] = Json::array();
    for (const SnapshotImage& s : ctx.snapshots)
        j["snapshots"].push_back(
            Json{{"condition", s.condition}, {"session", s.session}, {"png", s.png.generic_string()}});
    Json warnings = r.warnings;
    if (ctx.plots)
        for (const std::string& w : ctx.plots->problems) warnings.push_back(w);
    for (const std::string& w : ctx.problems) warnings.push_back(w);
    j["warnings"] = std::move(warnings);
    files::write_file_atomically(file, store::dump_json(j, 2) + "\n");
}

void write_fits_csv(const std::filesystem::path& file, const StudyResults& r) {
    std::string out;
    // The fixed columns, then one per factor of the design (StudyResults::factor_columns).
    std::vector<std::string> cols = fits_csv_columns();
    cols.insert(cols.end(), r.factor_columns.begin(), r.factor_columns.end());
    for (std::size_t i = 0; i < cols.size(); ++i) out += (i ? "," : "") + csv_field(cols[i]);
    out += "\n";
    for (const GroupResult& g : r.groups) {
        const ConditionInfo* c = r.condition(g.condition);
        if (!c) continue;
        auto row = [&](std::string analysis, std::string track, std::vector<std::pair<std::string, std::string>> kv) {
            std::map<std::string, std::string> m(kv.begin(), kv.end());
            m["condition"] = csv_field(g.condition);
            m["observer"] = csv_field(g.observer);
            m["analysis"] = analysis;
            m["track"] = csv_field(track);
            m["task"] = std::string(to_string(c->task));
            m["procedure"] = csv_field(c->procedure);
            m["level_unit"] = csv_field(c->level_unit());
            m["adaptation_cd_m2"] = opt(c->adaptation_cd_m2);
            m["tone_operator"] = csv_field(c->tone_operator);
            m["glare_test"] = csv_field(c->glare_test);
            m["glare_reference"] = csv_field(c->glare_reference);
            m["test_intensity_cd"] = opt(c->test_intensity_cd);
            m["test_colour"] = csv_field(c->test_look.colour);
            m["test_rhythm"] = csv_field(c->test_look.rhythm);
            m["test_spectrum"] = csv_field(c->test_look.spectrum);
            m["reference_colour"] = csv_field(c->reference_look.colour);
            m["reference_rhythm"] = csv_field(c->reference_look.rhythm);
            m["reference_spectrum"] = csv_field(c->reference_look.spectrum);
            m["difference"] = g.match_ratio ? csv_field(c->difference_label()) : std::string();
            for (const std::string& key : r.factor_columns) {
                const auto it = c->settings.find(key);
                m[key] = it == c->settings.end() ? std::string() : setting_csv(it->second);
            }
            for (std::size_t i = 0; i < cols.size(); ++i) out += (i ? "," : "") + m[cols[i]];
            out += "\n";
        };
        auto yn = [](bool b) { return std::string(b ? "1" : "0"); };
        const HeadlineEstimate& h = g.headline;
        row("headline", "",
            {{"n_trials", std::to_string(g.n_scored)},
             {"estimate", opt(h.value)},
             {"ci_lower", h.ci ? opt(h.ci->lower) : ""},
             {"ci_upper", h.ci ? opt(h.ci->upper) : ""},
             {"reliable", yn(h.reliable)},
             {"reason", csv_field(h.reason)},
             {"method", csv_field(h.method)}});
        if (g.fit) {
            const PsychometricFit& f = *g.fit;
            std::vector<std::pair<std::string, std::string>> kv{
                {"n_trials", std::to_string(f.n_trials)},
                {"n_levels", std::to_string(f.n_levels)},
                {"family", std::string(to_string(g.family))},
                {"reliable", yn(f.reliable && (!g.bootstrap || g.bootstrap->reliable))},
                {"reason", csv_field(!f.reason.empty()                       ? f.reason
                                     : g.bootstrap && !g.bootstrap->reliable ? "bootstrap: " + g.bootstrap->reason
                                                                             : std::string())},
                {"method", csv_field(fmt::format("maximum likelihood, threshold at F = {}",
                                                 g.threshold_proportion ? detail::number_text(*g.threshold_proportion)
                                                                        : std::string("0.5")))}};
            if (f.estimate) {
                const PsychometricEstimate& e = *f.estimate;
                kv.insert(kv.end(), {{"estimate", opt(e.threshold)},
                                     {"alpha", opt(e.params.alpha)},
                                     {"beta", opt(e.params.beta)},
                                     {"gamma", opt(e.params.gamma)},
                                     {"lambda", opt(e.params.lambda)},
                                     {"slope", opt(e.slope)},
                                     {"width", opt(e.width)},
                                     {"deviance", opt(e.deviance)}});
            }
            if (g.bootstrap) {
                const PsychometricBootstrap& b = *g.bootstrap;
                auto ci = [&](const char* lo, const char* hi, const std::optional<Interval>& v) {
                    if (!v) return;
                    kv.emplace_back(lo, opt(v->lower));
                    kv.emplace_back(hi, opt(v->upper));
                };
                ci("ci_lower", "ci_upper", b.threshold);
                ci("slope_ci_lower", "slope_ci_upper", b.slope);
                ci("width_ci_lower", "width_ci_upper", b.width);
                ci("lambda_ci_lower", "lambda_ci_upper", b.lambda);
                kv.emplace_back("dof", std::to_string(b.goodness_of_fit.dof));
                kv.emplace_back("gof_p", opt(b.goodness_of_fit.p_value));
                kv.emplace_back("bootstrap_n", std::to_string(b.n_done - b.n_failed));
            }
            row("psychometric", "", kv);
        }
        for (const TrackResult& t : g.tracks) {
            if (t.reversals) {
                const ReversalSummary& s = *t.reversals;
                row("staircase-track", t.session + " " + t.track,
                    {{"n_trials", std::to_string(s.n_trials)},
                     {"estimate", opt(s.mean)},
                     {"sd", opt(s.sd)},
                     {"reliable", yn(s.reliable)},
                     {"reason", csv_field(s.reason)},
                     {"method",
                      csv_field(fmt::format("mean of the last {} of {} reversals", s.n_used, s.n_reversals))}});
            }
            if (t.posterior) {
                const PosteriorSummary& q = *t.posterior;
                row("posterior-track", t.session + " " + t.track,
                    {{"n_trials", std::to_string(t.levels.size())},
                     {"estimate", opt(q.mean)},
                     {"sd", opt(q.sd)},
                     {"ci_lower", q.interval ? opt(q.interval->lower) : ""},
                     {"ci_upper", q.interval ? opt(q.interval->upper) : ""},
                     {"reliable", yn(q.reliable)},
                     {"reason", csv_field(q.reason)},
                     {"method", q.interval_is_normal_approximation ? "QUEST posterior mean, mean +- z sd"
                                                                   : "QUEST posterior mean, 2.5%..97.5% quantiles"}});
            }
        }
        if (g.matches) {
            const AdjustmentSummary& m = *g.matches;
            row("adjustment", "",
                {{"n_trials", std::to_string(m.n)},
                 {"estimate", opt(m.mean_log10_ratio)},
                 {"sd", opt(m.sd_log10_ratio)},
                 {"ci_lower", m.mean_ci ? opt(m.mean_ci->lower) : ""},
                 {"ci_upper", m.mean_ci ? opt(m.mean_ci->upper) : ""},
                 {"reliable", yn(m.reliable)},
                 {"reason", csv_field(m.reason)},
                 {"method", "mean matched level, bootstrap over matches"}});
        }
        if (g.match_ratio) {
            const MatchRatio& m = *g.match_ratio;
            row("match-ratio", "",
                {{"n_trials", std::to_string(g.n_scored)},
                 {"estimate", opt(m.value)},
                 {"ci_lower", m.ci ? opt(m.ci->lower) : ""},
                 {"ci_upper", m.ci ? opt(m.ci->upper) : ""},
                 {"reliable", yn(m.reliable)},
                 {"reason", csv_field(m.reason)},
                 {"method", csv_field(m.method)}});
        }
    }
    files::write_file_atomically(file, out);
}

std::vector<std::filesystem::path> write_report(const std::filesystem::path& out_dir, const ReportContext& ctx) {
    std::vector<std::filesystem::path> files{out_dir / "trials.csv", out_dir / "fits.csv", out_dir / "summary.json",
                                             out_dir / "report.html"};
    write_trials_csv(files[0], *ctx.data);
    write_fits_csv(files[1], *ctx.results);
    write_summary_json(files[2], ctx);
    write_report_html(files[3], ctx);
    return files;
}

}  // namespace atonlab::analysis
