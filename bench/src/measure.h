#pragma once
// Timing: the median of repeated runs after a warm-up, with the interquartile
// range and min–max, on a steady clock bracketed by glFinish (wall) and, for
// GPU stages, GL_TIME_ELAPSED timer queries.
#include <functional>
#include <vector>

namespace atonlab::bench {

struct Stats {
    double median = 0, q1 = 0, q3 = 0, min = 0, max = 0;
    int n = 0;
    double iqr() const { return q3 - q1; }
};
/// Quartiles by linear interpolation between order statistics (type 7).
Stats stats_of(std::vector<double> values);
/// The p-quantile (0 … 1) of the values, interpolated linearly between order statistics; NaN for none.
double quantile_of(std::vector<double> values, double p);

struct Timing {
    Stats wall;             ///< ms, steady clock, glFinish before and after
    Stats gpu;              ///< ms, GL timer queries (n = 0 when none)
    bool use_gpu = false;   ///< the primary time is the GPU's (when it has samples)
    const Stats& primary() const { return use_gpu && gpu.n > 0 ? gpu : wall; }
    const char* clock() const { return use_gpu && gpu.n > 0 ? "gpu-timer" : "cpu-wall"; }
};

struct TimeSpec {
    int warmup = 1;
    int repeats = 5;
    /// Wrap each run in a GL_TIME_ELAPSED query and make it the primary time.
    /// The function must not issue its own GL_TIME_ELAPSED queries then.
    bool gpu_timer = false;
};

/// Whether GL timer queries are believed (run_bench: not on a software
/// rasteriser, whose GL_TIME_ELAPSED measured 0 for compute dispatches and
/// nonsense for draws under Mesa 22.3 llvmpipe). Untrusted: no queries are
/// issued, GPU times reported by f are dropped, the wall clock is primary.
void set_gpu_timer_trusted(bool trusted);
bool gpu_timer_trusted();

/// Runs f warmup + repeats times. f returns the GPU time (ms) it measured
/// itself (e.g. GpuPsfGenerator::timings()), or a negative value for none;
/// those become Timing::gpu when spec.gpu_timer is off.
Timing measure(const std::function<double()>& f, const TimeSpec& spec);
/// The same for a function with nothing to report.
Timing measure_void(const std::function<void()>& f, const TimeSpec& spec);

/// Several settings timed in rounds (each round runs every function once), so
/// that a shared machine's load drifts over all of them alike instead of
/// favouring whichever ran in a quiet minute. One Timing per function.
std::vector<Timing> measure_interleaved(const std::vector<std::function<void()>>& fs, const TimeSpec& spec);

}  // namespace atonlab::bench
