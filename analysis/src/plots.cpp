// The report's figures (plots.h): the numbers are computed here, gnuplot only
// draws them, once with the pngcairo terminal and once with the svg terminal.
#include "atonlab/analysis/plots.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include "atonlab/analysis/simulation.h"
#include "atonlab/common/input_error.h"
#include "atonlab/display/display_model.h"
#include "atonlab/display/fit_json.h"
#include "atonlab/store/error.h"
#include "atonlab/store/sha256.h"
#include "csv.h"
#include "figure_drawer.h"
#include "gnuplot.h"

namespace atonlab::analysis {

namespace fs = std::filesystem;
using detail::gp_quote;

namespace {

const char* kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                          "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
constexpr std::size_t kNColours = sizeof(kColours) / sizeof(kColours[0]);

std::string num(double v) {
    return std::isfinite(v) ? detail::number_text(v) : std::string("NaN");
}

/// Clopper-Pearson (exact) interval of a binomial proportion k/n (simulation.h, clopper_pearson).
std::pair<double, double> proportion_interval(int k, int n, double level) {
    const std::optional<Interval> ci = clopper_pearson(k, n, level);
    return ci ? std::pair{ci->lower, ci->upper} : std::pair{0.0, 1.0};
}

using Drawer = detail::FigureDrawer;

std::string outcome_label(const ConditionInfo& c) {
    if (c.task == protocols::Task::YesNo) return "P(yes)";
    return c.level_on == "test" ? "P(chose the test)" : "P(chose the reference)";
}

std::string level_label(const ConditionInfo& c) {
    std::string what = c.level_key.empty() ? std::string("level") : c.level_key;
    return fmt::format("{} ({})", what, c.level_unit());
}

std::string estimate_name(const ConditionInfo& c) {
    return std::abs(c.target_p - 0.5) < 1e-12 && c.guess_rate == 0.0
               ? "PSE"
               : fmt::format("threshold (P = {:.3g})", c.target_p);
}

// --- psychometric curves ------------------------------------------------------

void psychometric_figure(Drawer& d, const StudyResults& r, const ConditionInfo& c, const std::string& slug) {
    const GroupResult* main = r.main_group(c.condition);
    if (!main || main->counts.empty()) return;
    const double level = r.options.ci_level;
    int n_max = 1;
    double lo = main->counts.front().level, hi = main->counts.back().level;
    for (const LevelCounts& k : main->counts) n_max = std::max(n_max, k.n_trials);
    std::vector<std::vector<std::string>> points;
    for (const LevelCounts& k : main->counts) {
        const auto [plo, phi] = proportion_interval(k.n_yes, k.n_trials, level);
        const double size = 0.6 + 2.0 * std::sqrt(static_cast<double>(k.n_trials) / n_max);
        points.push_back({num(k.level), num(static_cast<double>(k.n_yes) / k.n_trials), std::to_string(k.n_trials),
                          num(plo), num(phi), num(size)});
    }
    const std::string pts = d.data(slug + "-points.tsv", points);
    std::string plot = fmt::format(
        "plot {0} using 1:2:4:5 with yerrorbars lc rgb '#888888' pt 0 title '{1:.0f}% CI (Clopper-Pearson)', \\\n"
        "     {0} using 1:2:6 with points pt 7 ps variable lc rgb '#1f77b4' title 'observed (size: trials)'",
        pts, 100.0 * level);
    std::string thr_text;
    const auto curve_of = [&](const GroupResult& g) -> std::vector<std::vector<std::string>> {
        std::vector<std::vector<std::string>> rows;
        if (!g.fit || !g.fit->estimate) return rows;
        double a = lo, b = hi;
        if (g.bootstrap && g.bootstrap->threshold) {
            a = std::min(a, g.bootstrap->threshold->lower);
            b = std::max(b, g.bootstrap->threshold->upper);
        }
        a = std::min(a, g.fit->estimate->threshold);
        b = std::max(b, g.fit->estimate->threshold);
        const double pad = 0.05 * std::max(b - a, 1e-6);
        a -= pad;
        b += pad;
        if (takes_linear_levels(g.family)) a = std::max(a, 1e-9);
        for (int i = 0; i <= 200; ++i) {
            const double x = a + (b - a) * i / 200.0;
            rows.push_back({num(x), num(psi(g.family, x, g.fit->estimate->params))});
        }
        return rows;
    };
    if (r.observers.size() > 1) {
        std::size_t k = 0;
        for (const GroupResult& g : r.groups) {
            if (g.condition != c.condition || g.observer == kPooled) continue;
            const auto rows = curve_of(g);
            if (rows.empty()) continue;
            const std::string f = d.data(fmt::format("{}-curve-{}.tsv", slug, k), rows);
            plot += fmt::format(", \\\n     {} using 1:2 with lines lw 1 dt 2 lc rgb '{}' title {}", f,
                                kColours[(k + 2) % kNColours], gp_quote("fit: " + g.observer));
            ++k;
        }
    }
    const auto rows = curve_of(*main);
    if (!rows.empty()) {
        const std::string f = d.data(slug + "-curve.tsv", rows);
        plot += fmt::format(", \\\n     {} using 1:2 with lines lw 2 lc rgb '#d62728' title {}", f,
                            gp_quote(fmt::format("{} fit ({})", to_string(main->family), main->observer)));
        const PsychometricEstimate& e = *main->fit->estimate;
        const double y = psi(main->family, e.threshold, e.params);
        if (main->bootstrap && main->bootstrap->threshold) {
            const Interval& ci = *main->bootstrap->threshold;
            const std::string t =
                d.data(slug + "-threshold.tsv", {{num(e.threshold), num(y), num(ci.lower), num(ci.upper)}});
            plot += fmt::format(", \\\n     {} using 1:2:3:4 with xerrorbars pt 5 ps 1.3 lc rgb '#000000' title {}", t,
                                gp_quote(fmt::format("{} and {:.0f}% CI", estimate_name(c), 100.0 * level)));
        } else {
            const std::string t = d.data(slug + "-threshold.tsv", {{num(e.threshold), num(y)}});
            plot += fmt::format(", \\\n     {} using 1:2 with points pt 5 ps 1.3 lc rgb '#000000' title {}", t,
                                gp_quote(estimate_name(c) + " (no interval)"));
        }
    }
    std::string body = "reset\nset datafile separator '\\t'\nset key below\nset grid\n";
    body += fmt::format("set title {}\n", gp_quote(fmt::format("{}: {} against the level ({}, {} trials)", c.condition,
                                                               outcome_label(c), main->observer, main->n_scored)));
    body +=
        fmt::format("set xlabel {}\nset ylabel {}\nset yrange [-0.03:1.03]\nset offsets graph 0.04, graph 0.04, 0, 0\n",
                    gp_quote(level_label(c)), gp_quote(outcome_label(c)));
    body += plot + "\n";
    Figure f;
    f.id = "psychometric-" + slug;
    f.kind = "psychometric";
    f.condition = c.condition;
    f.title = fmt::format("Psychometric function: {}", c.condition);
    f.caption = fmt::format(
        "Proportion {} per level ({} trials in all; marker area grows with the trials at the level; bars: "
        "{:.0f}% Clopper-Pearson intervals), the maximum-likelihood {} fit (guess rate {} fixed, lapse rate free "
        "in [0, 0.06]) and its {} with the parametric-bootstrap interval.",
        outcome_label(c), main->n_scored, 100.0 * level, to_string(main->family), c.guess_rate, estimate_name(c));
    d.draw(std::move(f), body);
}

// --- adaptive tracks ------------------------------------------------------------

void tracks_figure(Drawer& d, const StudyResults& r, const ConditionInfo& c, const std::string& slug) {
    const GroupResult* main = r.main_group(c.condition);
    if (!main || main->tracks.empty()) return;
    std::string plot = "plot ";
    std::size_t k = 0;
    bool any_reversal = false;
    for (const TrackResult& t : main->tracks) {
        std::vector<std::vector<std::string>> rows;
        for (std::size_t i = 0; i < t.levels.size(); ++i)
            rows.push_back(
                {std::to_string(i + 1), num(t.levels[i]), i < t.reversal.size() && t.reversal[i] ? "1" : "0"});
        const std::string f = d.data(fmt::format("{}-track-{}.tsv", slug, k), rows);
        const std::string name = r.observers.size() > 1 ? t.observer + " " + t.track : t.track;
        plot += fmt::format("{}{} using 1:2 with linespoints pt 7 ps 0.6 lc rgb '{}' title {}", k ? ", \\\n     " : "",
                            f, kColours[k % kNColours], gp_quote(name));
        if (!t.reversal.empty()) {
            plot += fmt::format(", \\\n     {} using 1:($3 > 0 ? $2 : 1/0) with points pt 6 ps 1.8 lc rgb '{}' notitle",
                                f, kColours[k % kNColours]);
            for (const bool b : t.reversal) any_reversal = any_reversal || b;
        }
        ++k;
    }
    if (main->headline.value) {
        plot +=
            fmt::format(", \\\n     {} with lines dt 2 lw 1.5 lc rgb '#000000' title {}", num(*main->headline.value),
                        gp_quote(fmt::format("{} ({})", estimate_name(c), main->observer)));
    }
    std::string body = "reset\nset datafile separator '\\t'\nset key outside right top\nset grid\n";
    body += fmt::format("set title {}\nset xlabel 'trial of the track'\nset ylabel {}\n",
                        gp_quote(fmt::format("{}: adaptive tracks ({})", c.condition, c.procedure)),
                        gp_quote(level_label(c)));
    body += "set offsets 0.5, 0.5, graph 0.05, graph 0.05\n" + plot + "\n";
    Figure f;
    f.id = "tracks-" + slug;
    f.kind = "tracks";
    f.condition = c.condition;
    f.title = fmt::format("Adaptive tracks: {}", c.condition);
    f.caption = fmt::format("The level of every trial of each {} track in order{}; the dashed line is the {}.",
                            c.procedure, any_reversal ? ", reversals circled" : "", estimate_name(c));
    d.draw(std::move(f), body);
}

// --- PSE / threshold per condition ------------------------------------------------

void pse_figure(Drawer& d, const StudyResults& r) {
    std::vector<std::vector<std::string>> main_rows, obs_rows, unreliable;
    std::set<std::string> units;
    int x = 0;
    for (const ConditionInfo& c : r.conditions) {
        const GroupResult* main = r.main_group(c.condition);
        if (!main || !main->headline.value) continue;
        ++x;
        units.insert(c.level_unit());
        const HeadlineEstimate& h = main->headline;
        main_rows.push_back({std::to_string(x), num(*h.value), num(h.ci ? h.ci->lower : *h.value),
                             num(h.ci ? h.ci->upper : *h.value), c.condition});
        if (!h.reliable) unreliable.push_back({std::to_string(x), num(*h.value)});
        if (r.observers.size() > 1) {
            std::size_t k = 0;
            for (const GroupResult& g : r.groups) {
                if (g.condition != c.condition || g.observer == kPooled) continue;
                ++k;
                if (!g.headline.value) continue;
                const double off = 0.25 * (static_cast<double>(k) / static_cast<double>(r.observers.size() + 1) - 0.5);
                obs_rows.push_back({num(x + off), num(*g.headline.value),
                                    num(g.headline.ci ? g.headline.ci->lower : *g.headline.value),
                                    num(g.headline.ci ? g.headline.ci->upper : *g.headline.value)});
            }
        }
    }
    if (main_rows.empty()) return;
    const std::string m = d.data("pse-main.tsv", main_rows);
    std::string plot =
        fmt::format("plot {0} using 1:2:3:4:xtic(5) with yerrorbars pt 7 ps 1.4 lc rgb '#000000' title {1}", m,
                    gp_quote(r.observers.size() > 1 ? "pooled"
                             : r.observers.empty()  ? ""
                                                    : r.observers[0]));
    if (!obs_rows.empty()) {
        const std::string o = d.data("pse-observers.tsv", obs_rows);
        plot += fmt::format(
            ", \\\n     {} using 1:2:3:4 with yerrorbars pt 6 ps 0.9 lc rgb '#1f77b4' title 'each observer'", o);
    }
    if (!unreliable.empty())
        plot += fmt::format(
            ", \\\n     {} using 1:2 with points pt 6 ps 3 lw 1.5 lc rgb '#b3261e' title 'unreliable (see the report)'",
            d.data("pse-unreliable.tsv", unreliable));
    std::string body = "reset\nset datafile separator '\\t'\nset key top left box opaque\nset grid ytics\n";
    body += fmt::format("set xrange [0.4:{}]\nset xtics rotate by -30 nomirror\nset bmargin 9\n", x + 0.6);
    body += fmt::format("set title 'PSE or threshold per condition, {:.0f}% intervals'\nset ylabel {}\n",
                        100.0 * r.options.ci_level,
                        gp_quote(units.size() == 1 ? *units.begin() : std::string("level (each condition's units)")));
    body += plot + "\n";
    Figure f;
    f.id = "pse";
    f.kind = "pse";
    f.title = "PSE or threshold per condition";
    f.caption =
        "Each condition's headline estimate (the psychometric fit's PSE or threshold, QUEST's or the "
        "staircases' own estimate where no fit exists, the mean match for adjustment) with its interval" +
        std::string(r.observers.size() > 1 ? "; open circles: each observer, filled: pooled." : ".");
    d.draw(std::move(f), body);
}

// --- brightness enhancement ----------------------------------------------------------

void enhancement_figure(Drawer& d, const StudyResults& r) {
    struct Row {
        double adaptation;
        double value, lo, hi;
        std::string condition;
        bool reliable;
    };
    std::map<std::string, std::vector<Row>> series;  // by tone mapper
    bool all_adaptation = true;
    bool glare_only = true;  // every condition drawn differs in glare alone: an enhancement by glare
    int index = 0;
    for (const ConditionInfo& c : r.conditions) {
        const GroupResult* g = r.main_group(c.condition);
        if ((!c.compares_glare() && c.differences.empty()) || !g || !g->match_ratio || !g->match_ratio->value) continue;
        glare_only = glare_only && c.glare_only_difference();
        ++index;
        const MatchRatio& m = *g->match_ratio;
        all_adaptation = all_adaptation && c.adaptation_cd_m2.has_value();
        series[c.tone_operator.empty() ? "(scene default)" : c.tone_operator].push_back(
            {c.adaptation_cd_m2.value_or(index), *m.value, m.ci ? m.ci->lower : *m.value, m.ci ? m.ci->upper : *m.value,
             c.condition, m.reliable});
    }
    if (series.empty()) return;
    std::string plot = "plot ";
    std::size_t k = 0;
    std::vector<std::vector<std::string>> unreliable;
    for (auto& [op, rows] : series) {
        std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.adaptation < b.adaptation; });
        std::vector<std::vector<std::string>> data;
        // Series side by side: a small offset along x (a factor on a log axis).
        const double shift = (static_cast<double>(k) - 0.5 * static_cast<double>(series.size() - 1)) * 0.04;
        for (const Row& row : rows) {
            const double x = all_adaptation ? row.adaptation * std::pow(10.0, shift) : row.adaptation + shift;
            data.push_back({num(x), num(row.value), num(row.lo), num(row.hi)});
            if (!row.reliable) unreliable.push_back({num(x), num(row.value)});
        }
        const std::string f = d.data(fmt::format("enhancement-{}.tsv", k), data);
        plot += fmt::format("{}{} using 1:2:3:4 with yerrorlines pt 7 ps 1.2 lw 1.5 lc rgb '{}' title {}",
                            k ? ", \\\n     " : "", f, kColours[k % kNColours], gp_quote("tone mapper: " + op));
        ++k;
    }
    if (!unreliable.empty())
        plot += fmt::format(
            ", \\\n     {} using 1:2 with points pt 6 ps 3 lw 1.5 lc rgb '#b3261e' title 'unreliable (see the report)'",
            d.data("enhancement-unreliable.tsv", unreliable));
    plot += fmt::format(", \\\n     0 with lines dt 2 lc rgb '#000000' title '{}'",
                        glare_only ? "no enhancement" : "match = test");
    std::string body = "reset\nset datafile separator '\\t'\nset key outside right top\nset grid\n";
    if (all_adaptation)
        body +=
            "set logscale x 10\nset format x '%g'\nset xlabel 'adaptation luminance (cd/m2)'\nset offsets graph 0.1, "
            "graph 0.1, graph 0.1, graph 0.1\n";
    else
        body += "set xlabel 'condition (adaptation not stated)'\nset offsets 0.5, 0.5, graph 0.1, graph 0.1\n";
    // Named by what it measures (ConditionInfo::difference_label): glare
    // alone, or test − reference where the lights differ in more.
    body += glare_only ? "set ylabel 'log10(matched no-glare intensity / glare test intensity)'\n"
                       : "set ylabel 'log10(matched reference intensity / test intensity)'\n";
    body +=
        fmt::format("set title '{}, {:.0f}% intervals'\n",
                    glare_only ? "Brightness enhancement by glare" : "Test - reference", 100.0 * r.options.ci_level);
    body += plot + "\n";
    Figure f;
    f.id = "enhancement";
    f.kind = "enhancement";
    f.title = glare_only ? "Brightness enhancement by glare" : "Test − reference";
    f.caption = glare_only
                    ? "log10 of the intensity of the light without glare that matches the light with glare, over "
                      "the glare light's own intensity (both put the same illuminance into the eye), per adaptation "
                      "level and tone mapper. Above 0: the glare rendering looks brighter than its energy-matched "
                      "twin."
                    : "log10 of the reference intensity that matches the test, over the test's own intensity, per "
                      "adaptation level and tone mapper. The test and the reference differ in more than glare "
                      "(colour, rhythm, spectrum or frame settings: see each condition), so this is not an effect "
                      "of glare alone. Above 0: the test looks brighter than an equally intense reference.";
    d.draw(std::move(f), body);
}

