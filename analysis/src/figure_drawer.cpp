#include "figure_drawer.h"

#include <fmt/format.h>

#include <fstream>

namespace atonlab::analysis::detail {

namespace fs = std::filesystem;

std::string FigureDrawer::data(const std::string& name, const std::vector<std::vector<std::string>>& rows) {
    const fs::path p = tmp_.path() / name;
    std::ofstream out(p);
    for (const auto& row : rows) {
        for (std::size_t i = 0; i < row.size(); ++i) out << (i ? "\t" : "") << row[i];
        out << '\n';
    }
    return gp_quote(p.string());
}

bool FigureDrawer::draw(Figure f, const std::string& body) {
    if (result_.gnuplot_missing) return false;
    const fs::path png = fs::path("figures") / (f.id + ".png");
    const fs::path svg = fs::path("figures") / (f.id + ".svg");
    const fs::path script = tmp_.path() / (f.id + ".gp");
    {
        std::ofstream s(script);
        s << "set datafile separator '\\t'\n";
        s << fmt::format("set terminal pngcairo size {},{} noenhanced font 'DejaVu Sans,10' background '#ffffff'\n",
                         o_.width_px, o_.height_px);
        s << "set output " << gp_quote((out_dir_ / png).string()) << "\n" << body << "\nunset output\n";
        s << fmt::format("set terminal svg size {},{} noenhanced font 'DejaVu Sans,10' background '#ffffff'\n",
                         o_.width_px, o_.height_px);
        s << "set output " << gp_quote((out_dir_ / svg).string()) << "\n" << body << "\nunset output\n";
    }
    const detail::GnuplotRun run = detail::run_gnuplot(o_.gnuplot, script, tmp_.path());
    if (run.not_found) {
        result_.gnuplot_missing = true;
        result_.problems.push_back(
            fmt::format("gnuplot could not be started ('{}': {}), so the report has no figures; install the Debian "
                        "package gnuplot-nox (scripts/setup.sh does)",
                        o_.gnuplot, run.errors));
        return false;
    }
    std::error_code ec;
    const bool written = fs::file_size(out_dir_ / png, ec) > 0 && !ec && fs::file_size(out_dir_ / svg, ec) > 0 && !ec;
    if (run.exit_status != 0 || !written) {
        std::string first = run.errors;
        if (const auto nl = first.find_last_not_of("\n "); nl != std::string::npos) first.erase(nl + 1);
        result_.problems.push_back(fmt::format("figure {}: gnuplot failed (exit status {}): {}", f.id, run.exit_status,
                                               first.empty() ? "no output file" : first));
        fs::remove(out_dir_ / png, ec);
        fs::remove(out_dir_ / svg, ec);
        return false;
    }
    f.png = png;
    f.svg = svg;
    result_.figures.push_back(std::move(f));
    return true;
}

}  // namespace atonlab::analysis::detail
