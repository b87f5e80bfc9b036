#pragma once
// QUEST (Watson & Pelli 1983), following Psychtoolbox-3's Quest package
// (Psychtoolbox/Quest: QuestCreate.m, QuestRecompute.m, QuestUpdate.m,
// QuestQuantile.m, QuestMean.m, QuestMode.m, QuestSd.m, QuestDemo.m):
//  - levels are log10 intensities (the protocol maps them, e.g. to log10 cd);
//  - the threshold grid is t_guess + i*grain, i = -dim/2 .. dim/2, with
//    dim = 2*ceil(range/grain/2) (500 when range is not given);
//  - the psychometric function is the Weibull
//        p(x) = delta*gamma + (1-delta)*(1 - (1-gamma)*exp(-10^(beta*(x + xThreshold))))
//    of x = intensity - threshold, tabulated on x = i2*grain, i2 = -dim .. dim,
//    with xThreshold found by linear interpolation on that table so that
//    p(0) = p_threshold (QuestRecompute);
//  - the prior is a Gaussian of sd t_guess_sd centred on t_guess;
//  - an answer at intensity I multiplies the pdf by p (Yes) or 1 - p (No) at
//    x = round((I - t_guess)/grain)*grain - x_threshold_candidate, the rounded
//    offset clamped to the grid (QuestUpdate's table indexing);
//  - the next level is QuestQuantile at Pelli's (1987) optimal quantile order
//    (QuestRecompute's pE formula; QuestDemo's recommendation), or the mean or
//    mode; the final estimate is QuestMean +- QuestSd (QuestDemo's recommendation).
// One deliberate difference: Psychtoolbox keeps the pdf and renormalises it;
// here the LOG posterior is kept (the log-likelihood tables are computed in a
// form that does not underflow, and the maximum is subtracted after each
// update), so any number of trials stays finite. Psychtoolbox reduces gamma to
// 0.5 with a warning when gamma > p_threshold; here that is a ProcedureError.
// From PsychoPy's QuestHandler (psychopy/data/staircase.py): optional clamping
// of proposals to [min_level, max_level], first_at_guess, stop_interval.
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "atonlab/protocols/procedure.h"

namespace atonlab::protocols {

/// Which statistic of the posterior the next trial is placed at.
enum class QuestMethod : std::uint8_t { Quantile, Mean, Mode };

/// "quantile", "mean", "mode".
std::string_view to_string(QuestMethod m) noexcept;
/// Parses "quantile", "mean", "mode"; throws ProcedureError("method") otherwise.
QuestMethod parse_quest_method(std::string_view text);

/// QuestCreate's arguments (defaults: QuestDemo's values) and the stop rule.
struct QuestParams {
    double t_guess = 0.0;         ///< tGuess: prior mean of the threshold, log10 intensity
    double t_guess_sd = 3.0;      ///< tGuessSd: prior sd, log10 units; be generous (QuestCreate help)
    double p_threshold = 0.82;    ///< pThreshold: P(Yes) that defines threshold, gamma < p < 1 - delta*(1-gamma)
    double beta = 3.5;            ///< Weibull steepness, > 0
    double delta = 0.01;          ///< lapse rate: fraction of blind presses, 0 <= delta < 1
    double gamma = 0.5;           ///< P(Yes) at zero intensity (0.5 for 2AFC, ~0 for yes/no), 0 <= gamma < 1
    double grain = 0.01;          ///< grid step, log10 units, > 0
    std::optional<double> range;  ///< width of the threshold grid, log10 units; default dim = 500 steps
    QuestMethod method = QuestMethod::Quantile;
    std::optional<double> quantile_order;  ///< default: Pelli's optimal order from gamma/delta (QuestRecompute)
    int n_trials = 0;                      ///< stop after this many trials (>= 1)
    std::optional<double> stop_interval;   ///< also stop when the 5%..95% interval is narrower (PsychoPy)
    std::optional<double> min_level;       ///< proposals clamped here (PsychoPy QuestHandler minVal)
    std::optional<double> max_level;       ///< proposals clamped here (PsychoPy QuestHandler maxVal)
    bool first_at_guess = false;  ///< first trial at t_guess (PsychoPy) instead of the prior's quantile (QuestDemo)
};

/// QUEST. Takes Yes / No (Yes = correct / seen). Deterministic: the seed is
/// accepted for the common constructor shape and not used.
class Quest : public Procedure {
public:
    explicit Quest(QuestParams params, std::uint64_t seed = 0);

    /// Its name in protocol files, the store and analysis (procedures.h).
    static constexpr std::string_view kName = "quest";
    /// What protocols and analysis know of the kind (procedures.h; protocols/src/procedure_types/).
    static const ProcedureType& type();

    std::string_view kind() const noexcept override { return kName; }
    bool finished() const override { return finished_; }
    std::optional<Proposal> next() const override;
    /// QuestMean +- QuestSd.
    Estimate estimate() const override;
    std::unique_ptr<Procedure> clone() const override { return std::make_unique<Quest>(*this); }
    std::string state() const override;

    const QuestParams& params() const noexcept { return params_; }

    /// QuestMean: posterior mean of the threshold, log10 intensity.
    double mean() const;
    /// QuestSd: posterior sd, log10 units (clamped at 0 against rounding).
    double sd() const;
    /// QuestMode: the grid threshold of highest posterior (the first if tied).
    double mode() const;
    /// QuestQuantile: the threshold below which `order` of the posterior lies
    /// (linear interpolation of the cumulative sum, as interp1).
    double quantile(double order) const;
    /// QuestQuantile with the default (optimal or given) order.
    double quantile() const { return quantile(quantile_order_); }

    /// The quantile order in use (Pelli's optimum unless given).
    double quantile_order() const noexcept { return quantile_order_; }
    /// QuestRecompute's xThreshold: the shift that puts p_threshold at x = 0.
    double x_threshold() const noexcept { return x_threshold_; }
    /// Number of grid points (dim + 1).
    std::size_t grid_size() const noexcept { return log_pdf_.size(); }
    /// The threshold grid, log10 intensity: t_guess + i*grain.
    std::vector<double> grid() const;
    /// The posterior on the grid, normalised to sum 1.
    std::vector<double> posterior() const;
    /// The log posterior on the grid (maximum 0; -inf where the posterior is exactly 0).
    const std::vector<double>& log_posterior() const noexcept { return log_pdf_; }
    /// P(Yes) of the tabulated psychometric function at x = intensity - threshold,
    /// x rounded to the grain and clamped to the table (QuestP-like).
    double p_yes(double x) const;
    /// Levels of the trials answered so far.
    const std::vector<double>& levels() const noexcept { return levels_; }

protected:
    void do_record(Response r) override;

private:
    double propose() const;
    double x_at(std::ptrdiff_t i) const noexcept { return static_cast<double>(i) * params_.grain; }

    QuestParams params_;
    std::ptrdiff_t half_dim_ = 0;  ///< dim/2
    double x_threshold_ = 0.0;
    double quantile_order_ = 0.0;
    std::vector<double> p2_;       ///< p(x2) on i2 = -dim..dim (with xThreshold), plain PTB formula
    std::vector<double> log_p2_;   ///< log p(x2), computed without underflow
    std::vector<double> log_q2_;   ///< log(1 - p(x2)), computed without underflow
    std::vector<double> log_pdf_;  ///< log posterior on i = -dim/2..dim/2, max 0
    std::vector<double> levels_;
    double next_level_ = 0.0;
    bool finished_ = false;
};

}  // namespace atonlab::protocols
