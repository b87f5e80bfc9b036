#pragma once
// What `atonlab analyze DIR` writes for a simulation folder (simulation.h;
// docs/analysis.md "The simulation report"): report.html (self-contained, as
// the study report), summary.json (every number of the report, the files left
// out with their reasons), simulation.csv (one row per design and condition),
// sessions.csv (one row per session and condition) and figures/ (gnuplot):
// the estimates around the truth, the interval widths, and coverage against
// trials per session.
#include <filesystem>
#include <string>
#include <vector>

#include "atonlab/analysis/plots.h"
#include "atonlab/analysis/simulation.h"

namespace atonlab::analysis {

struct SimulationReportContext {
    const SimulationResults* results = nullptr;
    const PlotResult* plots = nullptr;
    std::string software_version;
    std::string command_line;  ///< as run, for the report's header
    double total_s = 0.0;      ///< wall time of the whole command so far
};

/// The columns of simulation.csv and sessions.csv, in order.
const std::vector<std::string>& simulation_csv_columns();
const std::vector<std::string>& sessions_csv_columns();

/// Draws the simulation figures into out_dir/figures/ (plots.h's rules: no
/// gnuplot, no figures, and PlotResult says why).
PlotResult make_simulation_figures(const std::filesystem::path& out_dir, const SimulationResults& results,
                                   const PlotOptions& options = {});

void write_simulation_summary_json(const std::filesystem::path& file, const SimulationReportContext& ctx);
void write_simulation_csv(const std::filesystem::path& file, const SimulationResults& results);
void write_sessions_csv(const std::filesystem::path& file, const SimulationResults& results);
void write_simulation_report_html(const std::filesystem::path& file, const SimulationReportContext& ctx);

/// Writes summary.json, simulation.csv, sessions.csv and report.html into
/// out_dir (which must exist), each whole or not at all. Returns the paths.
std::vector<std::filesystem::path> write_simulation_report(const std::filesystem::path& out_dir,
                                                           const SimulationReportContext& ctx);

}  // namespace atonlab::analysis
