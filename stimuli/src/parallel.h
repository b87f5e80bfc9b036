#pragma once
// Splitting CPU work over the machine's cores (issue 27 item 3): the glare
// paths that every headless run takes (the PSF's anchors and bands, the `cie`
// veil's FFTs and direct sums) run on every core instead of one. Each index is
// computed exactly as it would be alone, so the results are bit-identical to a
// serial run whatever the thread count.
#include <algorithm>
#include <atomic>
#include <exception>
#include <thread>
#include <vector>

#include "atonlab/stimuli/cpu_threads.h"

namespace atonlab::stimuli::detail {

/// Worker threads for `count` independent items: the cores the machine has
/// (at least 1; at most set_cpu_threads()'s limit), never more than the items.
inline int worker_count(int count) {
    int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    if (cpu_threads() > 0) cores = std::min(cores, cpu_threads());
    return std::max(1, std::min(cores, count));
}

/// Calls body(begin, end, worker) for contiguous chunks of [0, count), one per
/// worker, the calling thread taking the first; returns when all are done.
/// An exception from a chunk is rethrown here (the first one).
template <class Body>
void parallel_chunks(int count, Body&& body) {
    if (count <= 0) return;
    const int workers = worker_count(count);
    if (workers == 1) {
        body(0, count, 0);
        return;
    }
    std::vector<std::exception_ptr> errors(static_cast<std::size_t>(workers));
    auto run = [&](int t) {
        try {
            body(count * t / workers, count * (t + 1) / workers, t);
        } catch (...) {
            errors[static_cast<std::size_t>(t)] = std::current_exception();
        }
    };
    std::vector<std::thread> threads;
    for (int t = 1; t < workers; ++t) threads.emplace_back(run, t);
    run(0);
    for (auto& th : threads) th.join();
    for (const auto& e : errors)
        if (e) std::rethrow_exception(e);
}

/// body(i) for each i in [0, count), items handed out one at a time (for
/// items of unequal cost, such as anchor PSFs).
template <class Body>
void parallel_items(int count, Body&& body) {
    if (count <= 0) return;
    const int workers = worker_count(count);
    if (workers == 1) {
        for (int i = 0; i < count; ++i) body(i);
        return;
    }
    std::atomic<int> next{0};
    parallel_chunks(workers, [&](int, int, int) {
        for (int i = next++; i < count; i = next++) body(i);
    });
}

}  // namespace atonlab::stimuli::detail
