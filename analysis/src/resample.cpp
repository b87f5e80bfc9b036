// Percentiles and the resample loop shared by every bootstrap (resample.h).
#include "atonlab/analysis/resample.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>

namespace atonlab::analysis {

std::optional<double> sorted_quantile(std::span<const double> sorted, double p) noexcept {
    if (sorted.empty() || !std::isfinite(p)) return std::nullopt;
    const double n = static_cast<double>(sorted.size());
    // Hyndman & Fan (1996) type 6: position h = (n + 1) p, 1-based.
    const double h = (n + 1.0) * p;
    if (h <= 1.0) return sorted.front();
    if (h >= n) return sorted.back();
    const double lo = std::floor(h);
    const auto i = static_cast<std::size_t>(lo) - 1;  // 0-based index of order statistic floor(h)
    const double frac = h - lo;
    return sorted[i] + frac * (sorted[i + 1] - sorted[i]);
}

std::optional<Interval> percentile_interval(std::vector<double> samples, double level) noexcept {
    if (!(level > 0.0 && level < 1.0)) return std::nullopt;
    std::erase_if(samples, [](double v) { return !std::isfinite(v); });
    if (samples.size() < 2) return std::nullopt;
    std::sort(samples.begin(), samples.end());
    const auto lo = sorted_quantile(samples, 0.5 * (1.0 - level));
    const auto hi = sorted_quantile(samples, 0.5 * (1.0 + level));
    if (!lo || !hi) return std::nullopt;
    return Interval{*lo, *hi, level};
}

int run_resamples(int n, int n_threads, const ProgressCallback& progress, const std::function<void(int)>& body) {
    if (n <= 0) return 0;
    n_threads = std::clamp(n_threads, 1, n);
    if (n_threads == 1) {
        for (int i = 0; i < n; ++i) {
            body(i);
            if (progress && !progress(i + 1, n)) return i + 1;
        }
        return n;
    }

    // Workers take indices in increasing order from one counter; on cancel they
    // stop taking new ones but finish the ones they hold, so the indices done
    // are exactly 0 .. next-1.
    std::atomic<int> next{0};
    std::atomic<bool> stop{false};
    std::mutex mutex;
    std::condition_variable cv;
    int finished = 0;
    std::exception_ptr error;

    auto worker = [&] {
        for (;;) {
            if (stop.load(std::memory_order_acquire)) break;
            const int i = next.fetch_add(1, std::memory_order_acq_rel);
            if (i >= n) break;
            try {
                body(i);
            } catch (...) {
                const std::lock_guard lock(mutex);
                if (!error) error = std::current_exception();
                stop.store(true, std::memory_order_release);
            }
            {
                const std::lock_guard lock(mutex);
                ++finished;
            }
            cv.notify_one();
        }
        cv.notify_one();
    };

    std::vector<std::thread> threads;
    threads.reserve(static_cast<std::size_t>(n_threads));
    for (int t = 0; t < n_threads; ++t) threads.emplace_back(worker);

    // The calling thread reports progress, in order, until all are done,
    // cancelled, or a worker failed.
    int reported = 0;
    {
        std::unique_lock lock(mutex);
        while (reported < n && !stop.load(std::memory_order_acquire)) {
            cv.wait(lock, [&] { return finished > reported || stop.load(std::memory_order_acquire); });
            if (finished > reported) {
                reported = finished;
                if (progress) {
                    lock.unlock();
                    const bool go_on = progress(reported, n);
                    lock.lock();
                    if (!go_on) stop.store(true, std::memory_order_release);
                }
            }
        }
    }
    for (std::thread& t : threads) t.join();
    if (error) std::rethrow_exception(error);
    return std::min(next.load(), n);
}

}  // namespace atonlab::analysis
