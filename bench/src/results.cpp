#include "results.h"

#include <fmt/format.h>
#include <sys/utsname.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include "atonlab/common/atomic_file.h"
#include "atonlab/stimuli/error.h"

namespace atonlab::bench {

namespace {

std::string csv_text(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"') out += '"';
        out += c;
    }
    return out + "\"";
}

std::string num(double v, const char* spec = "{:.6g}") {
    return std::isnan(v) ? std::string() : fmt::format(fmt::runtime(spec), v);
}

std::string ms(double v) {
    if (std::isnan(v)) return "";
    if (v >= 100) return fmt::format("{:.0f}", v);
    if (v >= 10) return fmt::format("{:.1f}", v);
    if (v >= 1) return fmt::format("{:.2f}", v);
    return fmt::format("{:.3g}", v);
}

// The value of the first line of `file` that starts with `key`, after its
// separator (':' in /proc files, '=' in os-release).
std::string first_line_after(const std::string& file, const std::string& key, char separator = ':') {
    std::ifstream in(file);
    std::string line;
    while (std::getline(in, line))
        if (line.rfind(key, 0) == 0) {
            const auto at = line.find(separator);
            if (at == std::string::npos) continue;
            std::string v = line.substr(at + 1);
            v.erase(0, v.find_first_not_of(" \t"));
            return v;
        }
    return "";
}

std::string load_average() {
    std::ifstream in("/proc/loadavg");
    double one = 0, five = 0, fifteen = 0;
    if (!(in >> one >> five >> fifteen)) return "";
    return fmt::format("{:.2f} {:.2f} {:.2f}", one, five, fifteen);
}

// Benches in first-appearance order.
std::vector<std::string> bench_order(const std::vector<Row>& rows) {
    std::vector<std::string> order;
    for (const Row& r : rows)
        if (std::find(order.begin(), order.end(), r.bench) == order.end()) order.push_back(r.bench);
    return order;
}

std::vector<std::string> series_order(const std::vector<ScalePoint>& points) {
    std::vector<std::string> order;
    for (const ScalePoint& p : points)
        if (std::find(order.begin(), order.end(), p.series) == order.end()) order.push_back(p.series);
    return order;
}

}  // namespace

void write_output(const std::string& path, const std::string& text) {
    try {
        files::write_file_atomically(path, text);
    } catch (const files::WriteError& e) {
        throw InputError(SourceLocation{path, 0, 0, "--out"}, fmt::format("cannot write {}: {}.", path, e.reason()));
    }
}

Fit fit_line(const std::vector<ScalePoint>& points, const std::string& series) {
    double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
    for (const ScalePoint& p : points) {
        if (p.series != series) continue;
        const double x = p.lights, y = p.time.primary().median;
        n += 1;
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
        syy += y * y;
    }
    Fit f;
    f.points = static_cast<int>(n);
    const double det = n * sxx - sx * sx;
    if (n < 2 || !(det > 0)) return f;
    f.slope_ms = (n * sxy - sx * sy) / det;
    f.intercept_ms = (sy - f.slope_ms * sx) / n;
    const double ss_tot = syy - sy * sy / n;
    double ss_res = 0;
    for (const ScalePoint& p : points)
        if (p.series == series) {
            const double r = p.time.primary().median - (f.intercept_ms + f.slope_ms * p.lights);
            ss_res += r * r;
        }
    f.r2 = ss_tot > 0 ? 1.0 - ss_res / ss_tot : 1.0;
    return f;
}

void mark_pareto(std::vector<Row>& rows) {
    for (Row& p : rows) {
        p.pareto = false;
        if (std::isnan(p.error)) continue;
        bool dominated = false;
        for (const Row& q : rows) {
            if (&q == &p || q.bench != p.bench || std::isnan(q.error)) continue;
            const Stats &tp = p.time.primary(), &tq = q.time.primary();
            const double noise = std::max({tp.iqr(), tq.iqr(), 0.02 * std::max(tp.median, tq.median)});
            const double tiny = 1e-3 * std::max(p.error, q.error);  // errors equal to 0.1% are equal
            const bool better_error = q.error < p.error - tiny;
            const bool no_worse_error = q.error <= p.error + tiny;
            // Lower error needs no more time; equal error needs less time beyond the noise.
            if ((better_error && tq.median <= tp.median) || (no_worse_error && tq.median < tp.median - noise)) {
                dominated = true;
                break;
            }
        }
        p.pareto = !dominated;
    }
}

