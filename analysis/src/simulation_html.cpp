// The simulation report's page (simulation_report.h): one self-contained
// report.html, styled and built as the study report is (html_parts.h).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>

#include "atonlab/analysis/simulation_report.h"
#include "atonlab/common/atomic_file.h"
#include "html_parts.h"

namespace atonlab::analysis {

namespace {

using detail::esc;

std::string f3(const std::optional<double>& v) {
    return v ? fmt::format("{:.3f}", *v) : std::string("&ndash;");
}

std::string f4(const std::optional<double>& v) {
    return v ? fmt::format("{:.4f}", *v) : std::string("&ndash;");
}

std::string percent(const std::optional<double>& v) {
    return v ? fmt::format("{:.1f}%", 100.0 * *v) : std::string("&ndash;");
}

std::string ci_percent(const std::optional<Interval>& ci) {
    return ci ? fmt::format("[{:.1f}, {:.1f}]", 100.0 * ci->lower, 100.0 * ci->upper) : std::string("&ndash;");
}

/// The files left out, first, so that no reader misses them (at most kListed
/// in the page; summary.json lists every one).
std::string skipped_html(const SimulationResults& r) {
    if (r.skipped.empty()) return {};
    constexpr std::size_t kListed = 200;
    std::string h = fmt::format(
        "<div class=\"warn\"><p><b>{} file(s) left out</b> of {} found under <code>sessions/</code>; each with its "
        "reason:</p>\n<ul>\n",
        r.skipped.size(), r.files_found);
    for (std::size_t i = 0; i < std::min(kListed, r.skipped.size()); ++i)
        h += fmt::format("<li><code>{}</code>: {}</li>\n", esc(r.skipped[i].file), esc(r.skipped[i].reason));
    if (r.skipped.size() > kListed)
        h += fmt::format("<li>and {} more, every one in summary.json (<code>skipped</code>)</li>\n",
                         r.skipped.size() - kListed);
    return h + "</ul></div>\n";
}

std::string conditions_html(const SimulationResults& r) {
    const bool several = r.manifest.designs.size() > 1;
    std::string h = "<h2>Per design and condition</h2>\n<div class=\"table-wrap\"><table>\n<tr>";
    if (several) h += "<th>design</th>";
    h += "<th>condition</th><th>true value</th><th>sessions</th><th>mean</th><th>median</th>"
         "<th>bias</th><th>SD</th><th>RMSE</th><th>coverage [95% interval]</th><th>median width</th>"
         "<th>calibrated: widen × (held-out coverage)</th>"
         "<th>trials (median, P90)</th><th>unreliable</th></tr>\n";
    for (const ConditionSummary& c : r.conditions) {
        h += "<tr>";
        if (several)
            h += fmt::format("<td>{}</td>", esc(c.design.empty() ? fmt::format("{}", c.design_index) : c.design));
        const bool low = c.coverage_ci && c.coverage_ci->upper < r.options.ci_level;
        const std::string coverage = percent(c.coverage) + "<br><small>" + ci_percent(c.coverage_ci) + "</small>";
        h += fmt::format(
            "<td>{}</td><td class=\"num\">{}{}<br><small>{}<br>{}, P = {:.3g}</small></td>"
            "<td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
            "<td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
            "<td class=\"num\">{}</td><td class=\"num\">{}, {}</td><td class=\"num\">{} of {}</td></tr>\n",
            esc(c.condition), f4(c.truth), c.truth_differs ? "*" : "", esc(c.unit), esc(c.truth_what), c.truth_p,
            c.n_sessions, f4(c.mean), f4(c.median), f4(c.bias), f4(c.sd), f4(c.rmse),
            low ? "<span class=\"bad\">" + coverage + "</span>" : coverage, f3(c.width_median),
            c.widen_factor ? fmt::format("{:.2f}<br><small>{} {}</small>", *c.widen_factor,
                                         percent(c.calibrated_coverage), ci_percent(c.calibrated_coverage_ci))
                           : std::string("&ndash;"),
            c.trials_median ? fmt::format("{:g}", *c.trials_median) : "&ndash;",
            c.trials_p90 ? fmt::format("{:g}", *c.trials_p90) : "&ndash;", c.n_unreliable, c.n_estimates);
    }
    h += "</table></div>\n";
    h += fmt::format(
        "<p>Bias, SD and RMSE in the condition's level units. Coverage: of the sessions' {} intervals, the share "
        "that holds the session's true value, with its Clopper-Pearson 95% interval; in red where that interval "
        "lies wholly below the nominal {:.0f}%. Unreliable: estimates the analysis flagged (kept in every number). "
        "* the sessions' true values differ (each estimate is compared with its own). Calibrated: the factor by "
        "which this design's intervals must widen (each side, about the estimate) to hold the truth as often as "
        "nominal, found on half the sessions, and the coverage it gives on the other half.</p>\n",
        to_string(r.options.intervals), 100.0 * r.options.ci_level);
    return h;
}

std::string power_html(const SimulationResults& r) {
    std::string h = "<h2>Power</h2>\n";
    if (!r.options.effect_log10)
        return h +
               "<p>No effect was stated: give <code>--effect D</code> (log10 units) to see the power to detect "
               "it.</p>\n";
    if (r.power.empty()) return h + "<p>No power could be computed (see the notes above).</p>\n";
    h += fmt::format(
        "<p>The share of sessions that would detect an effect of {} log10 units at &alpha; = {:.2g} (two-sided), "
        "by the location-shift method (below).</p>\n<div class=\"table-wrap\"><table>\n<tr><th>design</th>"
        "<th>effect of</th><th>true difference</th><th>SD of the estimated difference</th><th>sessions</th>"
        "<th>power</th><th>its 95% interval</th></tr>\n",
        *r.options.effect_log10, 1.0 - r.options.ci_level);
    for (const PowerSummary& p : r.power)
        h += fmt::format(
            "<tr><td>{}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td>"
            "<td class=\"num\">{}</td><td class=\"num\">{}</td></tr>\n",
            esc(p.design.empty() ? fmt::format("{}", p.design_index) : p.design),
            esc(p.condition_b.empty() ? fmt::format("{}: {}", p.condition_a, p.what) : p.what), f4(p.true_difference),
            f4(p.sd_difference), p.n_sessions, percent(p.power), ci_percent(p.power_ci));
    return h + "</table></div>\n";
}

std::string methods_html(const SimulationResults& r) {
    const std::string interval =
        r.options.intervals == IntervalMethod::Profile
            ? "the profile-likelihood interval of the fit's threshold: every threshold whose profile "
              "log-likelihood (the slope and a free lapse rate maximised) lies within &chi;&sup2;<sub>1</sub>(level)/2 "
              "of the maximum (Wilks 1938; Venzon &amp; Moolgavkar 1988); no resampling. An end the profile does not "
              "reach within the fit's search range is that range's limit (counted as <em>open</em> in "
              "summary.json)"
            : fmt::format(
                  "the percentile interval of {} parametric bootstrap resamples per fit (Wichmann &amp; Hill "
                  "2001b), exactly as the study report's",
                  r.options.bootstrap);
    return "<h2>Methods</h2>\n<ul>\n"
           "<li>Each study file holds one simulated session and its observer's true values. Its conditions are "
           "estimated as the study report estimates one observer's (psychometric fit by binomial maximum "
           "likelihood; QUEST's or the staircases' own estimate where no fit exists).</li>\n"
           "<li>Intervals: " +
           interval +
           ". Where the estimate is not the fit's (QUEST's posterior), its own interval.</li>\n"
           "<li>Bias: the mean of estimate &minus; true value over sessions; SD: the estimates' standard deviation "
           "(n &minus; 1); RMSE: the root mean squared error. Coverage carries its Clopper-Pearson (exact) "
           "interval. Trials per session: the median and the 90th percentile (nearest rank).</li>\n"
           "<li>Power (location shift): each session's error d<sub>i</sub> &minus; true d<sub>i</sub> is taken to be "
           "what it would be were the true difference the stated effect D, and its standard error to be its "
           "interval's width / (2 z<sub>0.975</sub>); the session detects the effect when |D + d<sub>i</sub> "
           "&minus; true d<sub>i</sub>| / se<sub>i</sub> &gt; z<sub>0.975</sub>. This assumes the estimator's error "
           "and interval width do not depend on the size of the effect, and (for two conditions) that their "
           "errors are independent. By default d is each glare condition's enhancement log10(PSE / test "
           "intensity), the study report's; <code>--effect-between A,B</code> takes A &minus; B.</li>\n"
           "</ul>\n";
}

}  // namespace

void write_simulation_report_html(const std::filesystem::path& file, const SimulationReportContext& ctx) {
    const SimulationResults& r = *ctx.results;
    const std::filesystem::path out_dir = file.parent_path();
    std::string h = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
    h += "<title>atonlab simulation report</title>\n<style>\n" + std::string(detail::kReportStyle) +
         "\n</style>\n</head>\n<body>\n<h1>atonlab simulation report</h1>\n";
    h += skipped_html(r);
    h += fmt::format("<p>Made by atonlab {} with <code>{}</code>.</p>\n", esc(ctx.software_version),
                     esc(ctx.command_line));
    h += fmt::format(
        "<p>Simulation folder <code>{}</code>: protocol <code>{}</code> (SHA-256 <code>{}</code>), {} "
        "design(s):</p>\n<ul>\n",
        esc(r.folder.string()), esc(r.manifest.protocol()), esc(r.manifest.protocol_sha256().substr(0, 16)),
        r.manifest.designs.size());
    for (std::size_t i = 0; i < r.manifest.designs.size(); ++i) {
        const ManifestDesign& d = r.manifest.designs[i];
        h += fmt::format("<li>{}: <b>{}</b>{}</li>\n", i, esc(d.label.empty() ? "(the protocol as it is)" : d.label),
                         d.overrides.empty() || (d.overrides.size() == 1 && d.overrides[0] == d.label)
                             ? std::string()
                             : esc(fmt::format(" ({})", fmt::join(d.overrides, ", "))));
    }
    h += "</ul>\n";
    h += fmt::format(
        "<p>{} file(s) found, {} session(s) read, {} left out; read and estimated in {:.1f} s on {} thread(s) "
        "({:.0f} files/s). {:.0f}% intervals: {}{}; psychometric family {}.</p>\n",
        r.files_found, r.sessions.size(), r.skipped.size(), r.read_s, r.options.n_threads,
        r.read_s > 0.0 ? static_cast<double>(r.files_found) / r.read_s : 0.0, 100.0 * r.options.ci_level,
        to_string(r.options.intervals),
        r.options.intervals == IntervalMethod::Bootstrap
            ? fmt::format(" ({} resamples, percentile; {} refits, {:.0f} fits/s)", r.options.bootstrap,
                          r.bootstrap_fits, r.read_s > 0.0 ? static_cast<double>(r.bootstrap_fits) / r.read_s : 0.0)
            : std::string(),
        to_string(r.options.family));
    std::vector<std::string> warnings = r.warnings;
    if (ctx.plots) warnings.insert(warnings.end(), ctx.plots->problems.begin(), ctx.plots->problems.end());
    if (!warnings.empty()) {
        h += "<div class=\"warn\"><p><b>Notes and warnings</b></p>\n<ul>\n";
        for (const std::string& w : warnings) h += "<li>" + esc(w) + "</li>\n";
        h += "</ul></div>\n";
    }
    h += conditions_html(r);
    if (ctx.plots)
        for (const Figure& f : ctx.plots->figures) h += detail::figure_html(out_dir, f);
    h += power_html(r);
    h += methods_html(r);
    h += "<p>Files next to this report: <a href=\"simulation.csv\">simulation.csv</a> (one row per design and "
         "condition), <a href=\"sessions.csv\">sessions.csv</a> (one row per session and condition), <a "
         "href=\"summary.json\">summary.json</a> (every number here, and every file left out), and "
         "<code>figures/</code>. Their columns are described in docs/analysis.md.</p>\n</body>\n</html>\n";
    files::write_file_atomically(file, h);
}

}  // namespace atonlab::analysis
