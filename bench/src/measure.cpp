#include "measure.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "atonlab/stimuli/gl/objects.h"

namespace atonlab::bench {

namespace {

/// The p-quantile (0 … 1) of sorted values, interpolated linearly between order statistics.
double quantile_sorted(const std::vector<double>& v, double p) {
    const double h = p * static_cast<double>(v.size() - 1);
    const auto lo = static_cast<std::size_t>(std::floor(h));
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (h - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

}  // namespace

double quantile_of(std::vector<double> v, double p) {
    if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
    std::sort(v.begin(), v.end());
    return quantile_sorted(v, p);
}

Stats stats_of(std::vector<double> v) {
    Stats s;
    s.n = static_cast<int>(v.size());
    if (v.empty()) return s;
    std::sort(v.begin(), v.end());
    s.min = v.front();
    s.max = v.back();
    s.median = quantile_sorted(v, 0.5);
    s.q1 = quantile_sorted(v, 0.25);
    s.q3 = quantile_sorted(v, 0.75);
    return s;
}

namespace {
bool g_gpu_timer_trusted = true;
}

void set_gpu_timer_trusted(bool trusted) {
    g_gpu_timer_trusted = trusted;
}
bool gpu_timer_trusted() {
    return g_gpu_timer_trusted;
}

Timing measure(const std::function<double()>& f, const TimeSpec& requested) {
    using Clock = std::chrono::steady_clock;
    TimeSpec spec = requested;
    spec.gpu_timer = spec.gpu_timer && g_gpu_timer_trusted;
    gl::GpuTimer timer;
    if (spec.gpu_timer) timer = gl::GpuTimer::create();
    std::vector<double> wall, gpu;
    for (int i = 0; i < spec.warmup + spec.repeats; ++i) {
        glFinish();
        const auto t0 = Clock::now();
        if (spec.gpu_timer) timer.begin();
        const double own = f();
        if (spec.gpu_timer) timer.end();
        glFinish();
        const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        if (i < spec.warmup) continue;
        wall.push_back(ms);
        if (spec.gpu_timer) {
            if (auto g = timer.elapsed_ms()) gpu.push_back(*g);
        } else if (own >= 0 && g_gpu_timer_trusted) {
            gpu.push_back(own);
        }
    }
    Timing t;
    t.wall = stats_of(wall);
    t.gpu = stats_of(gpu);
    // A GPU time longer than the wall clock around it (plus 1 ms) is not a time.
    if (t.gpu.n > 0 && t.gpu.median > t.wall.max + 1.0) t.gpu = Stats{};
    t.use_gpu = spec.gpu_timer;
    return t;
}

std::vector<Timing> measure_interleaved(const std::vector<std::function<void()>>& fs, const TimeSpec& requested) {
    using Clock = std::chrono::steady_clock;
    TimeSpec spec = requested;
    spec.gpu_timer = spec.gpu_timer && g_gpu_timer_trusted;
    gl::GpuTimer timer;
    if (spec.gpu_timer) timer = gl::GpuTimer::create();
    std::vector<std::vector<double>> wall(fs.size()), gpu(fs.size());
    for (int round = 0; round < spec.warmup + spec.repeats; ++round)
        for (std::size_t k = 0; k < fs.size(); ++k) {
            glFinish();
            const auto t0 = Clock::now();
            if (spec.gpu_timer) timer.begin();
            fs[k]();
            if (spec.gpu_timer) timer.end();
            glFinish();
            const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
            if (round < spec.warmup) continue;
            wall[k].push_back(ms);
            if (spec.gpu_timer)
                if (auto g = timer.elapsed_ms()) gpu[k].push_back(*g);
        }
    std::vector<Timing> out(fs.size());
    for (std::size_t k = 0; k < fs.size(); ++k) {
        out[k].wall = stats_of(wall[k]);
        out[k].gpu = stats_of(gpu[k]);
        if (out[k].gpu.n > 0 && out[k].gpu.median > out[k].wall.max + 1.0) out[k].gpu = Stats{};
        out[k].use_gpu = spec.gpu_timer;
    }
    return out;
}

Timing measure_void(const std::function<void()>& f, const TimeSpec& spec) {
    return measure(
        [&f] {
            f();
            return -1.0;
        },
        spec);
}

}  // namespace atonlab::bench
