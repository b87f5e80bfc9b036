// report.html (report.h): one self-contained page. Styles are inline, the
// figures are embedded as base64 PNG (with a relative link to each SVG next
// to the report), and nothing is loaded from anywhere else: the page reads
// the same offline, from a USB stick or an e-mail attachment.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "atonlab/analysis/display_losses.h"
#include "atonlab/analysis/report.h"
#include "atonlab/common/atomic_file.h"
#include "atonlab/common/input_text.h"
#include "csv.h"
#include "html_parts.h"

namespace atonlab::analysis {

using detail::esc;
using detail::figure_html;

namespace {

std::string f3(const std::optional<double>& v) {
    return v ? fmt::format("{:.3f}", *v) : std::string("&ndash;");
}

std::string g3(const std::optional<double>& v) {
    return v ? fmt::format("{:.3g}", *v) : std::string("&ndash;");
}

std::string ci_text(const std::optional<Interval>& ci) {
    return ci ? fmt::format("[{:.3f}, {:.3f}]", ci->lower, ci->upper) : std::string("&ndash;");
}

/// Footnotes of one table: a reason longer than kInlineReason characters is
/// numbered in its cell and written out in full under the table, so that one
/// long sentence does not widen the whole table.
class Footnotes {
public:
    static constexpr std::size_t kInlineReason = 48;

