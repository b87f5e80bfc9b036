// summary.json and fits.csv (report.h); the HTML page is report_html.cpp.
#include <fmt/format.h>

#include <cstdio>
#include <fstream>
#include <map>

#include "atonlab/analysis/report.h"
#include "atonlab/common/atomic_file.h"
#include "csv.h"
#include "json_writer.h"

namespace atonlab::analysis {

namespace {

using detail::JsonWriter;

void interval(JsonWriter& j, std::string_view key, const std::optional<Interval>& ci) {
    j.key(key);
    if (!ci) {
        j.null();
        return;
    }
    j.begin_array().value(ci->lower).value(ci->upper).end_array();
}

void write_headline(JsonWriter& j, const HeadlineEstimate& h) {
    j.key("headline").begin_object();
    j.field("value", h.value);
    interval(j, "ci", h.ci);
    j.field("method", h.method).field("reliable", h.reliable).field("reason", h.reason);
    j.end_object();
}

void write_fit(JsonWriter& j, const GroupResult& g, const ConditionInfo& c) {
    j.key("psychometric");
    if (!g.fit) {
        j.null();
        return;
    }
    const PsychometricFit& f = *g.fit;
    j.begin_object();
    j.field("family", std::string(to_string(g.family))).field("family_note", g.family_note);
    j.field("guess_rate", c.guess_rate).field("target_p", c.target_p);
    j.field("threshold_proportion", g.threshold_proportion);
    j.field("reliable", f.reliable).field("reason", f.reason);
    j.field("n_trials", f.n_trials).field("n_levels", f.n_levels).field("n_free", f.n_free);
    j.field("converged", f.converged).field("at_bound", f.at_bound);
    if (f.estimate) {
        const PsychometricEstimate& e = *f.estimate;
        j.field("alpha", e.params.alpha).field("beta", e.params.beta);
        j.field("gamma", e.params.gamma).field("lambda", e.params.lambda);
        j.field("threshold", e.threshold).field("psi_at_threshold", e.psi_at_threshold);
        j.field("slope", e.slope).field("width", e.width);
        j.field("log_likelihood", e.log_likelihood).field("deviance", e.deviance);
    } else {
        for (const char* k : {"alpha", "beta", "gamma", "lambda", "threshold", "psi_at_threshold", "slope", "width",
                              "log_likelihood", "deviance"})
            j.field_null(k);
    }
    j.key("bootstrap");
    if (!g.bootstrap) {
        j.null();
    } else {
        const PsychometricBootstrap& b = *g.bootstrap;
        j.begin_object();
        j.field("requested", b.n_requested).field("done", b.n_done).field("failed", b.n_failed);
        j.field("at_bound", b.n_at_bound).field("reliable", b.reliable).field("reason", b.reason);
        j.key("ci").begin_object();
        interval(j, "threshold", b.threshold);
        interval(j, "slope", b.slope);
        interval(j, "width", b.width);
        interval(j, "lambda", b.lambda);
        j.end_object();
        j.key("goodness_of_fit").begin_object();
        j.field("deviance", b.goodness_of_fit.deviance).field("dof", b.goodness_of_fit.dof);
        j.field("p_value", b.goodness_of_fit.p_value).field("p_value_chi2", b.goodness_of_fit.p_value_chi2);
        j.end_object();
        j.end_object();
    }
    j.end_object();
}

void write_group(JsonWriter& j, const GroupResult& g, const ConditionInfo& c) {
    j.begin_object();
    j.field("observer", g.observer).field("n_trials", g.n_trials).field("n_scored", g.n_scored);
    j.field("n_sessions", g.n_sessions);
    write_headline(j, g.headline);
    j.key("counts").begin_array();
    for (const LevelCounts& k : g.counts)
        j.begin_object().field("level", k.level).field("n", k.n_trials).field("yes", k.n_yes).end_object();
    j.end_array();
    write_fit(j, g, c);
    j.key("tracks").begin_array();
    for (const TrackResult& t : g.tracks) {
        j.begin_object();
        j.field("session", t.session).field("observer", t.observer).field("track", t.track);
        j.field("procedure", t.procedure).field("n_trials", static_cast<int>(t.levels.size()));
        j.key("reversals");
        if (t.reversals) {
            const ReversalSummary& r = *t.reversals;
            j.begin_object().field("n_reversals", r.n_reversals).field("n_used", r.n_used);
            j.field("mean", r.mean).field("sd", r.sd).field("sem", r.sem);
            j.field("reliable", r.reliable).field("reason", r.reason).end_object();
        } else {
            j.null();
        }
        j.key("quest");
        if (t.quest) {
            const QuestSummary& q = *t.quest;
            j.begin_object().field("mean", q.mean).field("sd", q.sd);
            interval(j, "interval", q.interval);
            j.field("interval_is_normal_approximation", q.interval_is_normal_approximation);
            j.field("reliable", q.reliable).field("reason", q.reason).end_object();
        } else {
            j.null();
        }
        j.end_object();
    }
    j.end_array();
    j.field("reversal_mean", g.reversal_mean).field("quest_mean", g.quest_mean);
    j.key("adjustment");
    if (g.matches) {
        const AdjustmentSummary& m = *g.matches;
        j.begin_object().field("n", m.n).field("mean", m.mean_log10_ratio).field("median", m.median_log10_ratio);
        j.field("sd", m.sd_log10_ratio);
        interval(j, "mean_ci", m.mean_ci);
        interval(j, "median_ci", m.median_ci);
        j.field("reliable", m.reliable).field("reason", m.reason).end_object();
    } else {
        j.null();
    }
    j.key("match_ratio");
    if (g.match_ratio) {
        const MatchRatio& m = *g.match_ratio;
        j.begin_object().field("log10_ratio", m.value);
        interval(j, "ci", m.ci);
        j.field("method", m.method).field("reliable", m.reliable).field("reason", m.reason).end_object();
    } else {
        j.null();
    }
    j.end_object();
}

std::string opt(const std::optional<double>& v) {
    return v ? detail::number_text(*v) : std::string();
}

/// A setting's TOML value as a typed CSV field: a number, true / false, or text.
std::string setting_csv(const std::string& toml_value) {
    const SettingValue v = setting_value(toml_value);
    if (v.number) return detail::number_text(*v.number);
    if (v.boolean) return *v.boolean ? "true" : "false";
    return detail::csv_field(v.text);
}

/// The same as a JSON member.
void setting_json(JsonWriter& j, const std::string& key, const std::string& toml_value) {
    const SettingValue v = setting_value(toml_value);
    if (v.number)
        j.field(key, *v.number);
    else if (v.boolean)
        j.field(key, *v.boolean);
    else
        j.field(key, v.text);
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
                                               "test_intensity_cd"};
    return cols;
}

void write_summary_json(const std::filesystem::path& file, const ReportContext& ctx) {
    const StudyResults& r = *ctx.results;
    const Dataset& d = *ctx.data;
    JsonWriter j;
    j.begin_object();
    j.field("format", "atonlab-analysis-summary").field("format_version", 1);
    // First, so a reader cannot miss it: inputs that were damaged and salvaged.
    j.key("damaged_inputs").begin_array();
    for (const DamagedInput& x : d.damaged) {
        j.begin_object().field("file", x.file).field("problem", x.problem);
        j.field("sessions_read", static_cast<std::int64_t>(x.sessions_read));
        j.field("trials_read", static_cast<std::int64_t>(x.trials_read));
        j.field("sessions_unreadable", x.sessions_unreadable).field("trials_unreadable", x.trials_unreadable);
        j.end_object();
    }
    j.end_array();
    j.field("software_version", ctx.software_version);
    j.key("inputs").begin_array();
    for (const std::string& s : d.sources) j.value(s);
    j.end_array();
    j.key("options").begin_object();
    j.field("bootstrap", r.options.bootstrap).field("seed", std::to_string(r.options.seed));
    j.field("family", std::string(to_string(r.options.family))).field("ci_level", r.options.ci_level);
    j.field("last_reversals", r.options.last_reversals).end_object();
    j.key("factor_columns").begin_array();
    for (const std::string& k : r.factor_columns) j.value(k);
    j.end_array();
    j.key("observers").begin_array();
    for (const std::string& o : r.observers) j.value(o);
    j.end_array();
    j.key("sessions").begin_array();
    for (const SessionInfo& s : d.sessions) {
        j.begin_object().field("session", s.key).field("source", s.source).field("id", s.id);
        j.field("observer", s.observer).field("protocol_name", s.protocol_name);
        j.field("protocol_sha256", s.protocol_sha256).field("software_version", s.software_version);
        j.field("seed", std::to_string(s.seed)).field("status", s.status).field("started_at", s.started_at);
        j.field("ended_at", s.ended_at).field("trials", s.trial_count);
        if (s.displayable) {
            j.field("displayable", *s.displayable).field("allowed_undisplayable", s.allowed_undisplayable);
            j.key("undisplayable_conditions").begin_array();
            for (const std::string& c : s.undisplayable) j.value(c);
            j.end_array();
        }
        j.end_object();
    }
    j.end_array();
    j.key("conditions").begin_array();
    for (const ConditionInfo& c : r.conditions) {
        j.begin_object();
        j.field("condition", c.condition).field("task", std::string(to_string(c.task)));
        j.field("procedure", c.procedure).field("level_key", c.level_key).field("level_scale", c.level_scale);
        j.field("level_unit", c.level_unit()).field("level_on", c.level_on);
        j.field("adaptation_cd_m2", c.adaptation_cd_m2).field("tone_operator", c.tone_operator);
        j.field("glare_test", c.glare_test).field("glare_reference", c.glare_reference);
        j.field("test_intensity_cd", c.test_intensity_cd).field("guess_rate", c.guess_rate);
        j.field("target_p", c.target_p).field("n_trials", c.n_trials);
        // The design's other factors (StudyResults::factor_columns), typed; null where the condition has none.
        j.key("factors").begin_object();
        for (const std::string& key : r.factor_columns) {
            const auto it = c.settings.find(key);
            if (it == c.settings.end())
                j.field_null(key);
            else
                setting_json(j, key, it->second);
        }
        j.end_object();
        j.key("mixed").begin_array();
        for (const std::string& m : c.mixed) j.value(m);
        j.end_array();
        j.key("groups").begin_array();
        for (const GroupResult& g : r.groups)
            if (g.condition == c.condition) write_group(j, g, c);
        j.end_array();
        j.end_object();
    }
    j.end_array();
    j.key("paired_comparisons").begin_array();
    for (const PairedResult& p : r.paired) {
        const PairedComparison& c = p.comparison;
        j.begin_object().field("condition_a", p.condition_a).field("condition_b", p.condition_b);
        j.field("factor", p.factor);
        j.key("observers").begin_array();
        for (const std::string& o : p.observers) j.value(o);
        j.end_array();
        j.field("n", c.n).field("mean_difference", c.mean_difference).field("sd_difference", c.sd_difference);
        interval(j, "ci", c.ci);
        j.field("t", c.t).field("dof", c.dof).field("p_value", c.p_value);
        interval(j, "t_ci", c.t_ci);
        j.field("reliable", c.reliable).field("reason", c.reason).end_object();
    }
    j.end_array();
    j.key("frame_timing").begin_array();
    for (const SessionTiming& s : r.timing) {
        j.begin_object().field("session", s.session).field("observer", s.observer).field("trials", s.n_trials);
        j.field("dropped_frames", s.dropped_frames).field("trials_with_drops", s.trials_with_drops);
        j.field("missed_deadlines", s.missed_deadlines).end_object();
    }
    j.end_array();
    j.key("calibrations").begin_array();
    for (const CalibrationInfo& c : d.calibrations) {
        j.begin_object().field("source", c.source).field("id", c.id).field("display", c.display_name);
        j.field("width_px", c.width_px).field("height_px", c.height_px).field("width_m", c.width_m);
        j.field("height_m", c.height_m).field("viewing_distance_m", c.viewing_distance_m);
        j.field("how", c.how).field("measured_at", c.measured_at);
        j.field("readings", static_cast<int>(c.readings.size())).field("fit_json", c.fit_json);
        j.key("checks").begin_array();
        for (const DriftPoint& p : c.drift) {
            j.begin_object().field("check_id", p.check_id).field("checked_at", p.checked_at);
            j.field("passed", p.passed).field("peak_cd_m2", p.peak_cd_m2);
            j.field("peak_predicted_cd_m2", p.peak_predicted_cd_m2).field("black_cd_m2", p.black_cd_m2);
            j.field("black_predicted_cd_m2", p.black_predicted_cd_m2).field("gamma_measured", p.gamma_measured);
            j.field("gamma_predicted", p.gamma_predicted).field("worst_error_percent", p.worst_error_percent);
            j.field("worst_patch", p.worst_patch).field("tol_peak_percent", p.tol_peak_percent);
            j.field("tol_black_cd_m2", p.tol_black_cd_m2).field("tol_gamma", p.tol_gamma);
            j.field("tol_luminance_percent", p.tol_luminance_percent).end_object();
        }
        j.end_array().end_object();
    }
    j.end_array();
    j.key("figures").begin_array();
    if (ctx.plots) {
        for (const Figure& f : ctx.plots->figures) {
            j.begin_object().field("id", f.id).field("kind", f.kind).field("condition", f.condition);
            j.field("title", f.title).field("caption", f.caption).field("png", f.png.generic_string());
            j.field("svg", f.svg.generic_string()).end_object();
        }
    }
    j.end_array();
    j.key("snapshots").begin_array();
    for (const SnapshotImage& s : ctx.snapshots)
        j.begin_object()
            .field("condition", s.condition)
            .field("session", s.session)
            .field("png", s.png.generic_string())
            .end_object();
    j.end_array();
    j.key("warnings").begin_array();
    for (const std::string& w : r.warnings) j.value(w);
    if (ctx.plots)
        for (const std::string& w : ctx.plots->problems) j.value(w);
    for (const std::string& w : ctx.problems) j.value(w);
    j.end_array();
    j.end_object();
    files::write_file_atomically(file, j.text() + "\n");
}

void write_fits_csv(const std::filesystem::path& file, const StudyResults& r) {
    std::string out;
    // The fixed columns, then one per factor of the design (StudyResults::factor_columns).
    std::vector<std::string> cols = fits_csv_columns();
    cols.insert(cols.end(), r.factor_columns.begin(), r.factor_columns.end());
    for (std::size_t i = 0; i < cols.size(); ++i) out += (i ? "," : "") + detail::csv_field(cols[i]);
    out += "\n";
    using detail::csv_field;
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
            if (t.quest) {
                const QuestSummary& q = *t.quest;
                row("quest-track", t.session + " " + t.track,
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
