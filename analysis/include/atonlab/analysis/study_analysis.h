#pragma once
// The analysis of a whole study (docs/analysis.md "What is computed"): the
// trials grouped per condition and observer (and pooled over observers when
// there are several), each group analysed as its task and procedure ask:
//
//   2AFC and yes-no (staircases, QUEST, constant stimuli): a psychometric
//     function of P(outcome) against the level (psychometric.h), gamma fixed
//     at the procedure's guess rate, lambda free in [0, 0.06], threshold at
//     the procedure's target probability (0.5: the PSE), parametric
//     bootstrap CIs and deviance goodness of fit;
//   staircases, in addition: the mean of each track's last reversals;
//   QUEST, in addition: each track's own posterior mean and 95% interval;
//   adjustment: the mean matched level, and log10(match / test);
//   brightness enhancement by glare (PSE or match against the test's
//     intensity) per adaptation level and tone mapper;
//   paired comparisons of conditions that differ in one stimulus parameter,
//     across observers, when there are several.
//
// Nothing here is NaN: a value that cannot be given is absent, with a reason.
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/analysis/dataset.h"
#include "atonlab/analysis/psychometric.h"

namespace atonlab::analysis {

/// The observer name of the pooled group (all observers' trials together).
inline constexpr const char* kPooled = "(pooled)";

struct AnalysisOptions {
    int bootstrap = 999;                ///< parametric bootstrap resamples per fit; 0: no intervals
    std::uint64_t seed = kDefaultSeed;  ///< resample i draws from Rng(derive_seed(seed, i))
    Family family = Family::CumulativeNormal;
    double ci_level = 0.95;  ///< coverage of every interval reported
    int last_reversals = 6;  ///< staircases: reversals averaged (Levitt 1971: an even number)
    int n_threads = 1;       ///< bootstrap threads; results do not depend on it
    /// Called as each group's bootstrap advances (group label, done, total).
    std::function<void(const std::string& group, int done, int total)> progress;
};

/// What the trials of a condition share. A parameter that differs between its
/// trials (two protocols that use one condition name differently) is listed in
/// `mixed` and the first value is shown.
struct ConditionInfo {
    std::string condition;
    protocols::Task task = protocols::Task::TwoAfc;
    std::string procedure;
    std::string level_key, level_scale, level_on;
    std::optional<double> adaptation_cd_m2;
    std::string tone_operator, glare_test, glare_reference;
    std::optional<double> test_intensity_cd;
    /// The test and reference lights' colour, rhythm and spectrum (Trial::test_look,
    /// reference_look); empty where the study file holds no scene.
    LightLook test_look, reference_look;
    /// What differs between the test as shown and the reference as shown:
    /// "colour", "rhythm", "spectrum", "glare" (the model each was drawn
    /// with), and any frame-wide key the two frames set differently
    /// ("tonemap.operator", ...). Intensities and positions are not listed:
    /// a match varies the one and a side-by-side needs the other.
    std::vector<std::string> differences;
    double guess_rate = 0.0;
    double target_p = 0.5;
    std::vector<std::string> mixed;
    int n_trials = 0;
    /// The trials' other overrides (Trial::settings) that are the same in every
    /// trial of the condition, by factor column; raw TOML value text.
    std::map<std::string, std::string> settings;

