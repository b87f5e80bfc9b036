#pragma once
// The standard normal distribution for tests, written out independently of the
// code under test: Φ by erfc, its inverse by bisection.
#include <cmath>

namespace atonlab::test {

inline double normal_cdf(double z) {
    return 0.5 * std::erfc(-z / std::sqrt(2.0));
}

/// z with normal_cdf(z) = p, by bisection to double precision over [-10, 10].
inline double normal_quantile(double p) {
    double lo = -10, hi = 10;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (normal_cdf(mid) < p ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

}  // namespace atonlab::test
