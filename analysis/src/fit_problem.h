#pragma once
// Internal: the negative log-likelihood that fit_psychometric minimises, on the
// internal axis u (levels; log10 levels for the Weibull) with parameters
// x = (a, ln beta, [gamma], [lambda]).
#include <limits>
#include <span>
#include <vector>

#include "family_kernel.h"

namespace atonlab::analysis::detail {

struct FitProblem {
    struct Row {
        double u;  ///< internal axis; -inf for a Weibull level <= 0 (F = 0 there)
        double n;  ///< trials
        double k;  ///< yes
    };
    Kernel kernel_kind = Kernel::Normal;
    std::vector<Row> rows;
    int gamma_index = -1;  ///< index of gamma in x, -1 when fixed
    int lambda_index = -1;
    double gamma_fixed = 0.0;
    double lambda_fixed = 0.0;
    /// The objective is (-LL - objective_offset) * objective_scale: with objective_offset = -LL_saturated and
    /// objective_scale = 1 / total trials it is deviance / (2 N) >= 0, of order 1 whatever
    /// N, which keeps the minimiser's tolerances meaningful.
    double objective_offset = 0.0;
    double objective_scale = 1.0;
    int evaluations = 0;
    double best_value = std::numeric_limits<double>::infinity();
    std::vector<double> best_x;  ///< the lowest -LL seen, over all evaluations

    /// (-LL - objective_offset) * objective_scale at x (Psi clamped to [1e-12, 1 - 1e-12], with a zero gradient where
    /// clamped), and its gradient into grad when grad is not empty.
    double evaluate(std::span<const double> x, std::span<double> grad);
};

}  // namespace atonlab::analysis::detail