// --- display calibration --------------------------------------------------------------

/// A display's checks over time (calibration_drift.h), once per display and file.
void drift_figures(Drawer& d, const Dataset& data) {
    std::set<std::pair<std::string, std::string>> drawn;
    int k = 0;
    for (const CalibrationInfo& c : data.calibrations) {
        if (c.drift.empty() || !drawn.insert({c.source, c.display_name}).second) continue;
        const std::string id = fmt::format("calibration-drift-{}", ++k);
        Figure f;
        f.id = id;
        f.kind = "calibration-drift";
        f.title = fmt::format("Display calibration checks over time: {}", c.display_name);
        f.caption = fmt::format(
            "Every check of display {} stored in {}: white (peak), black, effective gamma and the worst grey "
            "patch's error against the date, each with the check's tolerance band (shaded, and as a bar at each "
            "check); failed checks are red crosses.",
            c.display_name, c.source);
        d.draw(std::move(f),
               drift_plot_body(d.data(id + ".tsv", drift_data_rows(c.drift)), c.drift, f.title));
    }
}

void calibration_figures(Drawer& d, const Dataset& data, std::vector<std::string>& problems) {
    drift_figures(d, data);
    int k = 0;
    for (const CalibrationInfo& c : data.calibrations) {
        ++k;
        std::vector<std::vector<std::string>> curve;
        for (int i = 0; i <= 200; ++i) {
            const double v = i / 200.0;
            const auto L = model_grey_luminance_cd_m2(c.fit_json, v);
            if (!L) {
                curve.clear();
                break;
            }
            curve.push_back({num(v), num(*L)});
        }
        std::vector<std::vector<std::string>> points, residuals;
        for (const CalibrationPoint& p : c.readings) {
            if (p.channel != "grey") continue;
            points.push_back({num(p.drive), num(p.luminance_cd_m2)});
            if (!curve.empty())
                if (const auto L = model_grey_luminance_cd_m2(c.fit_json, p.drive))
                    residuals.push_back({num(p.drive), num(p.luminance_cd_m2 - *L)});
        }
        const std::string id = fmt::format("calibration-{}", k);
        if (curve.empty() && points.empty()) {
            problems.push_back(
                fmt::format("display calibration {} of {}: its model (fit_json) is not one the report "
                            "can draw and it has no grey readings; no figure",
                            c.id, c.source));
            continue;
        }
        const bool nominal = display::fit_json_model(c.fit_json).value_or("") == "nominal";
        std::string title = fmt::format("Display {} ({}): luminance of grey", c.display_name, c.measured_at);
        std::string body = "reset\nset datafile separator '\\t'\nset grid\nset key top left box opaque\n";
        std::string top = "plot ";
        bool first = true;
        if (!curve.empty()) {
            top +=
                fmt::format("{} using 1:2 with lines lw 2 lc rgb '#d62728' title {}", d.data(id + "-model.tsv", curve),
                            gp_quote(nominal ? "nominal model (not measured)" : "fitted model"));
            first = false;
        }
        if (!points.empty())
            top += fmt::format("{}{} using 1:2 with points pt 7 lc rgb '#1f77b4' title 'photometer readings'",
                               first ? "" : ", \\\n     ", d.data(id + "-readings.tsv", points));
        if (!residuals.empty()) {
            body += "set multiplot layout 2,1 title " + gp_quote(title) + "\n";
            body += "set size 1,0.68\nset origin 0,0.32\nset ylabel 'luminance (cd/m2)'\nset xlabel ''\n" + top + "\n";
            body +=
                "set size 1,0.32\nset origin 0,0\nset title ''\nset ylabel 'reading - model (cd/m2)'\n"
                "set xlabel 'drive level V (all channels)'\nunset key\n";
            body +=
                fmt::format("plot {} using 1:2 with impulses lw 2 lc rgb '#1f77b4', 0 with lines lc rgb '#000000'\n",
                            d.data(id + "-residuals.tsv", residuals));
            body += "unset multiplot\n";
        } else {
            body += "set title " + gp_quote(title + (nominal ? " (nominal model: not measured)" : "")) + "\n";
            body += "set ylabel 'luminance (cd/m2)'\nset xlabel 'drive level V (all channels)'\n" + top + "\n";
        }
        Figure f;
        f.id = id;
        f.kind = "calibration";
        f.title = fmt::format("Display calibration: {}", c.display_name);
        f.caption = nominal ? fmt::format(
                                  "The display model the sessions used, {}: a nominal model taken from the "
                                  "scene's [display] table, not measured, so there are no readings or "
                                  "residuals to show.",
                                  c.how)
                    : residuals.empty()
                        ? fmt::format("The display model ({}) and its grey readings.", c.how)
                        : fmt::format(
                              "The fitted display model ({}) with its grey photometer readings (top) and the "
                              "residuals reading - model (bottom).",
                              c.how);
        d.draw(std::move(f), body);
    }
}

