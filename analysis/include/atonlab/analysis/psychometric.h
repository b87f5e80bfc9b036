#pragma once
// Psychometric functions fitted by binomial maximum likelihood, with parametric
// bootstrap intervals and a deviance goodness-of-fit test. The conventions are
// those of Palamedes (Prins & Kingdom 2018; PAL_PFML_Fit, PAL_PFML_BootstrapParametric,
// PAL_PFML_GoodnessOfFit) for the parameters and psignifit 4 (Schuett, Harmeling,
// Macke & Wichmann 2016) for threshold and width; docs/analysis-fits.md says
// everything below at more length.
//
//   Psi(x) = gamma + (1 - gamma - lambda) F(x; alpha, beta)
//
// with F one of (alpha: location, beta: steepness > 0; Palamedes' definitions):
//   CumulativeNormal  F = Phi(beta (x - alpha))                 F(alpha) = 0.5
//   Logistic          F = 1 / (1 + exp(-beta (x - alpha)))      F(alpha) = 0.5
//   Weibull           F = 1 - exp(-(x / alpha)^beta), x > 0 in LINEAR units
//                     (F = 0 for x <= 0), alpha > 0 linear  F(alpha) = 1 - 1/e
//   Gumbel            F = 1 - exp(-10^(beta (x - alpha))), x in log10 units;
//                     the Weibull of 10^x with alpha_W = 10^alpha, same beta
//                     ("log-Weibull"; Palamedes' PAL_Gumbel)  F(alpha) = 1 - 1/e
// The CumulativeNormal's beta is 1/sigma (sigma in level units).
//
// The levels are in whatever unit the caller chooses (for atonlab usually log10
// of an intensity in cd or of a luminance in cd/m2), except for the Weibull,
// whose levels must be linear (e.g. contrast, cd) because it takes their ratio.
//
// Derived outputs, all in level units (linear units for the Weibull):
//   threshold  x where F = threshold_proportion (default 0.5 of F, psignifit's
//              default). F, not Psi: with gamma = 0 (yes/no, or a 2AFC analysed
//              as "chose the test" against the level, whose curve runs 0..1)
//              it is the PSE where Psi = 0.5 (1 - lambda) ~ 0.5; with gamma = 0.5
//              (2AFC scored correct/incorrect) it is where Psi = 0.75 - lambda/2.
//              Use psi_inverse() for the level at a given Psi.
//   slope      dPsi/dx at the threshold (per level unit), scaled by (1-gamma-lambda)
//   width      psignifit's width: x(F = 1 - width_alpha) - x(F = width_alpha),
//              default alpha 0.05, i.e. the 5%..95% rise of F.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/analysis/resample.h"

namespace atonlab::analysis {

// ---------------------------------------------------------------------------
// Families

/// The sigmoid F of the psychometric function (see the file comment).
enum class Family : std::uint8_t { CumulativeNormal, Logistic, Weibull, Gumbel };

/// "normal", "logistic", "weibull", "gumbel".
std::string_view to_string(Family f) noexcept;
/// Parses "normal" (also "cumulative-normal", "gaussian"), "logistic", "weibull",
/// "gumbel" (also "log-weibull"); case-sensitive. Absent otherwise.
std::optional<Family> parse_family(std::string_view text) noexcept;
/// True for the Weibull, the only family whose levels are linear (x > 0).
constexpr bool takes_linear_levels(Family f) noexcept {
    return f == Family::Weibull;
}

/// The four parameters of Psi (Palamedes' order: alpha, beta, gamma, lambda).
struct PsiParams {
    double alpha = 0.0;   ///< location, level units (Weibull: linear, > 0)
    double beta = 1.0;    ///< steepness, > 0 (per level unit; Gumbel/Weibull: per log10 unit)
    double gamma = 0.0;   ///< guess rate, Psi at -infinity: 0 yes/no, 0.5 2AFC
    double lambda = 0.0;  ///< lapse rate: 1 - Psi at +infinity
    bool operator==(const PsiParams&) const = default;
};

/// F(x; alpha, beta) in [0, 1].
double sigmoid(Family f, double x, double alpha, double beta) noexcept;
/// dF/dx at x (per level unit); 0 where F is flat (e.g. Weibull at x <= 0).
double sigmoid_derivative(Family f, double x, double alpha, double beta) noexcept;
/// The x with F(x) = p, 0 < p < 1 (absent otherwise, or for beta <= 0).
std::optional<double> sigmoid_inverse(Family f, double p, double alpha, double beta) noexcept;

/// Psi(x) = gamma + (1 - gamma - lambda) F(x).
double psi(Family f, double x, const PsiParams& p) noexcept;
/// dPsi/dx = (1 - gamma - lambda) dF/dx.
double psi_derivative(Family f, double x, const PsiParams& p) noexcept;
/// The x with Psi(x) = target; absent unless gamma < target < 1 - lambda.
std::optional<double> psi_inverse(Family f, double target, const PsiParams& p) noexcept;

/// psignifit's width x(F = 1 - width_alpha) - x(F = width_alpha), level units.
std::optional<double> sigmoid_width(Family f, double alpha, double beta, double width_alpha = 0.05) noexcept;

/// alpha and beta from psignifit's (threshold, width): the F of `f` that passes
/// through F(threshold) = threshold_proportion and has the given width between
/// F = width_alpha and 1 - width_alpha. Returned with gamma = lambda = 0. Absent
/// for width <= 0, proportions outside (0, 1), or (Weibull) threshold <= 0 or
/// a width the Weibull cannot have with that threshold.
std::optional<PsiParams> from_threshold_width(Family f, double threshold, double width,
                                              double threshold_proportion = 0.5, double width_alpha = 0.05) noexcept;

// ---------------------------------------------------------------------------
// Data

/// One stimulus level and its responses. For yes/no data n_yes counts "yes"
/// (or "chose the test"); for 2AFC scored correct/incorrect it counts correct.
struct LevelCounts {
    double level = 0.0;  ///< stimulus value, level units (see the file comment)
    int n_trials = 0;    ///< >= 0
    int n_yes = 0;       ///< 0 <= n_yes <= n_trials
    bool operator==(const LevelCounts&) const = default;
};

/// Counts per distinct level, ascending, from trial-by-trial data (levels[i],
/// yes[i]). Rows with a non-finite level are dropped. Sizes must match (the
/// shorter length is used otherwise).
std::vector<LevelCounts> tabulate(std::span<const double> levels, std::span<const bool> yes);

/// Rows with equal levels merged, ascending; rows with n_trials <= 0 dropped.
std::vector<LevelCounts> pool_levels(std::span<const LevelCounts> data);

// ---------------------------------------------------------------------------
// Fitting

/// A guess or lapse rate: fixed, or free within [lower, upper].
struct RateConstraint {
    std::optional<double> fixed;  ///< when set, the rate is this value
    double lower = 0.0;           ///< when free
    double upper = 0.06;          ///< when free

