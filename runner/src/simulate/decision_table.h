#pragma once
// The model observer's decision variable tabulated against the level, once
// per condition and arrangement, from full renders (docs/simulate.md "Fast
// trials"): what lets a simulated session answer thousands of trials a second
// without rendering one. The spacing of the levels is chosen by an error bound
// on the piecewise-linear interpolant, and the table is cached under a hash of
// everything that shapes the frames.
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "atonlab/protocols/observer.h"
#include "atonlab/protocols/protocol.h"
#include "atonlab/runner/session/stimulus_renderer.h"

namespace atonlab::runner {

/// A condition's decision variable at each level of one arrangement:
/// 2AFC log10 B(view 0) − log10 B(view 1) (observer.h decision_2afc), yes-no
/// p·log10(E_inc / E_θ) (decision_yes_no; −∞ where the light adds nothing).
struct DecisionCurve {
    std::string condition;
    /// 2AFC: 1 when the test is on the left / in the first interval, 0 when it
    /// is on the right / second; yes-no: 0.
    int arrangement = 0;
    std::size_t level_view = 0;  ///< 2AFC: the view whose light the level sets
    std::vector<double> levels;  ///< ascending, the procedure's level units
    std::vector<double> values;  ///< the decision variable at each level

    /// The decision variable at `level`, linear between the tabulated levels
    /// (−∞ where either neighbour is), the end values beyond them.
    double at(double level) const;
};

/// What a table was built for and what it found.
struct DecisionTable {
    std::string key;           ///< table_key(): SHA-256 of what shapes the frames
    double bound = 0.0;          ///< the error bound asked for, decision units (log10 brightness)
    double largest_check = 0.0;  ///< the largest midpoint deviation of the last halving of any curve
    /// What the table holds the decision variable to: the larger of `bound`
    /// and 5 × largest_check (the rendered decision variable is a step
    /// function of the level, one pixel's code at a time, which linear
    /// interpolation cannot follow closer than its steps).
    double stated_bound = 0.0;
    bool bound_met = true;  ///< false: stated_bound is larger than bound
    std::size_t renders = 0;   ///< frames rendered to build it
    double build_s = 0.0;      ///< wall-clock seconds to build it
    std::vector<DecisionCurve> curves;
    /// The displayability check's verdict on this display (docs/running.md),
    /// kept so that a cached table refuses a protocol exactly as a run does.
    std::string displayability_json;
    std::string refusal;  ///< empty when displayable

    const DecisionCurve& curve(const std::string& condition, int arrangement) const;
    std::string json() const;
    /// Throws std::runtime_error for a file that is not a table.
    static DecisionTable parse(const std::string& text);
};

/// The arrangement of a 2AFC trial (the test on the left / first: 1).
inline int arrangement_of(const std::optional<bool>& test_on_left) {
    return test_on_left && *test_on_left ? 1 : 0;
}

/// SHA-256 of everything that shapes a table: the protocol text and scene text
/// (the display, the conditions and every override are in them), the display
/// model used to encode, the atonlab version, the observer's window, exponent
/// and detection threshold, and the bound.
std::string table_key(const std::string& protocol_text, const std::string& scene_text,
                      const std::string& display_model_json, const protocols::ModelObserverParams& params,
                      double bound);

/// Builds the table from renders: for each 2AFC or yes-no condition and
/// arrangement, the decision variable on 9 levels over the procedure's
/// level_range(), then every interval halved at once while the largest
/// deviation of a rendered midpoint from the line through its ends is above
/// bound / 2 and still shrinking, within max_renders frames a curve.
/// `progress` gets (curves done, curves).
/// Throws InputError for an adjustment condition (simulated only with --render-every-trial).
DecisionTable build_decision_table(StimulusRenderer& renderer, const protocols::Protocol& protocol,
                                   const protocols::ModelObserverParams& params, double bound,
                                   const std::function<void(std::size_t, std::size_t)>& progress,
                                   std::size_t max_renders = 80);

/// The model's true value for condition c from its table (the level at which
/// the procedure's target probability is reached, as true_value.h finds it on
/// renders), or none with the reason in `why`.
std::optional<double> table_true_value(const DecisionTable& table, const protocols::Condition& c,
                                       const protocols::ModelObserverParams& params, std::string& why);

}  // namespace atonlab::runner
