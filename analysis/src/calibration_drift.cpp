// A display's calibration checks over time (calibration_drift.h).
#include "atonlab/analysis/calibration_drift.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>

#include "atonlab/store/error.h"
#include "atonlab/store/json.h"
#include "gnuplot.h"

namespace atonlab::analysis {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double number_or_nan(const nlohmann::json& j, std::string_view at) {
    return store::number_at(j, at).value_or(kNaN);
}

/// Seconds since 1970-01-01T00:00:00Z of an ISO 8601 stamp
/// (YYYY-MM-DD[THH:MM[:SS[.fff]]][Z], read as UTC); NaN when it is not one.
double epoch_seconds(const std::string& iso) {
    auto digits = [&](std::size_t at, std::size_t n) -> int {
        if (iso.size() < at + n) return -1;
        int v = 0;
        for (std::size_t i = at; i < at + n; ++i) {
            if (iso[i] < '0' || iso[i] > '9') return -1;
            v = v * 10 + (iso[i] - '0');
        }
        return v;
    };
    const int y = digits(0, 4), mo = digits(5, 2), d = digits(8, 2);
    if (y < 0 || mo < 0 || d < 0) return kNaN;
    const std::chrono::year_month_day ymd{std::chrono::year{y}, std::chrono::month{static_cast<unsigned>(mo)},
                                          std::chrono::day{static_cast<unsigned>(d)}};
    if (!ymd.ok()) return kNaN;
    double s = static_cast<double>(std::chrono::sys_seconds(std::chrono::sys_days(ymd)).time_since_epoch().count());
    if (iso.size() >= 16 && iso[10] == 'T') {
        const int h = digits(11, 2), mi = digits(14, 2);
        if (h >= 0 && mi >= 0) s += h * 3600.0 + mi * 60.0;
        if (iso.size() >= 19 && iso[16] == ':')
            if (const int sec = digits(17, 2); sec >= 0) s += sec;
    }
    return s;
}

std::string cell(double v, const char* format = "{:.4g}") {
    return std::isfinite(v) ? fmt::format(fmt::runtime(format), v) : std::string("-");
}

std::string num(double v) {
    return std::isfinite(v) ? fmt::format("{:.17g}", v) : std::string("NaN");
}

}  // namespace

std::optional<DriftPoint> drift_point(const store::CalibrationCheck& check) {
    try {
        const nlohmann::json j =
            store::parse_json(check.results_json, fmt::format("results_json of check {}", check.id.value));
        if (!store::number_at(j, "/tolerances/luminance_percent")) return std::nullopt;
        DriftPoint p;
        p.check_id = check.id.value;
        p.calibration_id = check.calibration.value;
        p.checked_at = check.checked_at;
        p.calibration_measured_at = store::string_at(j, "/calibration_measured_at").value_or("");
        p.passed = check.passed;
        for (const nlohmann::json& f : store::array_at(j, "/failed"))
            if (f.is_string()) p.failed.push_back(f.get<std::string>());
        // Black is the patch at code 0, white (the peak) the one at the largest code.
        p.peak_cd_m2 = p.peak_predicted_cd_m2 = p.black_cd_m2 = p.black_predicted_cd_m2 = kNaN;
        double white_code = -1.0;
        for (const nlohmann::json& patch : store::array_at(j, "/patches")) {
            const double code = number_or_nan(patch, "/code");
            if (code == 0.0) {
                p.black_cd_m2 = number_or_nan(patch, "/measured_cd_m2");
                p.black_predicted_cd_m2 = number_or_nan(patch, "/predicted_cd_m2");
            } else if (code > white_code) {
                white_code = code;
                p.peak_cd_m2 = number_or_nan(patch, "/measured_cd_m2");
                p.peak_predicted_cd_m2 = number_or_nan(patch, "/predicted_cd_m2");
            }
        }
        p.gamma_measured = number_or_nan(j, "/gamma_measured");
        p.gamma_predicted = number_or_nan(j, "/gamma_predicted");
        p.worst_error_percent = number_or_nan(j, "/values/luminance_percent");
        p.worst_patch = store::string_at(j, "/worst_patch").value_or("");
        p.tol_luminance_percent = number_or_nan(j, "/tolerances/luminance_percent");
        p.tol_black_cd_m2 = number_or_nan(j, "/tolerances/black_cd_m2");
        p.tol_peak_percent = number_or_nan(j, "/tolerances/peak_percent");
        p.tol_gamma = number_or_nan(j, "/tolerances/gamma");
        return p;
    } catch (const store::StoreError&) {
        return std::nullopt;
    }
}