    /// `reason` itself when short, else a numbered reference to it.
    std::string cite(const std::string& reason) {
        if (reason.size() <= kInlineReason) return esc(reason);
        ++next_;
        notes_ += fmt::format("<li id=\"note-{0}\" value=\"{0}\">{1}</li>\n", next_, esc(reason));
        return fmt::format("see note <a href=\"#note-{0}\">{0}</a>", next_);
    }
    /// The notes cited since the last flush, as a list ("" when none).
    std::string flush() {
        if (notes_.empty()) return {};
        std::string h = "<ol class=\"notes\">\n" + notes_ + "</ol>\n";
        notes_.clear();
        return h;
    }

private:
    int next_ = 0;
    std::string notes_;
};

std::string yes_no(bool reliable, const std::string& reason, Footnotes& notes) {
    if (reliable) return "<span class=\"ok\">yes</span>";
    return "<span class=\"bad\">no</span>" + (reason.empty() ? std::string() : ": " + notes.cite(reason));
}

/// "12.3 (12.1 ± 5%)": a measured value, the calibration's prediction and the tolerance.
std::string drift_cell(double measured, double predicted, double tolerance, const char* unit) {
    auto v = [](double x) { return std::isfinite(x) ? fmt::format("{:.4g}", x) : std::string("&ndash;"); };
    return fmt::format("{} ({} &plusmn; {}{})", v(measured), v(predicted), v(tolerance), unit);
}

/// Each display's calibration checks over time, once per display and file (calibration_drift.h).
std::string drift_html(const Dataset& d) {
    std::string h;
    std::set<std::pair<std::string, std::string>> shown;
    for (const CalibrationInfo& c : d.calibrations) {
        if (c.drift.empty() || !shown.insert({c.source, c.display_name}).second) continue;
        h += fmt::format(
            "<h3>Checks of display {} over time</h3>\n<p>Every <code>atonlab calibrate check</code> of the display "
            "that {} holds (a session stores the latest check of the calibration it used): measured (predicted "
            "&plusmn; tolerance).</p>\n",
            esc(c.display_name), esc(c.source));
        h += "<table>\n<tr><th>checked</th><th>calibration</th><th>result</th><th>peak cd/m²</th>"
             "<th>black cd/m²</th><th>effective gamma</th><th>worst grey error %</th></tr>\n";
        for (const DriftPoint& p : c.drift)
            h += fmt::format(
                "<tr><td>{}</td><td class=\"num\">{}</td><td>{}</td><td class=\"num\">{}</td>"
                "<td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{} {} (&le; {})</td></tr>\n",
                esc(p.checked_at), p.calibration_id,
                p.passed ? std::string("<span class=\"ok\">passed</span>") : "<span class=\"bad\">failed</span>",
                drift_cell(p.peak_cd_m2, p.peak_predicted_cd_m2, p.tol_peak_percent, "%"),
                drift_cell(p.black_cd_m2, p.black_predicted_cd_m2, p.tol_black_cd_m2, ""),
                drift_cell(p.gamma_measured, p.gamma_predicted, p.tol_gamma, ""),
                std::isfinite(p.worst_error_percent) ? fmt::format("{:.2f}", p.worst_error_percent) : "&ndash;",
                esc(p.worst_patch), p.tol_luminance_percent);
        h += "</table>\n";
    }
    return h;
}

/// A JSON value's leaves as (path, cell) rows in document order, for the
/// calibration's parameter table: objects give "a.b", arrays "a[0]"; strings
/// unquoted, numbers to 6 significant digits (summary.json keeps them whole).
void flatten_json(const nlohmann::ordered_json& j, const std::string& path,
                  std::vector<std::pair<std::string, std::string>>& out) {
    if (j.is_object()) {
        for (const auto& [key, value] : j.items()) flatten_json(value, path.empty() ? key : path + "." + key, out);
    } else if (j.is_array()) {
        for (std::size_t n = 0; n < j.size(); ++n) flatten_json(j[n], fmt::format("{}[{}]", path, n), out);
    } else if (j.is_string()) {
        out.emplace_back(path, esc(j.get<std::string>()));
    } else if (j.is_number()) {
        out.emplace_back(path, fmt::format("{:.6g}", j.get<double>()));
    } else {
        out.emplace_back(path, esc(j.dump()));  // true, false, null
    }
}

/// A calibration's fit_json (valid: the store's CHECK has seen to that) as rows; none when it does not parse.
std::vector<std::pair<std::string, std::string>> fit_json_rows(const std::string& fit_json) {
    std::vector<std::pair<std::string, std::string>> rows;
    const auto j = nlohmann::ordered_json::parse(fit_json, nullptr, /*allow_exceptions=*/false);
    if (!j.is_discarded()) flatten_json(j, "", rows);
    return rows;
}

/// A judged light in a table cell: "red, Fl(1) 4s, –, glare wave-optics".
std::string light_cell(const LightLook& l, const std::string& glare) {
    const std::string g = "glare " + (glare.empty() ? std::string("(scene default)") : glare);
    if (l.colour.empty()) return esc(g);
    return esc(fmt::format("{}, {}, ", l.colour, l.rhythm)) + (l.spectrum.empty() ? "&ndash;" : esc(l.spectrum)) +
           ", " + esc(g);
}

/// A sentence naming the condition's two lights and what differs between them.
std::string lights_sentence(const ConditionInfo& c) {
    if (c.test_look.colour.empty())
        return " The lights' colour, rhythm and spectrum are not known: the study file does not hold the scene "
               "(or the CSV does not give them).";
    const auto one = [](const LightLook& l) {
        return fmt::format("{}, rhythm {}, spectrum {}", l.colour, l.rhythm,
                           l.spectrum.empty() ? std::string("not given (spd)") : l.spectrum);
    };
    std::string out = " The test light: " + esc(one(c.test_look));
    if (c.reference_look.colour.empty()) return out + ".";
    out += "; the reference light: " + esc(one(c.reference_look)) + ".";
    if (c.differences.empty()) return out + " They differ in nothing but intensity (and position).";
    std::string list;
    for (std::size_t i = 0; i < c.differences.size(); ++i)
        list += (i == 0 ? "" : i + 1 == c.differences.size() ? " and " : ", ") + c.differences[i];
    return out + " They differ in " + esc(list) + ": log10(match / test) is labelled <i>" + esc(c.difference_label()) +
           "</i>.";
}

/// The summary table: one row per condition.
std::string summary_html(const StudyResults& r, const std::map<std::string, std::string>& slugs, Footnotes& notes) {
    std::string h;
    h += "<h2>Summary</h2>\n";
    h += "<p>One row per condition (pooled over observers when there are several). <i>Estimate</i>: the PSE or "
         "threshold of the fitted psychometric function (2AFC, yes-no), or the mean match (adjustment). "
         "<i>log10(match / test)</i>: log10(matched reference intensity / test intensity), named under its value "
         "by what it measures: the effect of glare where glare is the only difference between the test and the "
         "reference light (colour, rhythm, spectrum and frame settings the same), else test &minus; reference. "
         "Each light: colour, rhythm, spectrum (the scene's <code>spd</code>; &ndash; none given), glare.</p>\n";
    // Each number over its interval in one cell, so that the table fits 1280 px.
    h += "<div class=\"table-wrap\"><table>\n<tr><th>condition</th><th>task / procedure</th>"
         "<th>adaptation (cd/m²)</th><th>tone mapper</th><th>test / reference light</th><th>test (cd)</th>"
         "<th>observer</th><th>trials</th><th>estimate [interval]</th><th>unit</th><th>log10(match / test) "
         "[interval]</th>"
         "<th>reliable</th></tr>\n";
    for (const ConditionInfo& c : r.conditions) {
        const GroupResult* g = r.main_group(c.condition);
        if (!g) continue;
        const HeadlineEstimate& e = g->headline;
        std::string enh = "&ndash;";
        if (g->match_ratio && g->match_ratio->value)
            enh = f3(g->match_ratio->value) + "<br>" + ci_text(g->match_ratio->ci) + "<br><i>" +
                  esc(c.difference_label()) + "</i>";
        h += fmt::format(
            "<tr><td><a href=\"#c-{}\">{}</a></td><td>{} / {}</td><td class=\"num\">{}</td><td>{}</td><td>{}<br>{}</td>"
            "<td class=\"num\">{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}<br>{}</td>"
            "<td>{}</td><td class=\"num\">{}</td><td>{}</td></tr>\n",
            esc(slugs.at(c.condition)), esc(c.condition), esc(std::string(to_string(c.task))),
            esc(c.procedure.empty() ? "(not stated)" : c.procedure), g3(c.adaptation_cd_m2), esc(c.tone_operator),
            light_cell(c.test_look, c.glare_test), light_cell(c.reference_look, c.glare_reference),
            g3(c.test_intensity_cd), esc(g->observer), g->n_scored, f3(e.value), ci_text(e.ci), esc(c.level_unit()),
            enh, yes_no(e.reliable, e.reason, notes));
    }
    h += "</table></div>\n" + notes.flush();
    return h;
}

/// A condition's heading, its settings and the table of its fits, one row per observer.
std::string condition_fits_html(const StudyResults& r, const ConditionInfo& c,
                                const std::map<std::string, std::string>& slugs, Footnotes& notes) {
    std::string h;
    h += fmt::format("<h2 id=\"c-{}\">Condition {}</h2>\n", esc(slugs.at(c.condition)), esc(c.condition));
    h += fmt::format(
        "<p>Task {}, procedure {}; the level sets <code>{}</code> ({}, on the {}); adaptation {} cd/m², tone "
        "mapper {}, glare {} on the test and {} on the reference, test intensity {} cd.{} Outcome counted: {} "
        "(guess rate {}, target P {}). {} trials.</p>\n",
        esc(std::string(to_string(c.task))), esc(c.procedure.empty() ? "(not stated)" : c.procedure), esc(c.level_key),
        esc(c.level_unit()), esc(c.level_on), g3(c.adaptation_cd_m2),
        esc(c.tone_operator.empty() ? "(scene default)" : c.tone_operator),
        esc(c.glare_test.empty() ? "(scene default)" : c.glare_test),
        esc(c.glare_reference.empty() ? "(scene default)" : c.glare_reference), g3(c.test_intensity_cd),
        lights_sentence(c),
        c.task == protocols::Task::YesNo    ? "yes"
        : c.task == protocols::Task::Adjust ? "the confirmed match"
        : c.level_on == "test"              ? "chose the test"
                                            : "chose the reference",
        c.guess_rate, c.target_p, c.n_trials);
    if (!r.factor_columns.empty()) {
        // The design's other factors (fits.csv's factor columns), as the protocol set them.
        std::string list;
        for (const std::string& key : r.factor_columns) {
            const auto it = c.settings.find(key);
            const SettingValue v = setting_value(it == c.settings.end() ? std::string() : it->second);
            const std::string shown = it == c.settings.end() ? std::string("(not set)")
                                      : v.number             ? fmt::format("{:.6g}", *v.number)
                                      : v.boolean            ? std::string(*v.boolean ? "true" : "false")
                                                             : v.text;
            list += fmt::format("{}<code>{}</code> = {}", list.empty() ? "" : ", ", esc(key), esc(shown));
        }
        h += "<p>Other factors of the design: " + list + ".</p>\n";
    }
    h += "<div "
         "class=\"table-wrap\"><table>\n<tr><th>observer</th><th>trials</th><th>estimate</th><th>interval</"
         "th><th>how</th>"
         "<th>slope [interval]</th><th>width</th><th>lapse λ</th><th>deviance (dof), p</th>"
         "<th>reliable</th></tr>\n";
    for (const GroupResult& g : r.groups) {
        if (g.condition != c.condition) continue;
        std::string slope = "&ndash;", width = "&ndash;", lapse = "&ndash;", gof = "&ndash;";
        if (g.fit && g.fit->estimate) {
            const PsychometricEstimate& e = *g.fit->estimate;
            slope = fmt::format("{:.3g}", e.slope);
            width = fmt::format("{:.3g}", e.width);
            lapse = fmt::format("{:.3f}", e.params.lambda);
            gof = fmt::format("{:.2f}", e.deviance);
            if (g.bootstrap) {
                if (g.bootstrap->slope)
                    slope += fmt::format(" [{:.3g}, {:.3g}]", g.bootstrap->slope->lower, g.bootstrap->slope->upper);
                const GoodnessOfFit& gf = g.bootstrap->goodness_of_fit;
                gof = fmt::format("{:.2f} ({}), {}", gf.deviance, gf.dof, g3(gf.p_value));
            }
        }
        h += fmt::format(
            "<tr><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td>{}</td>"
            "<td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
            "<td>{}</td></tr>\n",
            esc(g.observer), g.n_scored, f3(g.headline.value), ci_text(g.headline.ci), esc(g.headline.method), slope,
            width, lapse, gof, yes_no(g.headline.reliable, g.headline.reason, notes));
    }
    h += "</table></div>\n" + notes.flush();
    return h;
}

/// The procedures' own estimates (staircase reversals, QUEST posteriors, adjustment matches) of a
/// condition, per observer; empty when there are none.
std::string procedure_estimates_html(const StudyResults& r, const ConditionInfo& c, Footnotes& notes) {
    std::string h;
    std::string tracks;
    for (const GroupResult& g : r.groups) {
        if (g.condition != c.condition || (g.observer == kPooled)) continue;
        for (const TrackResult& t : g.tracks) {
            if (t.reversals) {
                const ReversalSummary& s = *t.reversals;
                tracks += fmt::format(
                    "<tr><td>{}</td><td>{}</td><td>staircase</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
                    "<td>mean of the last {} of {} reversals, sd {}</td><td>{}</td><td>{}</td></tr>\n",
                    esc(g.observer), esc(t.session + " " + t.track), t.levels.size(), f3(s.mean), s.n_used,
                    s.n_reversals, g3(s.sd), "&ndash;", yes_no(s.reliable, s.reason, notes));
            }
            if (t.posterior) {
                const PosteriorSummary& q = *t.posterior;
                tracks += fmt::format(
                    "<tr><td>{}</td><td>{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
                    "<td>posterior mean, sd {}</td><td class=\"num\">{}</td><td>{}</td></tr>\n",
                    esc(g.observer), esc(t.session + " " + t.track), esc(t.procedure), t.levels.size(), f3(q.mean),
                    g3(q.sd), ci_text(q.interval), yes_no(q.reliable, q.reason, notes));
            }
        }
        if (g.matches) {
            const AdjustmentSummary& m = *g.matches;
            tracks += fmt::format(
                "<tr><td>{}</td><td>all matches</td><td>adjustment</td><td class=\"num\">{}</td>"
                "<td class=\"num\">{}</td><td>mean match; median {} {}, sd {}</td><td class=\"num\">{}</td>"
                "<td>{}</td></tr>\n",
                esc(g.observer), m.n, f3(m.mean_log10_ratio), f3(m.median_log10_ratio), ci_text(m.median_ci),
                g3(m.sd_log10_ratio), ci_text(m.mean_ci), yes_no(m.reliable, m.reason, notes));
        }
    }
    if (!tracks.empty()) {
        h += "<p>The procedures' own estimates:</p>\n<div "
             "class=\"table-wrap\"><table>\n<tr><th>observer</th><th>track</th><th>procedure</th>"
             "<th>trials</th><th>estimate</th><th>how</th><th>interval</th><th>reliable</th></tr>\n" +
             tracks + "</table></div>\n" + notes.flush();
    }
    return h;
}

/// The paired comparisons across observers; empty when there are none.
std::string paired_html(const StudyResults& r, Footnotes& notes) {
    std::string h;
    if (!r.paired.empty()) {
        h += "<h2>Paired comparisons across observers</h2>\n";
        h += "<p>Conditions that differ in one stimulus parameter, compared within observers: the mean of each "
             "observer's difference A &minus; B of the headline estimates, its bootstrap interval over observers, "
             "and Student's paired t test.</p>\n";
        h += "<div class=\"table-wrap\"><table>\n<tr><th>A</th><th>B</th><th>differ in</th><th>observers</th><th>mean "
             "A &minus; B</th>"
             "<th>interval</th><th>t (dof)</th><th>p</th><th>reliable</th></tr>\n";
        for (const PairedResult& p : r.paired) {
            const PairedComparison& c = p.comparison;
            h += fmt::format(
                "<tr><td>{}</td><td>{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
                "<td class=\"num\">{}</td><td class=\"num\">{} ({})</td><td class=\"num\">{}</td><td>{}</td></tr>\n",
                esc(p.condition_a), esc(p.condition_b), esc(p.factor), c.n, f3(c.mean_difference), ci_text(c.ci),
                g3(c.t), c.dof, g3(c.p_value), yes_no(c.reliable, c.reason, notes));
        }
        h += "</table></div>\n" + notes.flush();
    }
    return h;
}

/// The sessions' table: who, which protocol, and their frame timing.
std::string sessions_html(const Dataset& d, const StudyResults& r, Footnotes& notes) {
    std::string h;
    h += "<h2>Sessions and frame timing</h2>\n<div class=\"table-wrap\"><table>\n<tr><th>session</th>"
         "<th>observer</th><th>answered by</th><th>protocol</th><th>status</th><th>started</th><th>trials</th>"
         "<th>dropped frames</th><th>trials with drops</th><th>missed deadlines</th><th>presentation margin</th>"
         "<th>stopped by the runner</th><th>display check</th></tr>\n";
    for (const SessionInfo& s : d.sessions) {
        const SessionTiming* t = nullptr;
        for (const SessionTiming& x : r.timing)
            if (x.session == s.key) t = &x;
        h += fmt::format(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"num\">{}</td>"
            "<td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
            "<td>{}</td><td>{}</td></tr>\n",
            esc(s.key), esc(s.observer), esc(s.answered_by.empty() ? "(not recorded)" : s.answered_by),
            esc(s.protocol_name), esc(s.status), esc(s.started_at), t ? t->n_trials : 0, t ? t->dropped_frames : 0,
            t ? t->trials_with_drops : 0, t ? t->missed_deadlines : 0,
            s.presentation_margin ? fmt::format("{:.0f} %", *s.presentation_margin * 100.0) : std::string("—"),
            s.stops == 0 ? std::string("no") : esc(fmt::format("{} time(s); last: {}", s.stops, s.stop_text)),
            !s.displayable   ? std::string("not recorded")
            : *s.displayable ? std::string("displayable")
                             : esc(fmt::format("NOT displayable, run with --allow-undisplayable: {}",
                                               fmt::join(s.undisplayable, ", "))));
    }
    h += "</table></div>\n" + notes.flush();
    return h;
}

/// The light each session's display took from each condition's judged lights (display_losses.h):
/// the largest share clipped at white and given up to display.out_of_gamut, against the limits.
std::string display_losses_html(const Dataset& d) {
    const auto limit = [](const std::optional<double>& v) {
        return v ? fmt::format("{:.3g} %", 100.0 * *v) : std::string("not recorded");
    };
    const auto verdict = [](const std::optional<bool>& over) {
        return !over ? std::string() : *over ? std::string(": <span class=\"bad\">over</span>") : std::string();
    };
    std::string rows;
    for (const SessionInfo& s : d.sessions)
        for (const DisplayLoss& c : s.display_losses)
            rows += fmt::format(
                "<tr><td>{}</td><td>{}</td><td>{}{}</td><td class=\"num\">{}</td><td>{}{}</td><td>{}</td>"
                "<td class=\"num\">{}</td></tr>\n",
                esc(s.key), esc(c.condition), esc(loss_text(c.white)), verdict(white_over_warning(s, c)),
                limit(s.white_loss_warning_share), esc(loss_text(c.gamut)), verdict(gamut_over_limit(s, c)),
                c.gamut ? esc(c.out_of_gamut) : std::string("—"), limit(s.max_out_of_gamut_loss));
    if (rows.empty()) return {};
    return "<h3 id=\"display-losses\">Light lost at the display</h3>\n"
           "<p>Per condition, the largest share of a judged light's light (within the observer's window, at either "
           "end of its level range) that its session's display clipped at its white, and that "
           "display.out_of_gamut gave up, as <code>atonlab check</code> computed before the first trial; and the "
           "limits the session ran under: above the warning share a match near that level may lie; above "
           "display.max_out_of_gamut_loss a brightness match (2AFC, adjust) is refused.</p>\n"
           "<div class=\"table-wrap\"><table>\n<tr><th>session</th><th>condition</th>"
           "<th>lost at white</th><th>warned above</th><th>lost to out of gamut</th><th>out_of_gamut</th>"
           "<th>refused above</th></tr>\n" +
           rows + "</table></div>\n";
}

/// The display calibrations: their geometry, the fitted models' parameters, figures and drift.
std::string calibration_html(const Dataset& d, const ReportContext& ctx, const std::filesystem::path& out_dir,
                             Footnotes& notes) {
    std::string h;
    h += "<h2>Display calibration</h2>\n";
    if (d.calibrations.empty()) {
        h += "<p>No calibration is recorded for these sessions (a CSV input has none).</p>\n";
    } else {
        h += "<div class=\"table-wrap\"><table>\n<tr><th>display</th><th>file</th><th>measured</th><th>how</th>"
             "<th>geometry</th><th>readings</th></tr>\n";
        for (const CalibrationInfo& c : d.calibrations) {
            h += fmt::format(
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{} × {} px, {:.3f} × {:.3f} m at {:.3f} m</td>"
                "<td class=\"num\">{}</td></tr>\n",
                esc(c.display_name), esc(c.source), esc(c.measured_at), esc(c.how), c.width_px, c.height_px, c.width_m,
                c.height_m, c.viewing_distance_m, c.readings.size());
        }
        h += "</table></div>\n" + notes.flush();
        // The fitted model's parameters (fit_json, docs/calibration.md), one row each.
        for (const CalibrationInfo& c : d.calibrations) {
            h += fmt::format(
                "<p>Display model of <b>{}</b> (calibration {} of <code>{}</code>; its <code>fit_json</code>):</p>\n",
                esc(c.display_name), c.id, esc(c.source));
            h += "<div class=\"table-wrap\"><table>\n<tr><th>parameter</th><th>value</th></tr>\n";
            for (const auto& [key, cell] : fit_json_rows(c.fit_json))
                h += fmt::format("<tr><td><code>{}</code></td><td class=\"num\">{}</td></tr>\n", esc(key), cell);
            h += "</table></div>\n";
        }
        if (ctx.plots)
            for (const Figure& f : ctx.plots->figures)
                if (f.kind == "calibration") h += figure_html(out_dir, f);
        h += drift_html(d);
        if (ctx.plots)
            for (const Figure& f : ctx.plots->figures)
                if (f.kind == "calibration-drift") h += figure_html(out_dir, f);
    }
    return h;
}

}  // namespace

std::string base64(const std::string& bytes) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    std::size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) |
                           (static_cast<unsigned char>(bytes[i + 1]) << 8) | static_cast<unsigned char>(bytes[i + 2]);
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += table[(v >> 6) & 63];
        out += table[v & 63];
    }
    if (i + 1 == bytes.size()) {
        const unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += "==";
    } else if (i + 2 == bytes.size()) {
        const unsigned v =
            (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8);
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += table[(v >> 6) & 63];
        out += '=';
    }
    return out;
}

