#pragma once
// What every resampling statistic in analysis/ shares: the interval type, the
// percentile rule, the options (count, level, seed, threads, progress) and the
// random stream of resample i.
//
// Random numbers: atonlab::protocols::Rng (xoshiro256**, rng.h), resample i
// seeded with protocols::derive_seed(seed, i). The standard distributions are
// implementation-defined, so they are not used: the same seed gives the same
// intervals on every compiler, platform and thread count.
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "atonlab/protocols/rng.h"

namespace atonlab::analysis {

/// A two-sided interval, in the units of the statistic it bounds.
struct Interval {
    double lower = 0.0;
    double upper = 0.0;
    double level = 0.95;  ///< nominal coverage, e.g. 0.95

    bool contains(double x) const noexcept { return lower <= x && x <= upper; }
    bool operator==(const Interval&) const = default;
};

/// Called after each finished resample with (done, total); return false to stop
/// early (the result then says it was cancelled and uses what was done).
/// With several threads it is called from the calling thread only, in order.
using ProgressCallback = std::function<bool(int done, int total)>;

/// The seed used when none is given.
inline constexpr std::uint64_t kDefaultSeed = 20250701;

/// Options of every bootstrap in analysis/.
struct ResampleOptions {
    int n_resamples = 999;              ///< B; 999 puts the 95% percentile limits on order statistics 25 and 975
    double level = 0.95;                ///< two-sided coverage of the percentile intervals, 0 < level < 1
    std::uint64_t seed = kDefaultSeed;  ///< resample i draws from Rng(derive_seed(seed, i))
    int n_threads = 1;                  ///< worker threads (>= 1); results do not depend on it
    ProgressCallback progress;          ///< optional
};

/// Quantile p (0..1) of ascending `sorted` values: Hyndman & Fan (1996) type 6,
/// the (n+1)p-th order statistic with linear interpolation, clamped to the
/// first/last value (for n = 999, p = 0.025 is exactly the 25th value).
/// Absent for an empty span.
std::optional<double> sorted_quantile(std::span<const double> sorted, double p) noexcept;

/// The percentile interval [(1-level)/2, (1+level)/2] of `samples` (any order;
/// non-finite values are dropped). Absent with fewer than 2 finite samples.
std::optional<Interval> percentile_interval(std::vector<double> samples, double level) noexcept;

/// The random stream of resample `index` of a bootstrap seeded with `seed`.
inline protocols::Rng resample_rng(std::uint64_t seed, std::uint64_t index) noexcept {
    return protocols::Rng(protocols::derive_seed(seed, index));
}

/// Runs body(i) for i = 0 .. n-1 on `n_threads` threads (body must only write
/// to slot i of its outputs), reporting progress from the calling thread.
/// Returns the number of resamples done: n, or fewer if progress returned false
/// (then exactly the first `returned` indices are done).
int run_resamples(int n, int n_threads, const ProgressCallback& progress, const std::function<void(int)>& body);

}  // namespace atonlab::analysis
