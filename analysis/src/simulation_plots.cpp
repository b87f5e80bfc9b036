// The simulation report's figures (simulation_report.h), drawn by gnuplot as
// the study report's are (figure_drawer.h): every number is computed here.
//   estimates  each session's estimate − its true value, per design and
//              condition, with the mean error ± 1 SD;
//   widths     each session's interval width, with the median;
//   coverage   coverage (Clopper-Pearson 95 % interval) against the median
//              trials per session, with the nominal level and, grey, where
//              the coverage of an exact interval falls 95 % of the time with
//              that many sessions (the binomial's 2.5 % and 97.5 % quantiles).
#include <fmt/format.h>

#include <algorithm>
#include <boost/math/distributions/binomial.hpp>
#include <cmath>
#include <map>

#include "atonlab/analysis/simulation_report.h"
#include "csv.h"
#include "figure_drawer.h"

namespace atonlab::analysis {

namespace {

using detail::gp_quote;
using Rows = std::vector<std::vector<std::string>>;

std::string num(double v) {
    return std::isfinite(v) ? detail::number_text(v) : std::string("NaN");
}

/// A spread of points about a column's centre, the same every run (golden-ratio steps).
double jitter(std::size_t i) {
    const double f = std::fmod(static_cast<double>(i) * 0.6180339887498949, 1.0);
    return 0.6 * (f - 0.5);
}

std::string column_label(const SimulationResults& r, const ConditionSummary& c) {
    const bool several = r.manifest.designs.size() > 1;
    if (!several) return c.condition;
    const std::string design = c.design.empty() ? fmt::format("design {}", c.design_index) : c.design;
    return fmt::format("{} / {}", design, c.condition);
}

/// The common unit of the conditions, or a general label.
std::string unit_label(const SimulationResults& r, const char* what) {
    std::string unit;
    for (const ConditionSummary& c : r.conditions) {
        if (unit.empty()) unit = c.unit;
        if (c.unit != unit) return fmt::format("{} (each condition's units)", what);
    }
    return fmt::format("{} ({})", what, unit);
}

std::string axes(std::size_t columns, const std::string& title, const std::string& ylabel) {
    std::string b = "reset\nset datafile separator '\\t'\nset key top left box opaque\nset grid ytics\n";
    b += fmt::format("set xrange [0.4:{}]\nset xtics rotate by -30 nomirror\nset bmargin 9\n",
                     static_cast<double>(columns) + 0.6);
    b += fmt::format("set title {}\nset ylabel {}\n", gp_quote(title), gp_quote(ylabel));
    return b;
}

/// Per session, a value of each design × condition column (estimate − truth, or width).
void strip_figure(detail::FigureDrawer& d, const SimulationResults& r, bool widths) {
    std::map<std::pair<int, std::string>, std::size_t> column;
    Rows tics, points, summary;
    for (const ConditionSummary& c : r.conditions) {
        column[{c.design_index, c.condition}] = column.size() + 1;
        const double x = static_cast<double>(column.size());
        tics.push_back({num(x), column_label(r, c)});
        if (!widths && c.bias && c.sd)
            summary.push_back({num(x), num(*c.bias), num(*c.bias - *c.sd), num(*c.bias + *c.sd)});
        if (widths && c.width_median) summary.push_back({num(x), num(*c.width_median)});
    }
    std::size_t i = 0;
    for (const SessionSummary& s : r.sessions)
        for (const SessionEstimate& e : s.conditions) {
            const auto it = column.find({s.design_index, e.condition});
            if (it == column.end() || !e.estimate || !e.truth) continue;
            if (widths && !e.ci) continue;
            const double y = widths ? e.ci->upper - e.ci->lower : *e.estimate - *e.truth;
            points.push_back({num(static_cast<double>(it->second) + jitter(i++)), num(y)});
        }
    if (points.empty()) return;
    std::string xtics = "set xtics (";
    for (std::size_t k = 0; k < tics.size(); ++k)
        xtics += fmt::format("{}{} {}", k ? ", " : "", gp_quote(tics[k][1]), tics[k][0]);
    xtics += ")\n";
    const double level = 100.0 * r.options.ci_level;
    std::string body =
        widths
            ? axes(tics.size(),
                   fmt::format("Width of each session's {:.0f}% interval ({})", level, to_string(r.options.intervals)),
                   unit_label(r, "interval width"))
            : axes(tics.size(), "Each session's estimate minus its true value", unit_label(r, "estimate − truth"));
    body += xtics;
    if (!widths) body += "set arrow from graph 0, first 0 to graph 1, first 0 nohead lc rgb '#444444' dt 2\n";
    body += fmt::format("plot {} using 1:2 with points pt 7 ps 0.35 lc rgb '#801f77b4' title 'one session'",
                        d.data(widths ? "widths.tsv" : "errors.tsv", points));
    if (!summary.empty())
        body += widths ? fmt::format(", \\\n     {} using 1:2 with points pt 5 ps 1.6 lc rgb '#d62728' title 'median'",
                                     d.data("widths-median.tsv", summary))
                       : fmt::format(
                             ", \\\n     {} using 1:2:3:4 with yerrorbars pt 5 ps 1.4 lw 2 lc rgb '#d62728' "
                             "title 'bias ± 1 SD'",
                             d.data("errors-summary.tsv", summary));
    body += "\n";
    Figure f;
    f.id = widths ? "simulation-widths" : "simulation-estimates";
    f.kind = f.id;
    f.title = widths ? "Interval widths" : "Estimates around the truth";
    f.caption = widths ? fmt::format(
                             "Each dot is one session's {:.0f}% interval width (spread sideways to be seen); "
                             "the red square is the median.",
                             level)
                       : "Each dot is one session's estimate minus its own true value (spread sideways to be seen); "
                         "red: the mean error (the bias) ± 1 SD of the estimates. The dashed line is no error.";
    d.draw(std::move(f), body);
}

void coverage_figure(detail::FigureDrawer& d, const SimulationResults& r) {
    Rows rows, band;
    const double level = r.options.ci_level;
    double x_min = 1e300, x_max = 0.0;
    // Conditions at the same trials side by side: each a little to the right of the last.
    std::map<double, int> at_x;
    for (const ConditionSummary& c : r.conditions) {
        if (!c.coverage || !c.coverage_ci || !c.trials_median) continue;
        const double x = *c.trials_median * (1.0 + 0.004 * at_x[*c.trials_median]++);
        x_min = std::min(x_min, x);
        x_max = std::max(x_max, x);
        rows.push_back(
            {num(x), num(*c.coverage), num(c.coverage_ci->lower), num(c.coverage_ci->upper), column_label(r, c)});
        // Where an exact interval's coverage falls 95 % of the time with n sessions.
        const boost::math::binomial_distribution<> b(c.n_intervals, level);
        const double lo = boost::math::quantile(b, 0.025) / c.n_intervals;
        const double hi = boost::math::quantile(boost::math::complement(b, 0.025)) / c.n_intervals;
        band.push_back({num(x), num(0.5 * (lo + hi)), num(0.5 * (hi - lo))});
    }
    if (rows.empty()) return;
    const double pad = std::max(1.0, 0.1 * (x_max - x_min));
    std::string body = "reset\nset datafile separator '\\t'\nset key above box\nset grid\n";
    // Room on the right for the last points' labels.
    body += fmt::format("set xrange [{}:{}]\nset yrange [*:1.02]\n", num(std::max(0.0, x_min - pad)),
                        num(x_max + 4.0 * pad));
    body += fmt::format(
        "set title {}\nset xlabel 'trials per session (median of the condition)'\nset ylabel "
        "'coverage'\n",
        gp_quote(fmt::format("Coverage of the {:.0f}% intervals ({})", 100.0 * level, to_string(r.options.intervals))));
    body += fmt::format("set arrow from graph 0, first {0} to graph 1, first {0} nohead lc rgb '#444444' dt 2\n",
                        num(level));
    body += fmt::format(
        "plot {} using 1:2:({}):3 with boxxyerror fs solid 0.25 noborder lc rgb '#888888' title 'a correct "
        "interval, 95% of the time', \\\n     {} using 1:2:3:4 with yerrorbars pt 7 ps 1.2 lc rgb '#1f77b4' title "
        "'coverage (Clopper-Pearson 95%)', \\\n     '' using 1:2:5 with labels offset 0.8,0 left font ',8' notitle\n",
        d.data("coverage-band.tsv", band), num(0.25 * pad), d.data("coverage.tsv", rows));
    Figure f;
    f.id = "simulation-coverage";
    f.kind = f.id;
    f.title = "Coverage against trials per session";
    f.caption = fmt::format(
        "Per design and condition: the share of sessions whose {:.0f}% interval holds their true value, with its "
        "Clopper-Pearson interval, at the condition's median trials per session. Grey: where the coverage of an "
        "interval that is exactly right would fall 95% of the time with as many sessions; the dashed line is the "
        "nominal level.",
        100.0 * level);
    d.draw(std::move(f), body);
}

}  // namespace

PlotResult make_simulation_figures(const std::filesystem::path& out_dir, const SimulationResults& results,
                                   const PlotOptions& options) {
    PlotResult out;
    std::filesystem::create_directories(out_dir / "figures");
    detail::FigureDrawer d(out_dir, options, out);
    strip_figure(d, results, false);
    strip_figure(d, results, true);
    coverage_figure(d, results);
    return out;
}

}  // namespace atonlab::analysis
