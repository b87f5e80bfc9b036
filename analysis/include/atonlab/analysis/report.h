#pragma once
// What `atonlab analyze` writes into its output folder (docs/analysis.md
// "Outputs"): report.html (self-contained: styles inline, figures embedded as
// base64 PNG, no external reference), summary.json (every number of the
// report; JSON has no NaN, so a value that cannot be given is null with a
// reason), fits.csv (one row per estimate), trials.csv (dataset.h,
// write_trials_csv) and the figures (plots.h).
#include <filesystem>
#include <string>
#include <vector>

#include "atonlab/analysis/dataset.h"
#include "atonlab/analysis/plots.h"
#include "atonlab/analysis/study_analysis.h"

namespace atonlab::analysis {

/// A condition's stimulus as rendered, made into a PNG by the caller (the
/// runner converts the stored EXR with the stimuli library's CPU tone mapper:
/// analysis/ has no GL and no stimuli dependency).
struct SnapshotImage {
    std::string condition;
    std::string session;
    std::filesystem::path png;  ///< relative to the output folder
    std::string caption;
};

struct ReportContext {
    const Dataset* data = nullptr;
    const StudyResults* results = nullptr;
    const PlotResult* plots = nullptr;
    std::vector<SnapshotImage> snapshots;
    std::vector<std::string> problems;  ///< beyond plots->problems: snapshots that could not be made, ...
    std::string software_version;
    std::string command_line;  ///< as run, for the report's header
};

/// The columns of fits.csv, in order.
const std::vector<std::string>& fits_csv_columns();

void write_summary_json(const std::filesystem::path& file, const ReportContext& ctx);
void write_fits_csv(const std::filesystem::path& file, const StudyResults& results);
void write_report_html(const std::filesystem::path& file, const ReportContext& ctx);

/// Writes report.html, summary.json, fits.csv and trials.csv into out_dir
/// (which must exist), each through a temporary file renamed into place.
/// Returns the paths written. Throws std::runtime_error when one cannot be written.
std::vector<std::filesystem::path> write_report(const std::filesystem::path& out_dir, const ReportContext& ctx);

/// RFC 4648 base64 of bytes (the report's embedded images).
std::string base64(const std::string& bytes);

}  // namespace atonlab::analysis
