#include "calibration_check.h"

#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>

#include "atonlab/common/atomic_file.h"
#include "atonlab/store/json.h"

extern char** environ;

namespace atonlab::runner {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Least-squares slope of log10(L − L_black) on log10(level) over the lit
/// patches; NaN when a lit patch is not above black (its log is undefined).
double effective_gamma(const std::vector<double>& levels, const std::vector<double>& luminance, double black) {
    double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
    int n = 0;
    for (std::size_t i = 0; i < levels.size(); ++i) {
        const double dl = luminance[i] - black;
        if (!(dl > 0.0)) return kNaN;
        const double x = std::log10(levels[i]), y = std::log10(dl);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
        ++n;
    }
    if (n < 2) return kNaN;
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

bool within(double value, double tolerance) {
    return std::isfinite(value) && value <= tolerance;
}

}  // namespace

CheckOutcome evaluate_check(const display::DisplayModel& model, const std::vector<Patch>& patches,
                            const std::vector<PhotometerReading>& readings, const CheckTolerances& tol) {
    CheckOutcome o;
    std::vector<double> levels, measured, predicted;
    double black_measured = kNaN, black_predicted = kNaN;
    bool have_white = false;
    o.luminance_percent = 0.0;
    for (std::size_t i = 0; i < patches.size(); ++i) {
        CheckPatch c;
        c.patch = patches[i];
        c.measured = readings[i];
        c.predicted_cd_m2 = display::displayed_luminance_cd_m2(model, patches[i].rgb, Patch::bits);
        c.error_cd_m2 = c.measured.luminance_cd_m2 - c.predicted_cd_m2;
        c.error_percent = c.predicted_cd_m2 > 0.0 ? 100.0 * c.error_cd_m2 / c.predicted_cd_m2 : kNaN;
        if (c.patch.code == 0) {
            black_measured = c.measured.luminance_cd_m2;
            black_predicted = c.predicted_cd_m2;
            o.black_cd_m2 = std::abs(c.error_cd_m2);
        } else {
            const double e = std::abs(c.error_percent);
            if (!(e <= o.luminance_percent)) {  // NaN counts as the worst
                o.luminance_percent = e;
                o.worst_patch = c.patch.name;
            }
            levels.push_back(c.patch.level());
            measured.push_back(c.measured.luminance_cd_m2);
            predicted.push_back(c.predicted_cd_m2);
            if (c.patch.code == Patch::max_code) {
                o.peak_percent = e;
                have_white = true;
            }
        }
        o.patches.push_back(c);
    }
    if (!have_white) o.peak_percent = kNaN;
    if (std::isnan(black_measured)) o.black_cd_m2 = kNaN;
    o.gamma_measured = effective_gamma(levels, measured, black_measured);
    o.gamma_predicted = effective_gamma(levels, predicted, black_predicted);
    o.gamma = std::abs(o.gamma_measured - o.gamma_predicted);
    if (!within(o.luminance_percent, tol.luminance_percent)) o.failed.push_back("luminance_percent");
    if (!within(o.black_cd_m2, tol.black_cd_m2)) o.failed.push_back("black_cd_m2");
    if (!within(o.peak_percent, tol.peak_percent)) o.failed.push_back("peak_percent");
    if (!within(o.gamma, tol.gamma)) o.failed.push_back("gamma");
    return o;
}

std::string check_results_json(const CheckOutcome& o, const CheckTolerances& tol, const store::Calibration& cal) {
    using Json = nlohmann::ordered_json;
    Json patches = Json::array();
    for (const CheckPatch& c : o.patches) {
        Json patch{{"patch", c.patch.name},
                   {"code", c.patch.code},
                   {"bits", Patch::bits},
                   {"predicted_cd_m2", c.predicted_cd_m2},
                   {"measured_cd_m2", c.measured.luminance_cd_m2},
                   {"error_cd_m2", c.error_cd_m2},
                   {"error_percent", c.error_percent},
                   {"xyz_cd_m2", nullptr}};
        if (const auto& xyz = c.measured.xyz_cd_m2) patch["xyz_cd_m2"] = Json::array({xyz->x, xyz->y, xyz->z});
        // With --instrument: what the instrument said for the patch, raw.
        if (!c.measured.transcript.empty()) patch["transcript"] = c.measured.transcript;
        patches.push_back(std::move(patch));
    }
    const Json j{{"calibration_id", cal.id.value},
                 {"calibration_measured_at", cal.measured_at},
                 {"passed", o.passed()},
                 {"failed", o.failed},
                 {"tolerances",
                  {{"luminance_percent", tol.luminance_percent},
                   {"black_cd_m2", tol.black_cd_m2},
                   {"peak_percent", tol.peak_percent},
                   {"gamma", tol.gamma}}},
                 {"values",
                  {{"luminance_percent", o.luminance_percent},
                   {"black_cd_m2", o.black_cd_m2},
                   {"peak_percent", o.peak_percent},
                   {"gamma", o.gamma}}},
                 {"worst_patch", o.worst_patch},
                 {"gamma_measured", o.gamma_measured},
                 {"gamma_predicted", o.gamma_predicted},
                 {"patches", std::move(patches)}};
    return store::dump_json(j);
}

void print_check(std::FILE* out, const CheckOutcome& o, const CheckTolerances& tol) {
    std::fprintf(out, "  %-9s %5s %15s %15s %10s\n", "patch", "code", "predicted cd/m²", "measured cd/m²", "error");
    for (const CheckPatch& c : o.patches)
        std::fprintf(out, "  %-9s %5d %15.5g %15.5g %+9.2f%%\n", c.patch.name.c_str(), c.patch.code, c.predicted_cd_m2,
                     c.measured.luminance_cd_m2, c.error_percent);
    auto line = [&](const char* name, std::string value, std::string limit) {
        bool failed = false;
        for (const std::string& f : o.failed) failed = failed || f == name;
        std::fprintf(out, "  %-4s %-18s %-34s tolerance %s\n", failed ? "FAIL" : "ok", name, value.c_str(),
                     limit.c_str());
    };
    line("luminance_percent", fmt::format("{:.2f} % (worst: {})", o.luminance_percent, o.worst_patch),
         fmt::format("{} %", tol.luminance_percent));
    line("black_cd_m2", fmt::format("{:.4g} cd/m²", o.black_cd_m2), fmt::format("{} cd/m²", tol.black_cd_m2));
    line("peak_percent", fmt::format("{:.2f} %", o.peak_percent), fmt::format("{} %", tol.peak_percent));
    line("gamma",
         fmt::format("{:.3f} ({:.3f} measured, {:.3f} predicted)", o.gamma, o.gamma_measured, o.gamma_predicted),
         fmt::format("{}", tol.gamma));
}

std::string plot_check(const std::filesystem::path& out, const CheckOutcome& o, const CheckTolerances& tol,
                       const display::DisplayModel& model, const std::string& title) {
    const std::string ext = out.extension().string();
    const char* terminal = ext == ".svg"   ? "svg size 900,560 dynamic font 'DejaVu Sans,12'"
                           : ext == ".png" ? "pngcairo size 900,560 font 'DejaVu Sans,11'"
                                           : nullptr;
    if (!terminal) return fmt::format("{}: a plot is written as .svg or .png, not '{}'", out.string(), ext);
    // Top: the calibration's luminance over every code (log scale) and the readings.
    // Bottom: each grey patch's error in % inside the ±luminance_percent band (white
    // also against ±peak_percent); black's error is absolute, so it is written out.
    std::string model_rows;
    for (int code = 0; code <= Patch::max_code; ++code)
        model_rows +=
            fmt::format("{} {:.9g}\n", code, display::displayed_luminance_cd_m2(model, glm::ivec3(code), Patch::bits));
    std::string points, errors, black_note;
    for (const CheckPatch& c : o.patches) {
        points += fmt::format("{} {:.9g}\n", c.patch.code, c.measured.luminance_cd_m2);
        if (c.patch.code == 0)
            black_note = fmt::format(
                "band: luminance ±{} %, dashed: peak ±{} %; black {:.4g} cd/m² measured, {:.4g} predicted (±{})",
                tol.luminance_percent, tol.peak_percent, c.measured.luminance_cd_m2, c.predicted_cd_m2,
                tol.black_cd_m2);
        else
            errors += fmt::format("{} {:.9g}\n", c.patch.code, c.error_percent);
    }
    const double span = std::max({tol.luminance_percent, tol.peak_percent,
                                  std::isfinite(o.luminance_percent) ? o.luminance_percent : 0.0}) *
                        1.3;
    std::string quoted_title;
    for (char ch : title) quoted_title += ch == '"' ? '\'' : ch;
    // gnuplot writes the figure to a temporary sibling, renamed over `out` only
    // when gnuplot succeeds (common's AtomicFile): whole or not at all.
    std::optional<files::AtomicFile> figure;
    try {
        figure.emplace(out);
        figure->close_fd();
    } catch (const files::WriteError& e) {
        return e.what();
    }
    const std::string script = fmt::format(
        "set terminal {}\nset output \"{}\"\n"
        "$model << EOD\n{}EOD\n$points << EOD\n{}EOD\n$errors << EOD\n{}EOD\n"
        "set multiplot title \"{}\" noenhanced\n"
        "set lmargin 12\nset rmargin 4\nset grid\nset xrange [-5:260]\n"
        "set size 1,0.58\nset origin 0,0.40\nset logscale y\nset format x ''\nset key left top\n"
        "set ylabel \"luminance (cd/m²)\"\n"
        "plot $model using 1:2 with lines lw 2 lc rgb '#08519c' title 'calibration (predicted)', \\\n"
        "     $points using 1:2 with points pt 7 ps 1.3 lc rgb '#d62728' title 'measured'\n"
        "set size 1,0.40\nset origin 0,0\nunset logscale y\nset format x '%g'\n"
        "unset key\n"
        "set yrange [{}:{}]\nset xlabel \"code value (8 bits, R = G = B)\"\nset ylabel \"error (%)\"\n"
        "set label 1 \"{}\" at graph 0.02, graph 0.9 noenhanced font ',10'\n"
        "plot {} with filledcurves y1={} lc rgb '#c6dbef' title 'luminance tolerance ±{} %', \\\n"
        "     {} with lines dt 2 lc rgb '#6baed6' title 'peak tolerance ±{} %', \\\n"
        "     {} with lines dt 2 lc rgb '#6baed6' notitle, \\\n"
        "     0 with lines lc rgb '#08519c' notitle, \\\n"
        "     $errors using 1:2 with points pt 7 ps 1.3 lc rgb '#d62728' title 'measured − predicted'\n"
        "unset multiplot\n",
        terminal, figure->temp_path().string(), model_rows, points, errors, quoted_title, -span, span, black_note,
        tol.luminance_percent, -tol.luminance_percent, tol.luminance_percent, tol.peak_percent, tol.peak_percent,
        -tol.peak_percent);
    const std::filesystem::path script_path =
        std::filesystem::temp_directory_path() / fmt::format("atonlab-check-{}.gp", getpid());
    {
        std::ofstream f(script_path, std::ios::binary);
        f << script;
        if (!f) return fmt::format("cannot write the gnuplot script {}", script_path.string());
    }
    std::string program = "gnuplot", path_arg = script_path.string();
    char* argv[] = {program.data(), path_arg.data(), nullptr};
    pid_t pid = 0;
    const int rc = posix_spawnp(&pid, "gnuplot", nullptr, nullptr, argv, environ);
    std::string why;
    if (rc != 0) {
        why = "gnuplot is not installed (scripts/setup.sh installs gnuplot-nox)";
    } else {
        int status = 0;
        waitpid(pid, &status, 0);
        if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
            why = fmt::format("gnuplot failed on {} (exit status {})", script_path.string(),
                              WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    }
    if (!why.empty()) return why;
    std::filesystem::remove(script_path);
    try {
        figure->commit();
    } catch (const files::WriteError& e) {
        return e.what();
    }
    return why;
}

}  // namespace atonlab::runner