std::vector<DriftPoint> display_drift(const store::Store& file, std::string_view display,
                                      std::vector<std::string>* problems) {
    std::vector<DriftPoint> out;
    for (const store::Calibration& c : file.calibrations(display))
        for (const store::CalibrationCheck& check : file.calibration_checks(c.id)) {
            if (auto p = drift_point(check))
                out.push_back(std::move(*p));
            else if (problems)
                problems->push_back(
                    fmt::format("{}: check {} of calibration {} (display \"{}\") has results the "
                                "drift table cannot read; it is left out",
                                file.path().string(), check.id.value, c.id.value, display));
        }
    std::sort(out.begin(), out.end(), [](const DriftPoint& a, const DriftPoint& b) {
        return a.checked_at != b.checked_at ? a.checked_at < b.checked_at : a.check_id < b.check_id;
    });
    return out;
}

std::string drift_table(const std::vector<DriftPoint>& points) {
    std::string out =
        fmt::format("  {:<20} {:>5} {:<6} {:>22} {:>24} {:>20} {:>20}\n", "checked", "cal", "result",
                    "peak cd/m² (pred ± %)", "black cd/m² (pred ± abs)", "gamma (pred ± abs)", "worst error % (tol)");
    for (const DriftPoint& p : points) {
        out += fmt::format("  {:<20} {:>5} {:<6} {:>22} {:>24} {:>20} {:>20}\n", p.checked_at.substr(0, 20),
                           p.calibration_id, p.passed ? "passed" : "FAILED",
                           fmt::format("{} ({} ± {}%)", cell(p.peak_cd_m2), cell(p.peak_predicted_cd_m2),
                                       cell(p.tol_peak_percent, "{:g}")),
                           fmt::format("{} ({} ± {})", cell(p.black_cd_m2), cell(p.black_predicted_cd_m2),
                                       cell(p.tol_black_cd_m2, "{:g}")),
                           fmt::format("{} ({} ± {})", cell(p.gamma_measured, "{:.3f}"),
                                       cell(p.gamma_predicted, "{:.3f}"), cell(p.tol_gamma, "{:g}")),
                           fmt::format("{} {} ({})", cell(p.worst_error_percent, "{:.2f}"), p.worst_patch,
                                       cell(p.tol_luminance_percent, "{:g}")));
    }
    return out;
}

std::vector<std::vector<std::string>> drift_data_rows(const std::vector<DriftPoint>& points) {
    std::vector<std::vector<std::string>> rows;
    for (const DriftPoint& p : points) {
        const double peak_band = p.peak_predicted_cd_m2 * p.tol_peak_percent / 100.0;
        const double t = epoch_seconds(p.checked_at);
        rows.push_back(
            {std::isfinite(t) ? fmt::format("{:.0f}", t) : std::string("NaN"), p.passed ? "1" : "0", num(p.peak_cd_m2),
             num(p.peak_predicted_cd_m2 - peak_band), num(p.peak_predicted_cd_m2 + peak_band), num(p.black_cd_m2),
             num(p.black_predicted_cd_m2 - p.tol_black_cd_m2), num(p.black_predicted_cd_m2 + p.tol_black_cd_m2),
             num(p.gamma_measured), num(p.gamma_predicted - p.tol_gamma), num(p.gamma_predicted + p.tol_gamma),
             num(p.worst_error_percent), num(p.tol_luminance_percent)});
    }
    return rows;
}