    static RateConstraint fixed_at(double value) noexcept { return {value, value, value}; }
    static RateConstraint free_in(double lo, double hi) noexcept { return {std::nullopt, lo, hi}; }
    bool is_free() const noexcept { return !fixed.has_value(); }
};

/// How to fit. Defaults: cumulative normal, gamma fixed at 0 (yes/no or
/// "chose the test" data), lambda free in [0, 0.06] (psignifit 4's default
/// lapse range is [0, 0.5] with a prior; Wichmann & Hill 2001 used [0, 0.06]).
struct FitOptions {
    Family family = Family::CumulativeNormal;
    RateConstraint guess = RateConstraint::fixed_at(0.0);       ///< gamma
    RateConstraint lapse = RateConstraint::free_in(0.0, 0.06);  ///< lambda
    double threshold_proportion = 0.5;                          ///< threshold is where F equals this, 0 < p < 1
    double width_alpha = 0.05;  ///< width spans F = width_alpha .. 1 - width_alpha, 0 < a < 0.5
    /// Search range of alpha, level units (Weibull: linear, > 0). Default: the
    /// tested range extended by its own length on each side (for the Weibull,
    /// in log10 units).
    std::optional<double> alpha_min, alpha_max;
    /// Search range of beta (> 0). Default: widths (see above) from 1/1000 to
    /// 100 times the tested range (Weibull: of log10 levels).
    std::optional<double> beta_min, beta_max;

