#pragma once
// Internal: the standard sigmoids G(z) that every family reduces to. The fit
// works on an internal axis u (the level, or log10 of it for the Weibull) with
// z = beta (u - alpha), so the Weibull is fitted as the Gumbel of log10 levels.
#include <optional>

#include "atonlab/analysis/psychometric.h"

namespace atonlab::analysis::detail {

enum class Kernel { Normal, Logistic, Gumbel };

struct KernelValue {
    double value;       ///< G(z)
    double derivative;  ///< dG/dz
};

/// G(z) and dG/dz; 0 / 1 with derivative 0 for z = -inf / +inf, {0, 0} for NaN.
KernelValue kernel(Kernel k, double z) noexcept;
/// z with G(z) = p, 0 < p < 1.
std::optional<double> kernel_quantile(Kernel k, double p) noexcept;
/// The kernel of a family (Weibull and Gumbel share the Gumbel kernel).
Kernel kernel_of(Family f) noexcept;

}  // namespace atonlab::analysis::detail