Machine describe_machine(const std::string& label, const std::string& vendor, const std::string& renderer,
                         const std::string& version, const std::string& platform, bool software, bool quick) {
    Machine m;
    m.label = label.empty() ? renderer : label;
    m.gl_vendor = vendor;
    m.gl_renderer = renderer;
    m.gl_version = version;
    m.gl_platform = platform;
    m.software = software;
    m.cpu = first_line_after("/proc/cpuinfo", "model name");
    m.cpu_cores = static_cast<int>(std::thread::hardware_concurrency());
    const std::string mem = first_line_after("/proc/meminfo", "MemTotal");
    if (!mem.empty()) m.memory_gib = std::strtod(mem.c_str(), nullptr) / (1024.0 * 1024.0);
    utsname u{};
    if (uname(&u) == 0) m.os = fmt::format("{} {} {}", u.sysname, u.release, u.machine);
    const std::string pretty = first_line_after("/etc/os-release", "PRETTY_NAME", '=');
    if (!pretty.empty()) {
        std::string p = pretty;
        p.erase(std::remove(p.begin(), p.end(), '"'), p.end());
        m.os = p + ", " + m.os;
    }
    const std::time_t now = std::time(nullptr);
    char buf[64];
    std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
    m.date = buf;
    m.version = ATONLAB_VERSION;
    m.build = ATONLAB_BUILD_TYPE;
    m.quick = quick;
    m.load_start = load_average();
    return m;
}

void write_csv(const std::string& path, const std::vector<Row>& rows) {
    std::ostringstream out;
    out << "bench,setting,default,time_ms,time_q1_ms,time_q3_ms,time_min_ms,time_max_ms,repeats,clock,"
           "wall_ms,gpu_ms,error,metric,max_code_diff,energy_error_pct,pareto,note\n";
    for (const Row& r : rows) {
        const Stats& t = r.time.primary();
        out << csv_text(r.bench) << ',' << csv_text(r.setting) << ',' << (r.is_default ? 1 : 0) << ','
            << num(t.median) << ',' << num(t.q1) << ',' << num(t.q3) << ',' << num(t.min) << ',' << num(t.max) << ','
            << t.n << ',' << r.time.clock() << ',' << num(r.time.wall.median) << ','
            << (r.time.gpu.n > 0 ? num(r.time.gpu.median) : std::string()) << ',' << num(r.error) << ','
            << csv_text(r.metric) << ',' << num(r.codes) << ',' << num(r.energy_pct) << ',' << (r.pareto ? 1 : 0)
            << ',' << csv_text(r.note) << '\n';
    }
    write_output(path, out.str());
}

void write_scaling_csv(const std::string& path, const std::vector<ScalePoint>& points) {
    std::ostringstream out;
    out << "series,lights,drawn,time_ms,time_q1_ms,time_q3_ms,time_min_ms,time_max_ms,repeats,clock,wall_ms\n";
    for (const ScalePoint& p : points) {
        const Stats& t = p.time.primary();
        out << csv_text(p.series) << ',' << p.lights << ',' << p.drawn << ',' << num(t.median) << ',' << num(t.q1)
            << ',' << num(t.q3) << ',' << num(t.min) << ',' << num(t.max) << ',' << t.n << ',' << p.time.clock()
            << ',' << num(p.time.wall.median) << '\n';
    }
    write_output(path, out.str());
}

void write_machine(const std::string& path, const Machine& m) {
    std::ostringstream out;
    out << "label: " << m.label << "\n"
        << "gl_renderer: " << m.gl_renderer << "\n"
        << "gl_vendor: " << m.gl_vendor << "\n"
        << "gl_version: " << m.gl_version << "\n"
        << "gl_platform: " << m.gl_platform << (m.software ? " (software rasteriser)" : "") << "\n"
        << "cpu: " << m.cpu << "\n"
        << "cpu_cores: " << m.cpu_cores << "\n"
        << fmt::format("memory_gib: {:.1f}\n", m.memory_gib) << "os: " << m.os << "\n"
        << "date: " << m.date << "\n"
        << "atonlab: " << m.version << " (" << m.build << ")\n"
        << "load_average_1_5_15min: " << m.load_start << " (at the start), " << load_average() << " (at the end)\n"
        << "form: " << (m.quick ? "quick" : "full") << "\n";
    write_output(path, out.str());
}