    /// Yes/no (or "chose the test") data: gamma fixed at 0, lambda free in [0, 0.06].
    static FitOptions yes_no(Family f = Family::CumulativeNormal) noexcept;
    /// 2AFC scored correct/incorrect: gamma fixed at 0.5, lambda free in [0, 0.06].
    static FitOptions two_afc(Family f = Family::CumulativeNormal) noexcept;
};

/// What a successful fit estimates. All values finite.
struct PsychometricEstimate {
    PsiParams params;               ///< maximum-likelihood alpha, beta, gamma, lambda
    double threshold = 0.0;         ///< x where F = threshold_proportion, level units
    double psi_at_threshold = 0.0;  ///< Psi(threshold)
    double slope = 0.0;             ///< dPsi/dx at the threshold, per level unit
    double width = 0.0;             ///< x(F = 1 - a) - x(F = a), level units
    /// sum_i k_i ln Psi(x_i) + (n_i - k_i) ln(1 - Psi(x_i)), natural log, without
    /// the binomial coefficients (as Palamedes' PAL_PFML_Fit LL).
    double log_likelihood = 0.0;
    /// 2 (LL_saturated - LL), the saturated model having Psi_i = k_i / n_i per
    /// row (Palamedes' PAL_PFML_GoodnessOfFit Dev).
    double deviance = 0.0;
};

/// The result of fit_psychometric. Never throws for the shape of the data: a
/// fit that is not trustworthy says so in `reliable` and `reason`; where no
/// estimate exists at all `estimate` is absent. Nothing is ever NaN.
struct PsychometricFit {
    FitOptions options;
    std::optional<PsychometricEstimate> estimate;
    bool reliable = false;
    std::string reason;      ///< why not reliable; empty when reliable
    int n_trials = 0;        ///< sum of n_trials over rows with trials
    int n_rows = 0;          ///< rows with n_trials > 0
    int n_levels = 0;        ///< distinct levels among those rows
    int n_free = 0;          ///< free parameters (2 + free gamma + free lambda)
    bool at_bound = false;   ///< alpha or beta ended on its search bound
    bool converged = false;  ///< NLopt stopped on its tolerance, not on an error
    int n_evaluations = 0;   ///< likelihood evaluations (grid + local search)
};

/// Fits Psi by binomial maximum likelihood: a 7 x 5 grid search over alpha and
/// ln beta (free rates started from the observed proportions at the extreme
/// levels), then NLopt's bounded SLSQP with the analytic gradient from the best
/// grid point and from the best one not adjacent to it (the better optimum wins). Rows with n_trials <= 0
/// are ignored; rows with invalid counts (n_yes < 0 or > n_trials) or a
/// non-finite level make the fit unreliable without an estimate. Degenerate
/// data (no trials, one trial, a single distinct level, all yes, all no) give
/// `estimate` absent, reliable = false and a reason. A fit whose alpha or beta
/// ends on its search bound keeps its estimate but is flagged unreliable.
/// A fit whose width (on the fitted axis) is narrower than the closest spacing
/// of the levels is flagged too: the data do not constrain its slope.
/// Throws std::invalid_argument only for invalid options (a bound or proportion
/// outside its range, largest gamma + largest lambda > 1, lower > upper).
PsychometricFit fit_psychometric(std::span<const LevelCounts> data, const FitOptions& options = {});

/// Log-likelihood of `data` under Psi with `p` (same convention as
/// PsychometricEstimate::log_likelihood); Psi is clamped to [1e-12, 1 - 1e-12].
double log_likelihood(Family f, std::span<const LevelCounts> data, const PsiParams& p) noexcept;
/// Deviance of `data` under Psi with `p` (as PsychometricEstimate::deviance).
double deviance(Family f, std::span<const LevelCounts> data, const PsiParams& p) noexcept;

// ---------------------------------------------------------------------------
// Parametric bootstrap and goodness of fit

/// Deviance goodness of fit (Wichmann & Hill 2001a; Palamedes PAL_PFML_GoodnessOfFit).
struct GoodnessOfFit {
    double deviance = 0.0;  ///< of the fit to the observed data
    int dof = 0;            ///< rows - free parameters
    /// Monte-Carlo p: (1 + #{simulated deviance >= observed}) / (1 + B), from
    /// the same B simulations as the intervals (Davison & Hinkley 1997 eq 4.11;
    /// Palamedes' pDev is #{>}/B, which differs by less than 1/B).
    std::optional<double> p_value;
    /// The asymptotic chi-squared(dof) p (Boost.Math); misleading for few
    /// trials per level (Wichmann & Hill 2001a), shown for comparison only.
    std::optional<double> p_value_chi2;
};

/// Parametric bootstrap of a fit (Wichmann & Hill 2001b; Palamedes
/// PAL_PFML_BootstrapParametric): B datasets are drawn from the fitted Psi at
/// the observed levels with the observed n per row (binomial draws as sums of
/// Bernoulli trials on resample_rng(seed, i)), each is refitted with the same
/// options, and the percentile intervals of the refitted values are reported.
struct PsychometricBootstrap {
    int n_requested = 0;  ///< B asked for
    int n_done = 0;       ///< resamples simulated (B unless cancelled)
    int n_failed = 0;     ///< of those, refits without an estimate (excluded from the intervals)
    int n_at_bound = 0;   ///< of those, refits with alpha or beta on a bound (kept)
    bool cancelled = false;
    bool reliable = false;
    std::string reason;  ///< why not reliable; empty when reliable
    std::optional<Interval> threshold, slope, width, lambda, gamma, alpha, beta;
    /// Refitted values of the successful resamples, in resample order (the
    /// same index in every vector), e.g. for the CI of a difference of PSEs.
    std::vector<double> threshold_samples, slope_samples, width_samples, lambda_samples, gamma_samples;
    /// Deviance of every simulated dataset under its own refit (successful ones).
    std::vector<double> deviance_samples;
    GoodnessOfFit goodness_of_fit;
};

/// Bootstraps `fit` (which must come from fit_psychometric(data, ...)). Without
/// an estimate in `fit` nothing is simulated and the result says why.
/// Deterministic: same data, fit, seed and B give identical results for any
/// n_threads. reliable is false when the fit was unreliable, when the run was
/// cancelled, or when more than 1% of the refits failed.
PsychometricBootstrap bootstrap_psychometric(std::span<const LevelCounts> data, const PsychometricFit& fit,
                                             const ResampleOptions& options = {});

}  // namespace atonlab::analysis

#include "atonlab/analysis/matching.h"    // IWYU pragma: export
#include "atonlab/analysis/thresholds.h"  // IWYU pragma: export
