#pragma once
// The bench's results: one row per knob setting, one point per light count,
// and how they are written (CSV, Markdown, gnuplot).
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "measure.h"

namespace atonlab::bench {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// One setting of one knob.
struct Row {
    std::string bench;        ///< the knob, e.g. "psf_size"
    std::string setting;      ///< e.g. "N=512"
    bool is_default = false;  ///< the setting the pipeline uses unless told otherwise
    Timing time;
    double error = kNaN;      ///< against the bench's reference (see metric)
    std::string metric;       ///< what error is, with its unit
    double codes = kNaN;      ///< largest display code difference (before dither), where measured
    double energy_pct = kNaN; ///< energy error of the lights (%), where measured
    std::string note;
    bool pareto = false;      ///< on the front of (time, error) within its bench
};

/// One frame time of the light-count scaling bench.
struct ScalePoint {
    std::string series;  ///< e.g. "visible, overlapping"
    int lights = 0;
    int drawn = 0;       ///< lights the frame drew (FrameStats)
    Timing time;
};

/// Least-squares line time = a + b · lights over a series (ms, ms per light).
struct Fit {
    double intercept_ms = kNaN, slope_ms = kNaN, r2 = kNaN;
    int points = 0;
};
Fit fit_line(const std::vector<ScalePoint>& points, const std::string& series);

/// Marks each bench's Pareto front (less time, less error): q dominates p when
/// its error is lower (by more than 0.1%) and its median time no higher, or its
/// error is no higher and its time lower by more than the timing noise (the
/// larger IQR, at least 2% of the slower). Rows without an error are left off.
void mark_pareto(std::vector<Row>& rows);

struct Machine {
    std::string label;     ///< --device-label, or the GL renderer
    std::string gl_vendor, gl_renderer, gl_version, gl_platform;
    bool software = false;
    std::string cpu, os;
    int cpu_cores = 0;
    double memory_gib = 0;
    std::string date, version, build;
    std::string load_start;  ///< /proc/loadavg when the bench started (a shared machine's noise)
    bool quick = false;
};
Machine describe_machine(const std::string& label, const std::string& vendor, const std::string& renderer,
                         const std::string& version, const std::string& platform, bool software, bool quick);

/// Every file the bench writes goes through here: whole or not at all
/// (common's AtomicFile); a failure is an InputError naming the file (`--out`).
void write_output(const std::string& path, const std::string& text);

void write_csv(const std::string& path, const std::vector<Row>& rows);
void write_scaling_csv(const std::string& path, const std::vector<ScalePoint>& points);
void write_machine(const std::string& path, const Machine& m);
/// bench.md: the machine, one table per knob, the defaults' verdicts, scaling.
void write_markdown(const std::string& path, const Machine& m, const std::vector<Row>& rows,
                    const std::vector<ScalePoint>& points, const std::vector<std::string>& scaling_notes);
/// pareto.png and scaling.png through gnuplot (data and scripts in dir/plot/).
/// Returns false (and writes the scripts only) when gnuplot is not installed.
bool write_plots(const std::string& dir, const std::vector<Row>& rows, const std::vector<ScalePoint>& points);

}  // namespace atonlab::bench