    /// The unit of the level: "log10 cd", "cd", "log10 cd/m2", ... from level_key and level_scale.
    std::string level_unit() const;
    /// Glare on the test and not (or differently) on the reference: the glare-brightness question.
    bool compares_glare() const noexcept {
        return task != protocols::Task::YesNo && !glare_test.empty() && glare_test != "none" &&
               glare_test != glare_reference;
    }
    /// Both lights are known from the stored scene.
    bool lights_known() const noexcept { return !test_look.colour.empty() && !reference_look.colour.empty(); }
    /// Glare on the test is the only difference between test and reference
    /// (known from the stored scene): log10(match / test) is then a
    /// brightness enhancement by glare.
    bool glare_only_difference() const {
        return compares_glare() && lights_known() && differences == std::vector<std::string>{"glare"};
    }
    /// What log10(match / test) is called: "enhancement by glare" when
    /// glare_only_difference(), else "test − reference".
    std::string difference_label() const;
};

/// One adaptive track (a staircase or QUEST of one session).
struct TrackResult {
    std::string session, observer, track, procedure;
    std::vector<double> levels;  ///< per trial, in order
    std::vector<std::optional<bool>> outcomes;
    std::vector<bool> reversal;                 ///< per trial; empty when unknown
    std::optional<ReversalSummary> reversals;   ///< staircases
    std::optional<PosteriorSummary> posterior;  ///< a procedure with a posterior (QUEST)
};

/// A headline number with its interval: what the PSE figure and paired
/// comparisons use for a group.
struct HeadlineEstimate {
    std::optional<double> value;  ///< level units (ConditionInfo::level_unit)
    std::optional<Interval> ci;
    std::string method;  ///< how it was obtained, one phrase
    bool reliable = false;
    std::string reason;  ///< why not reliable / absent
};

/// log10(match / test): brightness enhancement when the test has glare.
struct MatchRatio {
    std::optional<double> value;  ///< log10 units
    std::optional<Interval> ci;
    std::string method;
    bool reliable = false;
    std::string reason;
};

/// One condition, one observer (or kPooled).
struct GroupResult {
    std::string condition;
    std::string observer;
    int n_trials = 0;  ///< trials in the group (every row)
    int n_scored = 0;  ///< with a binary outcome (2AFC, yes-no) or matches (adjustment)
    int n_sessions = 0;
    std::vector<LevelCounts> counts;  ///< outcome counts per level
    Family family = Family::CumulativeNormal;
    std::string family_note;  ///< e.g. the Weibull fitted as its log-level twin, the Gumbel
    std::optional<PsychometricFit> fit;
    std::optional<PsychometricBootstrap> bootstrap;
    std::optional<double> threshold_proportion;  ///< F at the threshold: (target_p - gamma) / (1 - gamma)
    std::vector<TrackResult> tracks;
    std::optional<double> reversal_mean;       ///< mean over tracks of their reversal means
    std::optional<double> posterior_mean;      ///< mean over tracks of QUEST's posterior means
    std::optional<AdjustmentSummary> matches;  ///< adjustment: matched levels (mean, median, CIs)
    std::optional<MatchRatio> match_ratio;     ///< log10(match / test intensity)
    HeadlineEstimate headline;
};

/// Two conditions that differ in one stimulus parameter, compared within observers.
struct PairedResult {
    std::string condition_a, condition_b;
    std::string factor;  ///< the parameter that differs: "tone mapper", "adaptation", ...
    std::vector<std::string> observers;
    PairedComparison comparison;
};

/// Frame-timing quality of one session.
struct SessionTiming {
    std::string session, observer;
    int n_trials = 0;
    int dropped_frames = 0;  ///< sum over trials
    int trials_with_drops = 0;
    int missed_deadlines = 0;  ///< trials whose onset frame was late
};

struct StudyResults {
    AnalysisOptions options;                ///< as given (progress cleared)
    std::vector<std::string> observers;     ///< sorted
    std::vector<ConditionInfo> conditions;  ///< in the order first met (protocol order where known)
    std::vector<GroupResult> groups;        ///< per condition: each observer, then kPooled when > 1 observer
    std::vector<PairedResult> paired;
    std::vector<SessionTiming> timing;
    std::vector<std::string> warnings;  ///< the reader's notes and anything doubtful found here
    /// The settings columns (ConditionInfo::settings) whose value is not the
    /// same in every condition: the factors of the design beyond adaptation,
    /// tone mapper, glare and test intensity. Sorted.
    std::vector<std::string> factor_columns;

    const ConditionInfo* condition(const std::string& name) const;
    /// The group of a condition that the figures and the summary lead with:
    /// kPooled when there are several observers, else the one observer.
    const GroupResult* main_group(const std::string& condition) const;
};

/// An override's TOML value text, typed: a number, a boolean, or text (a
/// string's contents without its quotes; anything else as written).
struct SettingValue {
    std::optional<double> number;
    std::optional<bool> boolean;
    /// An array of numbers ("[0.0, 3.0, -500.0]": a position), element by element.
    std::optional<std::vector<double>> numbers;
    std::string text;
};
SettingValue setting_value(std::string_view toml_value);

/// Analyses every condition of the dataset. Never throws for the shape of the
/// data (degenerate groups are flagged); std::invalid_argument for bad options.
StudyResults analyze_study(const Dataset& data, const AnalysisOptions& options);

}  // namespace atonlab::analysis