// --- frame timing ------------------------------------------------------------------------

void timing_figure(Drawer& d, const Dataset& data, const StudyResults& r) {
    if (!has_display_timing(data, r)) return;
    std::map<std::string, std::vector<const Trial*>> per;
    for (const Trial& t : data.trials) per[t.session].push_back(&t);
    int max_drop = 0;
    std::string plot = "plot ";
    std::size_t k = 0;
    for (const SessionTiming& s : r.timing) {
        std::vector<std::vector<std::string>> rows;
        for (const Trial* t : per[s.session]) {
            rows.push_back(
                {std::to_string(t->trial_index), std::to_string(t->dropped_frames), t->missed_deadline ? "1" : "0"});
            max_drop = std::max(max_drop, t->dropped_frames);
        }
        const std::string f = d.data(fmt::format("timing-{}.tsv", k), rows);
        plot += fmt::format("{}{} using 1:2 with impulses lw 2 lc rgb '{}' title {}", k ? ", \\\n     " : "", f,
                            kColours[k % kNColours],
                            gp_quote(fmt::format("{} ({}): dropped frames", s.session, s.observer)));
        plot += fmt::format(
            ", \\\n     {} using 1:($3 > 0 ? $2 + 0.2 : 1/0) with points pt 2 ps 1.2 lc rgb '{}' "
            "title 'missed deadline'",
            f, kColours[k % kNColours]);
        ++k;
    }
    std::string body = "reset\nset datafile separator '\\t'\nset key outside bottom center horizontal\nset grid\n";
    body += fmt::format("set yrange [0:{}]\nset xlabel 'trial (index in the session)'\nset ylabel 'dropped frames'\n",
                        max_drop + 1);
    int total_drops = 0, total_missed = 0;
    for (const SessionTiming& s : r.timing) {
        total_drops += s.dropped_frames;
        total_missed += s.missed_deadlines;
    }
    body += fmt::format("set title {}\n", gp_quote(fmt::format("Frame timing: {} dropped frames, {} missed deadlines "
                                                               "in {} session(s)",
                                                               total_drops, total_missed, r.timing.size())));
    body += plot + "\n";
    Figure f;
    f.id = "timing";
    f.kind = "timing";
    f.title = "Frame-timing quality per session";
    f.caption =
        "Dropped frames per trial (impulses) and trials whose onset frame missed its deadline (crosses), "
        "per session. Headless sessions (model or scripted observer) have no display and record none.";
    d.draw(std::move(f), body);
}

}  // namespace

