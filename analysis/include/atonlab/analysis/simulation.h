#pragma once
// The simulation report (docs/analysis.md "The simulation report"): a folder
// that `atonlab simulate` wrote (docs/simulate.md) holds one study file per
// simulated session, each session knowing its observer's true values. This
// reads every file read-only on all cores, estimates each session's
// conditions with the ordinary per-group analysis (study_analysis.h) and a
// cheap interval (the profile likelihood, profile_interval.h; or the
// parametric bootstrap), keeps one small summary per session (never its
// trials: memory grows with the number of files, not with their trials),
// and summarises per design and condition: the truth, the mean and median
// estimate, bias, SD, RMSE, interval coverage with its Clopper-Pearson
// interval, trials per session, and the power to detect a stated effect.
//
// A file that cannot be used (unfinished, refused by the store, not a
// simulated session, ...) is never silently skipped: it is listed with its
// reason (SimulationResults::skipped).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "atonlab/analysis/psychometric.h"
#include "atonlab/analysis/resample.h"
#include "atonlab/analysis/simulation_manifest.h"

namespace atonlab::analysis {

/// How each session's interval is obtained.
enum class IntervalMethod : std::uint8_t {
    Profile,    ///< profile likelihood of the fit's threshold (profile_interval.h); no resampling
    Bootstrap,  ///< the analysis's parametric bootstrap, percentile interval (psychometric.h)
};
/// "profile", "bootstrap".
const char* to_string(IntervalMethod m) noexcept;

struct SimulationOptions {
    IntervalMethod intervals = IntervalMethod::Profile;
    int bootstrap = 999;  ///< resamples per fit with IntervalMethod::Bootstrap
    std::uint64_t seed = kDefaultSeed;
    Family family = Family::CumulativeNormal;
    double ci_level = 0.95;
    int last_reversals = 6;
    int n_threads = 1;  ///< files read and analysed in parallel; results do not depend on it
    /// The effect whose power is computed, log10 units; none: no power.
    std::optional<double> effect_log10;
    /// The two conditions the effect lies between (A − B); none: every
    /// glare condition's enhancement log10(PSE / test intensity).
    std::optional<std::pair<std::string, std::string>> effect_between;
    /// Called as files finish (done, total), from the calling thread.
    std::function<void(std::size_t done, std::size_t total)> progress;
};

/// One condition of one session.
struct SessionEstimate {
    std::string condition;
    std::optional<double> truth;     ///< simulation_json's true value, level units
    std::string truth_what;          ///< "pse", "matching level", "threshold"
    double truth_p = 0.5;            ///< the probability the truth is defined at
    double estimate_p = 0.5;         ///< the probability the estimate is defined at (ConditionInfo::target_p)
    std::optional<double> estimate;  ///< the analysis's headline (study_analysis.h HeadlineEstimate)
    std::optional<Interval> ci;
    bool ci_open = false;  ///< a profile interval that reached the search range: not closed there
    std::string method;    ///< the headline's method
    bool reliable = false;
    std::string reason;  ///< why not reliable / no estimate / no interval
    int n_trials = 0;
    /// log10 of the test's intensity when the condition compares glare and its
    /// estimate is a PSE on log10 levels of the reference (the analysis's
    /// enhancement, MatchRatio): the enhancement is estimate − test_log10.
    std::optional<double> test_log10;
    std::string difference_label;  ///< ConditionInfo::difference_label()
};

/// One simulated session (one study file).
struct SessionSummary {
    std::string file;  ///< as found under DIR
    int design_index = 0;
    std::int64_t index = 0;  ///< the session's index in its design
    std::uint64_t seed = 0;
    std::string observer;
    int n_trials = 0;
    std::string level_unit;  ///< of its first condition
    std::vector<SessionEstimate> conditions;
};

/// A file listed and left out, with its reason (one sentence).
struct SkippedFile {
    std::string file;
    std::string reason;
};

/// One design and condition over all its sessions.
struct ConditionSummary {
    int design_index = 0;
    std::string design, condition, unit, truth_what;
    double truth_p = 0.5;
    std::optional<double> truth;  ///< the mean of the sessions' true values
    double truth_min = 0.0, truth_max = 0.0;
    bool truth_differs = false;          ///< the sessions' true values are not all the same (beyond 1e-9)
    int n_sessions = 0;                  ///< sessions holding the condition
    int n_estimates = 0;                 ///< of those, with an estimate and a truth
    int n_unreliable = 0;                ///< estimates the analysis flagged unreliable (kept)
    std::optional<double> mean, median;  ///< of the estimates
    /// Of the errors estimate − truth, each against its own session's truth:
    /// bias their mean, sd the estimates' SD (n − 1), rmse sqrt(mean error²).
    std::optional<double> bias, sd, rmse;
    int n_intervals = 0;                              ///< estimates with an interval
    int n_covered = 0;                                ///< intervals holding their session's truth
    int n_open = 0;                                   ///< profile intervals not closed within the search range
    std::optional<double> coverage;                   ///< n_covered / n_intervals
    std::optional<Interval> coverage_ci;              ///< Clopper-Pearson, at the report's level
    std::optional<double> width_median;               ///< of the intervals, level units
    /// The design's calibrated interval (docs/analysis.md "Calibrated
    /// intervals"): the factor by which each side of a session's interval must
    /// widen so that `level` of the sessions' intervals hold their truth
    /// (the nearest-rank quantile of each session's needed widening), and the
    /// coverage of intervals so widened when the factor is found on the other
    /// half of the sessions (even against odd positions, and back): held out,
    /// so not covering by construction.
    std::optional<double> widen_factor;
    int n_calibrated = 0, n_calibrated_covered = 0;
    std::optional<double> calibrated_coverage;
    std::optional<Interval> calibrated_coverage_ci;  ///< Clopper-Pearson
    std::optional<double> trials_median, trials_p90;  ///< the condition's trials per session
};

/// The power to detect an effect of `effect` log10 units (see power_of()).
struct PowerSummary {
    int design_index = 0;
    std::string design;
    std::string condition_a, condition_b;  ///< b empty: a's enhancement against its test intensity
    std::string what;                      ///< "enhancement by glare", "A − B", ...
    double effect = 0.0;
    std::optional<double> true_difference;  ///< the sessions' mean true difference
    int n_sessions = 0;                     ///< sessions with both estimates and intervals
    int n_detected = 0;
    std::optional<double> power;
    std::optional<Interval> power_ci;     ///< Clopper-Pearson
    std::optional<double> sd_difference;  ///< SD of the estimated differences over sessions
};

/// One session's difference and its standard error: the input of power_of().
struct DifferenceSample {
    double estimate = 0.0;  ///< the estimated difference d_i
    double truth = 0.0;     ///< the session's true difference
    double se = 0.0;        ///< its standard error, > 0
};

struct SimulationResults {
    SimulationOptions options;  ///< as given (progress cleared)
    SimulationManifest manifest;
    std::filesystem::path folder;
    std::size_t files_found = 0;               ///< every file under sessions/ (a -wal or -shm counted with its file)
    std::vector<SessionSummary> sessions;      ///< read and summarised, in file order
    std::vector<SkippedFile> skipped;          ///< left out, each with its reason
    std::vector<ConditionSummary> conditions;  ///< per design, in the conditions' order
    std::vector<PowerSummary> power;
    std::vector<std::string> warnings;
    double read_s = 0.0;              ///< wall time of reading and estimating every file
    std::int64_t bootstrap_fits = 0;  ///< refits done (IntervalMethod::Bootstrap)
};

/// Reads and summarises the simulation folder `dir`. Throws InputError for a
/// folder without a readable manifest or a bad option; never for a bad
/// session file (listed in `skipped`).
SimulationResults analyze_simulation(const std::filesystem::path& dir, const SimulationOptions& options);

/// One file's summary, or the reason it cannot be used (the file is then
/// skipped). `design_index`: the design its folder names.
struct SessionRead {
    std::optional<SessionSummary> summary;
    std::string reason;
    std::int64_t bootstrap_fits = 0;
};
SessionRead read_simulated_session(const std::filesystem::path& file, int design_index,
                                   const SimulationOptions& options);

/// Per design and condition (ConditionSummary) from the sessions.
std::vector<ConditionSummary> summarize_conditions(const std::vector<SessionSummary>& sessions,
                                                   const SimulationManifest& manifest, double level);

/// The power of a two-sided z test at α = 1 − level to find an effect of
/// `effect` (log10 units), by the location-shift method (docs/analysis.md):
/// session i's error d_i − truth_i is taken to be what it would be were the
/// true difference `effect`, so the session detects the effect when
/// |effect + d_i − truth_i| / se_i > z_{(1+level)/2}. Power = the share of
/// sessions that detect it, with its Clopper-Pearson interval.
PowerSummary power_of(const std::vector<DifferenceSample>& samples, double effect, double level);

/// The power analyses the options ask for (per design).
std::vector<PowerSummary> power_analyses(const std::vector<SessionSummary>& sessions,
                                         const SimulationManifest& manifest, const SimulationOptions& options,
                                         std::vector<std::string>& warnings);

/// Clopper-Pearson (exact) interval of a binomial proportion k / n at `level`
/// (Boost.Math's find_lower/upper_bound_on_p); absent for n <= 0.
std::optional<Interval> clopper_pearson(int k, int n, double level);

/// Quantile p of ascending `sorted` by the nearest rank: the ceil(p n)-th
/// value (p = 0.9: the 90th percentile of trials). Absent when empty.
std::optional<double> nearest_rank(const std::vector<double>& sorted, double p);

}  // namespace atonlab::analysis