std::string drift_plot_body(const std::string& data, const std::vector<DriftPoint>& points, const std::string& title) {
    // One check has no span of dates: give the axis a day either side.
    double t0 = std::numeric_limits<double>::infinity(), t1 = -t0;
    for (const DriftPoint& p : points)
        if (const double t = epoch_seconds(p.checked_at); std::isfinite(t)) t0 = std::min(t0, t), t1 = std::max(t1, t);
    const double pad = std::isfinite(t0) ? std::max(86400.0, 0.05 * (t1 - t0)) : 86400.0;
    std::string b = "reset\nset datafile separator '\\t'\nset grid\nset xdata time\nset timefmt '%s'\n";
    b += "set format x '%Y-%m-%d'\nset xtics rotate by 20 right font ',8'\n";
    if (std::isfinite(t0)) b += fmt::format("set xrange ['{:.0f}':'{:.0f}']\n", t0 - pad, t1 + pad);
    // A few days: one tick a day (gnuplot's own would repeat each date at 6-hour ticks).
    if (std::isfinite(t0) && t1 - t0 + 2 * pad <= 20 * 86400.0) b += "set xtics 86400\n";
    b += "set multiplot layout 4,1 title " + detail::gp_quote(title) +
         "\nset lmargin 12\nset rmargin 14\n"
         "set key outside right top font ',8'\n";
    // Each panel: the tolerance band around the calibration's prediction
    // (filled where there are two or more checks, and as a bar at each check),
    // passed checks as dots, failed ones as crosses.
    auto panel = [&](const char* ylabel, int y, int lo, int hi, const char* band) {
        return fmt::format(
            "set ylabel '{}'\n"
            "plot {} using 1:{}:{} with filledcurves lc rgb '#c6dbef' title '{}', \\\n"
            "     {} using 1:{}:(0):(${}-${}) with vectors nohead lw 2 lc rgb '#6baed6' notitle, \\\n"
            "     {} using 1:((${}+${})/2) with lines dt 2 lc rgb '#6baed6' title 'predicted', \\\n"
            "     {} using 1:($2==1 ? ${} : NaN) with points pt 7 ps 1.2 lc rgb '#08519c' title 'passed', \\\n"
            "     {} using 1:($2==0 ? ${} : NaN) with points pt 2 ps 1.6 lw 2 lc rgb '#d62728' title 'failed'\n",
            ylabel, data, lo, hi, band, data, lo, hi, lo, data, lo, hi, data, y, data, y);
    };
    b += panel("peak (cd/m2)", 3, 4, 5, "tolerance");
    b += "unset key\n";
    b += panel("black (cd/m2)", 6, 7, 8, "tolerance");
    b += panel("effective gamma", 9, 10, 11, "tolerance");
    b += fmt::format(
        "set ylabel 'worst grey error (%)'\nset yrange [0:*]\n"
        "plot {} using 1:(0):13 with filledcurves lc rgb '#c6dbef' notitle, \\\n"
        "     {} using 1:(0):(0):13 with vectors nohead lw 2 lc rgb '#6baed6' notitle, \\\n"
        "     {} using 1:($2==1 ? $12 : NaN) with points pt 7 ps 1.2 lc rgb '#08519c' notitle, \\\n"
        "     {} using 1:($2==0 ? $12 : NaN) with points pt 2 ps 1.6 lw 2 lc rgb '#d62728' notitle\n"
        "unset multiplot\n",
        data, data, data, data);
    return b;
}

std::string plot_drift(const std::filesystem::path& out, const std::vector<DriftPoint>& points,
                       const std::string& title, const std::string& gnuplot) {
    if (points.empty()) return "there are no checks to plot";
    const std::string ext = out.extension().string();
    const char* terminal = ext == ".svg"   ? "svg size 900,900 dynamic font 'DejaVu Sans,11' background '#ffffff'"
                           : ext == ".png" ? "pngcairo size 900,900 font 'DejaVu Sans,10' background '#ffffff'"
                                           : nullptr;
    if (!terminal) return fmt::format("{}: a plot is written as .svg or .png, not '{}'", out.string(), ext);
    detail::TempFolder tmp("atonlab-drift-");
    const std::filesystem::path data = tmp.path() / "drift.tsv";
    {
        std::ofstream f(data);
        for (const auto& row : drift_data_rows(points)) {
            for (std::size_t i = 0; i < row.size(); ++i) f << (i ? "\t" : "") << row[i];
            f << '\n';
        }
    }
    const std::filesystem::path script = tmp.path() / "drift.gp";
    {
        // `reset` (the body's first command) keeps the terminal and the output.
        std::ofstream f(script);
        f << fmt::format("set terminal {} noenhanced\nset output {}\n", terminal, detail::gp_quote(out.string()))
          << drift_plot_body(detail::gp_quote(data.string()), points, title) << "unset output\n";
        if (!f) return fmt::format("cannot write the gnuplot script {}", script.string());
    }
    const detail::GnuplotRun run = detail::run_gnuplot(gnuplot, script, tmp.path());
    if (run.not_found) return "gnuplot is not installed (scripts/setup.sh installs gnuplot-nox)";
    std::error_code ec;
    if (run.exit_status != 0 || std::filesystem::file_size(out, ec) == 0 || ec) {
        std::string first = run.errors;
        if (const auto nl = first.find_last_not_of("\n "); nl != std::string::npos) first.erase(nl + 1);
        return fmt::format("gnuplot failed (exit status {}): {}", run.exit_status,
                           first.empty() ? "no output file" : first);
    }
    return {};
}

}  // namespace atonlab::analysis