void write_markdown(const std::string& path, const Machine& m, const std::vector<Row>& rows,
                    const std::vector<ScalePoint>& points, const std::vector<std::string>& scaling_notes) {
    std::ostringstream out;
    out << "# atonlab bench: run time against error\n\n"
        << "Machine: **" << m.label << "** — GL `" << m.gl_renderer << "`, " << m.gl_version << " (" << m.gl_platform
        << (m.software ? ", software rasteriser" : "") << "); CPU " << m.cpu << ", " << m.cpu_cores << " cores, "
        << fmt::format("{:.1f}", m.memory_gib) << " GiB; " << m.os << ". atonlab " << m.version << " (" << m.build
        << "), " << m.date << ", " << (m.quick ? "**quick** form" : "full form") << "; load average "
        << m.load_start << " at the start, " << load_average() << " at the end (1, 5, 15 min).\n\n"
        << "Times are medians of repeated runs after a warm-up (IQR and min–max beside them); `gpu-timer` is "
           "GL_TIME_ELAPSED, `cpu-wall` a steady clock between glFinish calls. Errors are against each bench's "
           "double-precision reference (docs/bench.md). ● marks the Pareto front of time against error within a "
           "bench; **bold** is the default.\n\n";
    for (const std::string& b : bench_order(rows)) {
        out << "## " << b << "\n\n";
        std::string metric;
        for (const Row& r : rows)
            if (r.bench == b && !r.metric.empty()) metric = r.metric;
        out << "Error: " << metric << ".\n\n";
        out << "| setting | time (ms) | IQR | min–max | clock | error | max Δcode | energy % | front | note |\n"
            << "|---|---:|---:|---|---|---:|---:|---:|:-:|---|\n";
        for (const Row& r : rows) {
            if (r.bench != b) continue;
            const Stats& t = r.time.primary();
            const std::string name = r.is_default ? "**" + r.setting + "** (default)" : r.setting;
            out << "| " << name << " | " << ms(t.median) << " | " << ms(t.iqr()) << " | " << ms(t.min) << "–"
                << ms(t.max) << " | " << r.time.clock() << " | " << num(r.error, "{:.3g}") << " | "
                << num(r.codes, "{:.3g}") << " | " << num(r.energy_pct, "{:.3g}") << " | " << (r.pareto ? "●" : "")
                << " | " << r.note << " |\n";
        }
        out << "\n";
    }
    out << "## Defaults on the front\n\n| bench | default | on the Pareto front |\n|---|---|---|\n";
    for (const std::string& b : bench_order(rows))
        for (const Row& r : rows)
            if (r.bench == b && r.is_default)
                out << "| " << b << " | " << r.setting << " | "
                    << (std::isnan(r.error) ? "no error measured" : r.pareto ? "yes" : "**no**") << " |\n";
    out << "\n";
    if (!points.empty()) {
        out << "## Frame time against the number of lights (K2012 table 6.2 scene)\n\n"
            << "| series | lights | drawn | time (ms) | IQR | min–max | clock |\n|---|---:|---:|---:|---:|---|---|\n";
        for (const ScalePoint& p : points) {
            const Stats& t = p.time.primary();
            out << "| " << p.series << " | " << p.lights << " | " << p.drawn << " | " << ms(t.median) << " | "
                << ms(t.iqr()) << " | " << ms(t.min) << "–" << ms(t.max) << " | " << p.time.clock() << " |\n";
        }
        out << "\n| series | ms per light (least squares) | intercept (ms) | R² | points |\n|---|---:|---:|---:|---:|\n";
        for (const std::string& s : series_order(points)) {
            const Fit f = fit_line(points, s);
            out << "| " << s << " | " << num(f.slope_ms, "{:.4g}") << " | " << num(f.intercept_ms, "{:.4g}") << " | "
                << num(f.r2, "{:.4f}") << " | " << f.points << " |\n";
        }
        out << "\n";
    }
    for (const std::string& n : scaling_notes) out << "- " << n << "\n";
    write_output(path, out.str());
}