bool has_display_timing(const Dataset& data, const StudyResults& results) {
    if (results.timing.empty()) return false;
    for (const SessionTiming& s : results.timing)
        if (s.dropped_frames > 0 || s.missed_deadlines > 0) return true;
    for (const SessionInfo& s : data.sessions)
        if (s.answered_by != "model" && s.answered_by != "script") return true;
    return false;
}

std::string file_slug(const std::string& name) {
    std::string out;
    for (const char ch : name) {
        const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '.' ||
                        ch == '-' || ch == '_';
        out += ok ? ch : '_';
    }
    return out.empty() ? std::string("_") : out;
}

std::map<std::string, std::string> condition_slugs(const std::vector<std::string>& names) {
    const std::set<std::string> unique(names.begin(), names.end());
    std::map<std::string, int> count;
    for (const std::string& n : unique) ++count[file_slug(n)];
    std::map<std::string, std::string> out;
    std::set<std::string> used;
    for (const std::string& n : unique) {
        const std::string slug = file_slug(n);
        if (count[slug] == 1) {
            out[n] = slug;
            used.insert(slug);
        }
    }
    for (const std::string& n : unique) {
        if (out.count(n)) continue;
        // The name's own hash: 8 hex digits, or more in the (2^-32) case that
        // they meet another file name.
        const std::string hash = store::sha256_hex(n);
        std::string slug;
        for (std::size_t digits = 8; digits <= hash.size(); digits += 8) {
            slug = fmt::format("{}-{}", file_slug(n), hash.substr(0, digits));
            if (!used.count(slug)) break;
        }
        out[n] = slug;
        used.insert(slug);
    }
    return out;
}

