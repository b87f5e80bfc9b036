// The simulation report's data files (simulation_report.h): summary.json,
// simulation.csv and sessions.csv; the page is simulation_html.cpp, the
// figures simulation_plots.cpp.
#include "atonlab/analysis/simulation_report.h"

#include <fmt/format.h>

#include "atonlab/common/atomic_file.h"
#include "atonlab/store/json.h"
#include "csv.h"

namespace atonlab::analysis {

namespace {

using Json = nlohmann::ordered_json;  // members in the order written here

Json or_null(const std::optional<double>& v) {
    return v ? Json(*v) : Json(nullptr);
}

Json interval(const std::optional<Interval>& ci) {
    return ci ? Json::array({ci->lower, ci->upper}) : Json(nullptr);
}

std::string cell(const std::optional<double>& v) {
    return v ? detail::number_text(*v) : std::string();
}

std::string row_of(const std::vector<std::string>& fields) {
    std::string out;
    for (std::size_t i = 0; i < fields.size(); ++i) out += (i ? "," : "") + csv_field(fields[i]);
    return out + "\n";
}

Json condition_json(const ConditionSummary& c) {
    Json j;
    j["design_index"] = c.design_index;
    j["design"] = c.design;
    j["condition"] = c.condition;
    j["unit"] = c.unit;
    j["true"] = Json{{"what", c.truth_what},
                     {"p", c.truth_p},
                     {"mean", or_null(c.truth)},
                     {"min", c.truth ? Json(c.truth_min) : Json(nullptr)},
                     {"max", c.truth ? Json(c.truth_max) : Json(nullptr)},
                     {"differs", c.truth_differs}};
    j["sessions"] = c.n_sessions;
    j["estimates"] = c.n_estimates;
    j["unreliable"] = c.n_unreliable;
    j["mean"] = or_null(c.mean);
    j["median"] = or_null(c.median);
    j["bias"] = or_null(c.bias);
    j["sd"] = or_null(c.sd);
    j["rmse"] = or_null(c.rmse);
    j["intervals"] = c.n_intervals;
    j["covered"] = c.n_covered;
    j["open_intervals"] = c.n_open;
    j["coverage"] = or_null(c.coverage);
    j["coverage_ci"] = interval(c.coverage_ci);
    j["width_median"] = or_null(c.width_median);
    j["widen_factor"] = or_null(c.widen_factor);
    j["calibrated_intervals"] = c.n_calibrated;
    j["calibrated_covered"] = c.n_calibrated_covered;
    j["calibrated_coverage"] = or_null(c.calibrated_coverage);
    j["calibrated_coverage_ci"] = interval(c.calibrated_coverage_ci);
    j["trials_per_session"] = Json{{"median", or_null(c.trials_median)}, {"p90", or_null(c.trials_p90)}};
    return j;
}

Json power_json(const PowerSummary& p) {
    Json j;
    j["design_index"] = p.design_index;
    j["design"] = p.design;
    j["condition_a"] = p.condition_a;
    j["condition_b"] = p.condition_b.empty() ? Json(nullptr) : Json(p.condition_b);
    j["what"] = p.what;
    j["effect_log10"] = p.effect;
    j["true_difference"] = or_null(p.true_difference);
    j["sd_difference"] = or_null(p.sd_difference);
    j["sessions"] = p.n_sessions;
    j["detected"] = p.n_detected;
    j["power"] = or_null(p.power);
    j["power_ci"] = interval(p.power_ci);
    return j;
}

}  // namespace

const std::vector<std::string>& simulation_csv_columns() {
    static const std::vector<std::string> c{"design_index",   "design",         "condition",      "unit",
                                            "true_what",      "true_p",         "true_value",     "true_min",
                                            "true_max",       "sessions",       "estimates",      "unreliable",
                                            "mean",           "median",         "bias",           "sd",
                                            "rmse",           "intervals",      "covered",        "coverage",
                                            "coverage_lower", "coverage_upper", "open_intervals", "width_median",
                                            "trials_median",  "trials_p90",     "widen_factor",   "calibrated_coverage",
                                            "calibrated_lower", "calibrated_upper"};
    return c;
}

const std::vector<std::string>& sessions_csv_columns() {
    static const std::vector<std::string> c{"design_index", "design",     "index",    "seed",  "file",  "observer",
                                            "condition",    "true_value", "estimate", "lower", "upper", "open",
                                            "covered",      "trials",     "reliable", "method"};
    return c;
}

void write_simulation_summary_json(const std::filesystem::path& file, const SimulationReportContext& ctx) {
    const SimulationResults& r = *ctx.results;
    Json j;
    j["format"] = "atonlab-simulation-report";
    j["version"] = 1;
    j["software_version"] = ctx.software_version;
    j["command_line"] = ctx.command_line;
    j["folder"] = r.folder.string();
    Json designs = Json::array();
    for (const ManifestDesign& d : r.manifest.designs)
        designs.push_back(Json{{"label", d.label}, {"overrides", d.overrides}});
    j["simulation"] = Json{{"protocol", r.manifest.protocol()},
                           {"protocol_sha256", r.manifest.protocol_sha256()},
                           {"designs", std::move(designs)}};
    j["options"] = Json{
        {"intervals", to_string(r.options.intervals)},
        {"bootstrap", r.options.intervals == IntervalMethod::Bootstrap ? Json(r.options.bootstrap) : Json(nullptr)},
        {"bootstrap_interval", r.options.intervals == IntervalMethod::Bootstrap ? Json("percentile") : Json(nullptr)},
        {"seed", r.options.seed},
        {"family", to_string(r.options.family)},
        {"level", r.options.ci_level},
        {"effect_log10", or_null(r.options.effect_log10)},
        {"effect_between", r.options.effect_between
                               ? Json::array({r.options.effect_between->first, r.options.effect_between->second})
                               : Json(nullptr)}};
    Json skipped = Json::array();
    for (const SkippedFile& s : r.skipped) skipped.push_back(Json{{"file", s.file}, {"reason", s.reason}});
    j["files"] = Json{{"found", r.files_found}, {"read", r.sessions.size()}, {"skipped", r.skipped.size()}};
    j["skipped"] = std::move(skipped);
    Json conditions = Json::array();
    for (const ConditionSummary& c : r.conditions) conditions.push_back(condition_json(c));
    j["conditions"] = std::move(conditions);
    Json power = Json::array();
    for (const PowerSummary& p : r.power) power.push_back(power_json(p));
    j["power"] = std::move(power);
    j["warnings"] = r.warnings;
    if (ctx.plots) j["figure_problems"] = ctx.plots->problems;
    j["timing"] =
        Json{{"read_s", r.read_s},
             {"files_per_s", r.read_s > 0.0 ? Json(static_cast<double>(r.files_found) / r.read_s) : Json(nullptr)},
             {"threads", r.options.n_threads},
             {"bootstrap_fits", r.bootstrap_fits},
             {"bootstrap_fits_per_s", r.bootstrap_fits > 0 && r.read_s > 0.0
                                          ? Json(static_cast<double>(r.bootstrap_fits) / r.read_s)
                                          : Json(nullptr)},
             {"total_s", ctx.total_s}};
    files::write_file_atomically(file, store::dump_json(j, 2) + "\n");
}

void write_simulation_csv(const std::filesystem::path& file, const SimulationResults& r) {
    std::string out = row_of(simulation_csv_columns());
    for (const ConditionSummary& c : r.conditions) {
        out += row_of({std::to_string(c.design_index),
                       c.design,
                       c.condition,
                       c.unit,
                       c.truth_what,
                       detail::number_text(c.truth_p),
                       cell(c.truth),
                       c.truth ? detail::number_text(c.truth_min) : "",
                       c.truth ? detail::number_text(c.truth_max) : "",
                       std::to_string(c.n_sessions),
                       std::to_string(c.n_estimates),
                       std::to_string(c.n_unreliable),
                       cell(c.mean),
                       cell(c.median),
                       cell(c.bias),
                       cell(c.sd),
                       cell(c.rmse),
                       std::to_string(c.n_intervals),
                       std::to_string(c.n_covered),
                       cell(c.coverage),
                       c.coverage_ci ? detail::number_text(c.coverage_ci->lower) : "",
                       c.coverage_ci ? detail::number_text(c.coverage_ci->upper) : "",
                       std::to_string(c.n_open),
                       cell(c.width_median),
                       cell(c.trials_median),
                       cell(c.trials_p90),
                       cell(c.widen_factor),
                       cell(c.calibrated_coverage),
                       c.calibrated_coverage_ci ? detail::number_text(c.calibrated_coverage_ci->lower) : "",
                       c.calibrated_coverage_ci ? detail::number_text(c.calibrated_coverage_ci->upper) : ""});
    }
    files::write_file_atomically(file, out);
}

void write_sessions_csv(const std::filesystem::path& file, const SimulationResults& r) {
    std::string out = row_of(sessions_csv_columns());
    for (const SessionSummary& s : r.sessions) {
        const std::string design = static_cast<std::size_t>(s.design_index) < r.manifest.designs.size()
                                       ? r.manifest.designs[static_cast<std::size_t>(s.design_index)].label
                                       : std::string();
        for (const SessionEstimate& e : s.conditions) {
            const bool covered = e.ci && e.truth && e.ci->contains(*e.truth);
            out += row_of({std::to_string(s.design_index), design, std::to_string(s.index), std::to_string(s.seed),
                           s.file, s.observer, e.condition, cell(e.truth), cell(e.estimate),
                           e.ci ? detail::number_text(e.ci->lower) : "", e.ci ? detail::number_text(e.ci->upper) : "",
                           e.ci ? (e.ci_open ? "1" : "0") : "", e.ci && e.truth ? (covered ? "1" : "0") : "",
                           std::to_string(e.n_trials), e.reliable ? "1" : "0", e.method});
        }
    }
    files::write_file_atomically(file, out);
}

std::vector<std::filesystem::path> write_simulation_report(const std::filesystem::path& out_dir,
                                                           const SimulationReportContext& ctx) {
    std::vector<std::filesystem::path> files{out_dir / "simulation.csv", out_dir / "sessions.csv",
                                             out_dir / "summary.json", out_dir / "report.html"};
    write_simulation_csv(files[0], *ctx.results);
    write_sessions_csv(files[1], *ctx.results);
    write_simulation_summary_json(files[2], ctx);
    write_simulation_report_html(files[3], ctx);
    return files;
}

}  // namespace atonlab::analysis