void write_report_html(const std::filesystem::path& file, const ReportContext& ctx) {
    const StudyResults& r = *ctx.results;
    const Dataset& d = *ctx.data;
    const std::filesystem::path out_dir = file.parent_path();
    const std::map<std::string, std::string> slugs = condition_slugs(r);  // the anchors, one per condition
    std::map<std::string, std::vector<const Figure*>> by_condition;
    std::map<std::string, const Figure*> by_kind;
    if (ctx.plots) {
        for (const Figure& f : ctx.plots->figures) {
            if (!f.condition.empty())
                by_condition[f.condition].push_back(&f);
            else if (!by_kind.count(f.kind))
                by_kind[f.kind] = &f;
        }
    }
    std::string h;
    Footnotes notes;  // long reasons, numbered under each table
    h += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
    h += "<title>atonlab analysis</title>\n<style>\n" + std::string(detail::kReportStyle) +
         "\n</style>\n</head>\n<body>\n";
    h += "<h1>atonlab analysis</h1>\n";
    // First, so a reader cannot miss it: inputs that were damaged and salvaged.
    for (const DamagedInput& x : d.damaged) {
        h += fmt::format(
            "<div class=\"warn\"><p><b>Damaged input: <code>{}</code></b> was read with <code>--salvage</code>: "
            "{} session(s) and {} trial(s) were read; {} trial row(s) and {} session row(s) could not be read. "
            "{}What is wrong: {}</p>\n",
            esc(x.file), x.sessions_read, x.trials_read, x.trials_unreadable, x.sessions_unreadable,
            x.schema_altered ? "<b>Its schema was altered</b>: its tables are not the ones atonlab made, so its rows "
                               "were held to constraints atonlab did not write. "
                             : "",
            esc(x.problem));
        if (!x.skipped_rows.empty()) {
            h += "<p>Rows left out:</p>\n<ul>\n";
            for (const std::string& row : x.skipped_rows) h += "<li>" + esc(row) + "</li>\n";
            h += "</ul>\n";
        }
        h += "</div>\n";
    }
    h += fmt::format("<p>Made by atonlab {} with <code>{}</code>.</p>\n", esc(ctx.software_version),
                     esc(ctx.command_line));
    h += "<p>Inputs:</p>\n<ul>\n";
    for (const std::string& s : d.sources) h += "<li><code>" + esc(s) + "</code></li>\n";
    h += "</ul>\n";
    h += fmt::format(
        "<p>{} trials of {} observer(s) in {} session(s). Psychometric functions: {} family, binomial maximum "
        "likelihood, guess rate fixed by the task, lapse rate free in [0, 0.06]; {:.0f}% intervals from {} parametric "
        "bootstrap resamples (seed {}). Levels are in each condition's procedure units.</p>\n",
        d.trials.size(), r.observers.size(), d.sessions.size(), to_string(r.options.family), 100.0 * r.options.ci_level,
        r.options.bootstrap, r.options.seed);

    std::vector<std::string> warnings = r.warnings;
    if (ctx.plots) warnings.insert(warnings.end(), ctx.plots->problems.begin(), ctx.plots->problems.end());
    warnings.insert(warnings.end(), ctx.problems.begin(), ctx.problems.end());
    if (!warnings.empty()) {
        h += "<div class=\"warn\"><p><b>Notes and warnings</b></p>\n<ul>\n";
        for (const std::string& w : warnings) h += "<li>" + esc(w) + "</li>\n";
        h += "</ul></div>\n";
    }

    // --- summary table
    h += summary_html(r, slugs, notes);
    for (const char* kind : {"pse", "enhancement"})
        if (by_kind.count(kind)) h += figure_html(out_dir, *by_kind[kind]);

    // --- per condition
    for (const ConditionInfo& c : r.conditions) {
        h += condition_fits_html(r, c, slugs, notes);
        h += procedure_estimates_html(r, c, notes);
        if (const auto it = by_condition.find(c.condition); it != by_condition.end())
            for (const Figure* f : it->second) h += figure_html(out_dir, *f);
        for (const SnapshotImage& s : ctx.snapshots) {
            if (s.condition != c.condition) continue;
            Figure f;
            f.title = "Stimulus: " + c.condition;
            f.caption = s.caption;
            f.png = s.png;
            h += figure_html(out_dir, f);
        }
    }

    // --- paired comparisons
    h += paired_html(r, notes);

    // --- sessions and timing
    h += sessions_html(d, r, notes);
    h += display_losses_html(d);
    if (by_kind.count("timing"))
        h += figure_html(out_dir, *by_kind["timing"]);
    else if (!r.timing.empty() && !has_display_timing(d, r))
        h += "<p>Every session was answered by the model or a scripted observer and dropped no frame: their "
             "frame times are the virtual clock's (headless) or a simulated observer's, not a person's view of a "
             "display, so no timing figure is drawn.</p>\n";

    // --- calibration
    h += calibration_html(d, ctx, out_dir, notes);

    // --- methods and files
    h += "<h2>Methods</h2>\n<ul>\n"
         "<li>Each condition's trials are grouped per observer (sessions pooled), and over observers when there "
         "are several. 2AFC trials count whether the observer chose the stimulus the level is on; yes-no trials "
         "count yes.</li>\n"
         "<li>Psychometric function &Psi;(x) = &gamma; + (1 &minus; &gamma; &minus; &lambda;) F(x) fitted by binomial "
         "maximum likelihood (Wichmann &amp; Hill 2001; the Palamedes conventions). &gamma; is fixed: 0 for "
         "comparisons and yes-no, 0.5 for a 2AFC scored correct / incorrect, QUEST's own &gamma; for QUEST. The "
         "threshold is where F = (P &minus; &gamma;) / (1 &minus; &gamma;), P the procedure's target (0.5: the "
         "PSE).</li>\n"
         "<li>Intervals: percentile intervals of a parametric bootstrap (Wichmann &amp; Hill 2001b); goodness of "
         "fit: the deviance against its bootstrap distribution.</li>\n"
         "<li>Staircases: the mean of each track's last reversals (Levitt 1971). QUEST: the posterior mean and "
         "the 2.5% and 97.5% posterior quantiles (Watson &amp; Pelli 1983; Psychtoolbox QuestMean, "
         "QuestQuantile), from the logged answers replayed through the protocol's procedure.</li>\n"
         "<li>Adjustment: the mean of the confirmed matches with a bootstrap interval over matches. "
         "log10(PSE or match / test intensity), both in cd: a brightness enhancement when glare is the only "
         "difference between the lights (read from the scene stored in the study file), else test &minus; "
         "reference.</li>\n"
         "<li>Observed proportions carry Clopper-Pearson intervals.</li>\n"
         "</ul>\n";
    h += "<p>Files next to this report: <a href=\"trials.csv\">trials.csv</a> (one row per trial), "
         "<a href=\"fits.csv\">fits.csv</a> (one row per estimate), <a href=\"summary.json\">summary.json</a> (every "
         "number here), and <code>figures/</code>. Their columns are described in docs/analysis.md.</p>\n";
    h += "</body>\n</html>\n";

    files::write_file_atomically(file, h);
}

}  // namespace atonlab::analysis