bool write_plots(const std::string& dir, const std::vector<Row>& rows, const std::vector<ScalePoint>& points) {
    namespace fs = std::filesystem;
    const fs::path plot = fs::path(dir) / "plot";
    fs::create_directories(plot);
    const std::vector<std::string> benches = bench_order(rows);
    std::vector<std::string> plotted;
    for (const std::string& b : benches) {
        double min_positive = 0;
        int n = 0;
        for (const Row& r : rows)
            if (r.bench == b && !std::isnan(r.error)) {
                ++n;
                if (r.error > 0 && (min_positive == 0 || r.error < min_positive)) min_positive = r.error;
            }
        if (n == 0) continue;
        plotted.push_back(b);
        // Exact settings (error 0) sit a decade below the smallest error, labelled "exact".
        const double floor_err = min_positive > 0 ? min_positive / 10 : 1e-9;
        std::ostringstream all, front;
        all << "# error time_ms is_default label (error 0 drawn at " << floor_err << ")\n";
        std::vector<const Row*> sorted;
        for (const Row& r : rows)
            if (r.bench == b && !std::isnan(r.error)) sorted.push_back(&r);
        std::sort(sorted.begin(), sorted.end(), [](const Row* a, const Row* c) { return a->error < c->error; });
        for (const Row* r : sorted) {
            const double e = r->error > 0 ? r->error : floor_err;
            const std::string label = r->error > 0 ? r->setting : r->setting + " (exact)";
            all << fmt::format("{:.6g} {:.6g} {} \"{}\"\n", e, r->time.primary().median, r->is_default ? 1 : 0, label);
            if (r->pareto) front << fmt::format("{:.6g} {:.6g}\n", e, r->time.primary().median);
        }
        write_output((plot / (b + ".dat")).string(), all.str());
        write_output((plot / (b + "-front.dat")).string(), front.str());
    }
    const int cols = 3, nrows = std::max(1, static_cast<int>((plotted.size() + cols - 1) / cols));
    {
        std::ostringstream gp;
        gp << "# Time against error per knob, Pareto front as a line, the default as a red star.\n"
           << fmt::format("set terminal pngcairo size {},{} font 'sans,9' noenhanced\n", 520 * cols, 420 * nrows)
           << "set output 'pareto.png'\n"
           << fmt::format("set multiplot layout {},{}\n", nrows, cols)
           << "set logscale xy\nset grid\nset key off\nset format x '%.0e'\n"
           << "set xlabel 'error'\nset ylabel 'time (ms)'\n";
        for (const std::string& b : plotted) {
            std::string metric;
            for (const Row& r : rows)
                if (r.bench == b && !r.metric.empty()) metric = r.metric;
            const std::string d = "plot/" + b + ".dat", f = "plot/" + b + "-front.dat";
            gp << "set title '" << b << "'\nset xlabel '" << metric << "' font 'sans,7'\n"
               << "plot '" << d << "' using 1:2 with points pt 7 ps 1 lc rgb '#777777', \\\n"
               << "     '" << f << "' using 1:2 with linespoints lw 2 pt 6 ps 1.6 lc rgb '#1f77b4', \\\n"
               << "     '" << d << "' using 1:($3 > 0 ? $2 : 1/0) with points pt 3 ps 2.5 lc rgb '#d62728', \\\n"
               << "     '" << d << "' using 1:2:4 with labels offset 0.8,0.6 left font 'sans,7'\n";
        }
        gp << "unset multiplot\n";
        write_output((plot / "pareto.gp").string(), gp.str());
    }
    if (!points.empty()) {
        std::ostringstream gp;
        gp << "# Frame time against the number of lights, per series.\n"
           << "set terminal pngcairo size 900,600 font 'sans,10' noenhanced\n"
           << "set output 'scaling.png'\n"
           << "set logscale xy\nset grid\nset key top left\nset xlabel 'lights'\nset ylabel 'frame time (ms)'\n"
           << "set xrange [0.35:20000]\nset xtics ('0' 0.5, '1' 1, '10' 10, '100' 100, '1000' 1000, '10000' 10000)\n"
           << "set title 'K2012 table 6.2 scene: frame time against the number of lights'\nplot ";
        bool first = true;
        for (const std::string& s : series_order(points)) {
            std::string file = s;
            for (char& c : file)
                if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
            std::ostringstream d;
            for (const ScalePoint& p : points)
                if (p.series == s)  // 0 lights at x = 0.5 on the log axis
                    d << (p.lights > 0 ? p.lights : 0.5) << ' ' << p.time.primary().median << ' '
                      << p.time.primary().min << ' ' << p.time.primary().max << '\n';
            write_output((plot / ("scaling-" + file + ".dat")).string(), d.str());
            gp << (first ? "" : ", \\\n     ") << "'plot/scaling-" << file << ".dat"
               << "' using 1:2:3:4 with yerrorlines title '" << s << "'";
            first = false;
        }
        gp << "\n";
        write_output((plot / "scaling.gp").string(), gp.str());
    }
    // Paths in the scripts are relative to dir, so the results can be moved and re-plotted.
    if (std::system("command -v gnuplot > /dev/null 2>&1") != 0) return false;
    const std::string cd = "cd '" + fs::absolute(dir).string() + "' && gnuplot ";
    bool ok = std::system((cd + "plot/pareto.gp 2> plot/gnuplot.log").c_str()) == 0;
    if (!points.empty()) ok = std::system((cd + "plot/scaling.gp 2>> plot/gnuplot.log").c_str()) == 0 && ok;
    return ok;
}

}  // namespace atonlab::bench
