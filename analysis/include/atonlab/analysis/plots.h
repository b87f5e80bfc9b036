#pragma once
// The report's figures, drawn by gnuplot (a maintained plotting tool; Debian
// package gnuplot-nox): for each figure a data file and a script go into a
// private temporary folder, and `gnuplot SCRIPT` is run as a subprocess that
// writes the figure as PNG (pngcairo terminal) and SVG (svg terminal) into
// OUT/figures/. Its exit status and stderr are checked; the temporary folder is
// removed afterwards. The numbers plotted are computed here (fits, intervals),
// never by gnuplot.
//
// Without gnuplot (not installed, or --gnuplot names no program) no figure is
// drawn and PlotResult says why in one sentence; the report is still written.
#include <filesystem>
#include <string>
#include <vector>

#include <map>

#include "atonlab/analysis/dataset.h"
#include "atonlab/analysis/study_analysis.h"

namespace atonlab::analysis {

/// One figure of the report. Paths are relative to the output folder.
struct Figure {
    std::string id;         ///< "psychometric-L0.001-empirical", "pse", ...
    std::string kind;       ///< "psychometric", "tracks", "pse", "enhancement", "calibration", "timing", "snapshot"
    std::string condition;  ///< the condition it shows, if one
    std::string title;
    std::string caption;  ///< what it shows, one or two sentences
    std::filesystem::path png;
    std::filesystem::path svg;  ///< empty for a snapshot (a PNG only)
};

struct PlotOptions {
    std::string gnuplot = "gnuplot";  ///< the program, looked up in PATH
    int width_px = 800;
    int height_px = 560;
};

struct PlotResult {
    std::vector<Figure> figures;
    /// Empty when every figure was drawn; otherwise one sentence per problem
    /// (gnuplot missing, a figure gnuplot refused with its message).
    std::vector<std::string> problems;
    bool gnuplot_missing = false;
};

/// Draws every figure the results have data for into out_dir/figures/
/// (created). Throws std::runtime_error only when the folder cannot be written.
PlotResult make_figures(const std::filesystem::path& out_dir, const Dataset& data, const StudyResults& results,
                        const PlotOptions& options = {});

/// The file-name form of a name: letters, digits, '.', '-' and '_' kept,
/// anything else '_'.
std::string file_slug(const std::string& name);

/// Whether the frame-timing figure has anything to show: some session was
/// answered by a person (or by an observer of unknown kind, a CSV's), or some
/// frame was dropped. Sessions of the model or scripted observer alone run on
/// the virtual clock when headless: their timing is not the display's.
bool has_display_timing(const Dataset& data, const StudyResults& results);

/// The file-name form of each condition name, all distinct, for figures,
/// snapshots and the report's anchors: file_slug(name) where no other name
/// has the same slug; where two do ("a<b" and "a>b" are both "a_b"), the slug
/// plus "-" and the first 8 hex digits of the name's SHA-256, so a name keeps
/// its file name whatever other conditions a study has. Keyed by name.
std::map<std::string, std::string> condition_slugs(const std::vector<std::string>& names);
/// The same for a study's conditions (StudyResults::conditions).
std::map<std::string, std::string> condition_slugs(const StudyResults& results);

/// The display model's luminance of a grey drive level V in [0, 1] (all
/// channels at V), cd/m², from a calibration's fit_json (docs/analysis.md
/// "Display calibration"); std::nullopt when the model is not understood.
std::optional<double> model_grey_luminance_cd_m2(const std::string& fit_json, double drive);

}  // namespace atonlab::analysis
