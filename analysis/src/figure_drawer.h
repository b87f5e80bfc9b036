#pragma once
// One figure drawn by gnuplot (plots.h): the caller writes data files into a
// private temporary folder, then hands the plotting script's body to draw(),
// which renders it once with the pngcairo and once with the svg terminal into
// OUT/figures/ and checks gnuplot's exit status and output. Shared by the
// study report's figures (plots.cpp) and the simulation report's
// (simulation_plots.cpp).
#include <filesystem>
#include <string>
#include <vector>

#include "atonlab/analysis/plots.h"
#include "gnuplot.h"

namespace atonlab::analysis::detail {

class FigureDrawer {
public:
    FigureDrawer(const std::filesystem::path& out_dir, const PlotOptions& o, PlotResult& result)
        : out_dir_(out_dir), o_(o), result_(result), tmp_("atonlab-analyze-") {}

    const std::filesystem::path& tmp() const { return tmp_.path(); }

    /// A data file in the temporary folder (tab-separated), returned as a gnuplot literal.
    std::string data(const std::string& name, const std::vector<std::vector<std::string>>& rows);

    /// Draws `f` from `body` (the script without terminal and output); false
    /// when it was not drawn (the reason is in the PlotResult's problems).
    bool draw(Figure f, const std::string& body);

private:
    std::filesystem::path out_dir_;
    const PlotOptions& o_;
    PlotResult& result_;
    TempFolder tmp_;
};

}  // namespace atonlab::analysis::detail