std::map<std::string, std::string> condition_slugs(const StudyResults& results) {
    std::vector<std::string> names;
    for (const ConditionInfo& c : results.conditions) names.push_back(c.condition);
    return condition_slugs(names);
}

std::optional<double> model_grey_luminance_cd_m2(const std::string& fit_json, double v) {
    // The display model the calibration holds (docs/calibration.md "fit_json"), read and
    // evaluated by the display library: grey drives all three channels, which add.
    try {
        const display::DisplayModel model = display::display_model_from_fit_json(fit_json, "");
        double sum = 0.0;
        for (int c = 0; c < 3; ++c) sum += model.channel_luminance_cd_m2(c, v);
        return std::isfinite(sum) ? std::optional<double>(sum) : std::nullopt;
    } catch (const atonlab::InputError&) {  // a fit_json the display model refuses (common/input_error.h)
        return std::nullopt;
    }
}

PlotResult make_figures(const fs::path& out_dir, const Dataset& data, const StudyResults& results,
                        const PlotOptions& options) {
    PlotResult out;
    fs::create_directories(out_dir / "figures");
    Drawer d(out_dir, options, out);
    const std::map<std::string, std::string> slugs = condition_slugs(results);
    for (const ConditionInfo& c : results.conditions) {
        const std::string& slug = slugs.at(c.condition);
        if (c.task != protocols::Task::Adjust) psychometric_figure(d, results, c, slug);
        tracks_figure(d, results, c, slug);
    }
    pse_figure(d, results);
    enhancement_figure(d, results);
    calibration_figures(d, data, out.problems);
    timing_figure(d, data, results);
    return out;
}

}  // namespace atonlab::analysis
