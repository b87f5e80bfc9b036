// The model observer's decision variable tabulated against the level (decision_table.h).
#include "simulate/decision_table.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <utility>

#include "atonlab/common/input_error.h"
#include "atonlab/protocols/simulated_observer.h"
#include "atonlab/runner/session/session_observer.h"
#include "atonlab/store/sha256.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
using Json = nlohmann::ordered_json;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kInitialLevels = 9;     // the first grid: 8 equal intervals over the level range
constexpr double kStatedFactor = 5.0;  // the stated bound over the largest midpoint deviation (build_curve)

/// The noiseless decision variable of condition c at `level` in one
/// arrangement, from the frames the renderer makes (or has cached);
/// `level_view` gets the view the level sets.
double rendered_decision(StimulusRenderer& renderer, const p::Protocol& protocol, const p::Condition& c,
                         const p::ModelObserverParams& params, double level, int arrangement,
                         std::size_t& level_view) {
    p::Proposal proposal;
    proposal.level = level;
    if (c.task == p::Task::TwoAfc) proposal.test_on_left = arrangement == 1;
    p::ScheduledTrial t;
    t.task = c.task;
    t.condition_id = c.name;
    t.stimulus = p::make_stimulus(protocol, c, proposal);
    for (std::size_t i = 0; i < t.stimulus.views.size(); ++i)
        if (t.stimulus.views[i].role == c.level_on) level_view = i;
    std::vector<std::shared_ptr<const FrameViews>> frames;
    const p::Shown shown = shown_for(t, renderer, frames);
    const p::ModelObserver model(params, 0);
    return c.task == p::Task::TwoAfc ? model.decision_2afc(shown) : model.decision_yes_no(shown);
}

/// How far the rendered midpoint lies from the line through its ends.
double midpoint_deviation(double fa, double fm, double fb) {
    const bool a = std::isfinite(fa), m = std::isfinite(fm), b = std::isfinite(fb);
    if (!a && !m && !b) return 0.0;  // no increment anywhere on the interval
    if (!a || !m || !b) return kInf;
    return std::abs(fm - 0.5 * (fa + fb));
}

/// One curve: a uniform grid of 8 intervals, then every interval halved at
/// once (its midpoint rendered and checked against the line through its ends)
/// while the largest deviation is above bound / 2, still shrinking (a
/// rendered frame's decision variable is a step function of the level, its
/// steps one code of a pixel: halving stops helping once the intervals are as
/// fine as the steps), and the next halving fits in max_renders. The curve's
/// stated bound is the larger of `bound` and kStatedFactor × the last largest
/// deviation: between its samples a step function can stray further from the
/// line than at the midpoints checked (an empirical factor: at random levels
/// GL.Simulate.TheTableHolds… found errors up to 4.5 × the largest midpoint
/// deviation on sim_2afc.toml; docs/simulate.md).
DecisionCurve build_curve(StimulusRenderer& renderer, const p::Protocol& protocol, const p::Condition& c,
                          const p::ModelObserverParams& params, int arrangement, double bound,
                          std::size_t max_renders, DecisionTable& table) {
    auto [lo, hi] = c.procedure.level_range();
    if (lo > hi) std::swap(lo, hi);
    DecisionCurve curve;
    curve.condition = c.name;
    curve.arrangement = arrangement;
    std::map<double, double> samples;
    std::size_t renders = 0;
    auto sample = [&](double level) {
        ++renders;
        return samples[level] = rendered_decision(renderer, protocol, c, params, level, arrangement, curve.level_view);
    };
    std::size_t intervals = kInitialLevels - 1;
    for (std::size_t i = 0; i <= intervals; ++i)
        sample(i == intervals ? hi : lo + (hi - lo) * static_cast<double>(i) / static_cast<double>(intervals));
    double previous = kInf, largest = kInf;
    while (renders + intervals <= max_renders) {
        std::vector<std::pair<double, double>> ends;
        for (auto it = samples.begin(); std::next(it) != samples.end(); ++it)
            ends.emplace_back(it->first, std::next(it)->first);
        largest = 0.0;
        for (const auto& [a, b] : ends) {
            const double fa = samples.at(a), fb = samples.at(b);
            if (!std::isfinite(fa) && !std::isfinite(fb)) continue;  // E_inc grows with the level: none in between
            largest = std::max(largest, midpoint_deviation(fa, sample(0.5 * (a + b)), fb));
        }
        intervals *= 2;
        // A smooth curve's deviation falls 4× per halving; one that does not
        // even halve is at the floor of the display's code steps.
        if (largest <= 0.5 * bound || largest > 0.5 * previous) break;
        previous = largest;
    }
    const double stated = std::max(bound, kStatedFactor * largest);
    table.largest_check = std::max(table.largest_check, largest);
    table.stated_bound = std::max(table.stated_bound, stated);
    if (stated > bound) table.bound_met = false;
    for (const auto& [level, value] : samples) {
        curve.levels.push_back(level);
        curve.values.push_back(value);
    }
    table.renders += renders;
    return curve;
}

Json number_or_null(double v) {
    return std::isfinite(v) ? Json(v) : Json(nullptr);
}

}  // namespace

double DecisionCurve::at(double level) const {
    if (levels.empty()) return 0.0;
    if (level <= levels.front()) return values.front();
    if (level >= levels.back()) return values.back();
    const auto it = std::upper_bound(levels.begin(), levels.end(), level);
    const std::size_t i = static_cast<std::size_t>(it - levels.begin());
    const double a = values[i - 1], b = values[i];
    if (!std::isfinite(a) || !std::isfinite(b)) return -kInf;
    const double t = (level - levels[i - 1]) / (levels[i] - levels[i - 1]);
    return a + t * (b - a);
}

const DecisionCurve& DecisionTable::curve(const std::string& condition, int arrangement) const {
    for (const DecisionCurve& c : curves)
        if (c.condition == condition && c.arrangement == arrangement) return c;
    throw std::logic_error(fmt::format("the decision table has no curve for {} in arrangement {}", condition,
                                       arrangement));
}

std::string DecisionTable::json() const {
    Json j;
    j["format"] = "atonlab-decision-table";
    j["version"] = 1;
    j["key"] = key;
    j["bound"] = bound;
    j["largest_check"] = largest_check;
    j["stated_bound"] = stated_bound;
    j["bound_met"] = bound_met;
    j["renders"] = renders;
    j["build_s"] = build_s;
    j["displayability"] = displayability_json.empty() ? Json(nullptr) : Json::parse(displayability_json);
    j["refusal"] = refusal;
    Json cs = Json::array();
    for (const DecisionCurve& c : curves) {
        Json one;
        one["condition"] = c.condition;
        one["arrangement"] = c.arrangement;
        one["level_view"] = c.level_view;
        one["levels"] = c.levels;
        Json values = Json::array();
        for (double v : c.values) values.push_back(number_or_null(v));
        one["values"] = std::move(values);
        cs.push_back(std::move(one));
    }
    j["curves"] = std::move(cs);
    return j.dump(1);
}

DecisionTable DecisionTable::parse(const std::string& text) {
    const Json j = Json::parse(text, nullptr, false);
    if (!j.is_object() || j.value("format", "") != "atonlab-decision-table" || j.value("version", 0) != 1)
        throw std::runtime_error("not an atonlab decision table (version 1)");
    try {
        DecisionTable t;
        t.key = j.at("key").get<std::string>();
        t.bound = j.at("bound").get<double>();
        t.largest_check = j.at("largest_check").get<double>();
        t.stated_bound = j.at("stated_bound").get<double>();
        t.bound_met = j.at("bound_met").get<bool>();
        t.renders = j.at("renders").get<std::size_t>();
        t.build_s = j.at("build_s").get<double>();
        if (!j.at("displayability").is_null()) t.displayability_json = j.at("displayability").dump();
        t.refusal = j.at("refusal").get<std::string>();
        for (const Json& c : j.at("curves")) {
            DecisionCurve curve;
            curve.condition = c.at("condition").get<std::string>();
            curve.arrangement = c.at("arrangement").get<int>();
            curve.level_view = c.at("level_view").get<std::size_t>();
            curve.levels = c.at("levels").get<std::vector<double>>();
            for (const Json& v : c.at("values")) curve.values.push_back(v.is_null() ? -kInf : v.get<double>());
            if (curve.levels.size() != curve.values.size() || curve.levels.empty() ||
                !std::is_sorted(curve.levels.begin(), curve.levels.end()))
                throw std::runtime_error("a curve's levels and values do not match");
            t.curves.push_back(std::move(curve));
        }
        return t;
    } catch (const Json::exception& e) {
        throw std::runtime_error(fmt::format("a decision table's field is missing or of the wrong type: {}", e.what()));
    }
}

std::string table_key(const std::string& protocol_text, const std::string& scene_text,
                      const std::string& display_model_json, const p::ModelObserverParams& params, double bound) {
    Json j;
    j["atonlab"] = ATONLAB_VERSION;
    j["table_format"] = 1;
    j["protocol_sha256"] = store::sha256_hex(protocol_text);
    j["scene_sha256"] = store::sha256_hex(scene_text);
    j["display_model"] = display_model_json;
    j["window_radius_deg"] = params.window_radius_deg;
    j["exponent"] = params.exponent;
    j["detection_threshold_lux"] = params.detection_threshold_lux;
    j["bound"] = bound;
    return store::sha256_hex(j.dump());
}

DecisionTable build_decision_table(StimulusRenderer& renderer, const p::Protocol& protocol,
                                   const p::ModelObserverParams& params, double bound,
                                   const std::function<void(std::size_t, std::size_t)>& progress,
                                   std::size_t max_renders) {
    if (!(bound > 0.0)) throw std::invalid_argument("a decision table's bound must be > 0");
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::pair<const p::Condition*, int>> todo;
    std::vector<std::string> seen;
    for (const p::Block& b : protocol.blocks)
        for (const p::Condition& c : b.conditions) {
            if (std::find(seen.begin(), seen.end(), c.name) != seen.end()) continue;
            seen.push_back(c.name);
            if (c.task == p::Task::Adjust)
                throw InputError(SourceLocation{protocol.file, 0, 0, ""},
                                 fmt::format("condition \"{}\" is a method of adjustment, whose trials a decision "
                                             "table does not answer: simulate it with --render-every-trial.",
                                             c.name));
            if (c.task == p::Task::TwoAfc) todo.emplace_back(&c, 1);
            todo.emplace_back(&c, 0);
        }
    DecisionTable table;
    table.bound = bound;
    for (std::size_t i = 0; i < todo.size(); ++i) {
        if (progress) progress(i, todo.size());
        table.curves.push_back(
            build_curve(renderer, protocol, *todo[i].first, params, todo[i].second, bound, max_renders, table));
    }
    if (progress) progress(todo.size(), todo.size());
    table.build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return table;
}

std::optional<double> table_true_value(const DecisionTable& table, const p::Condition& c,
                                       const p::ModelObserverParams& params, std::string& why) {
    const std::optional<double> p_yes = c.procedure.target_p_yes();
    if (!p_yes) {
        why = "no target probability for this procedure";
        return std::nullopt;
    }
    const bool two_afc = c.task == p::Task::TwoAfc;
    const double p_target = two_afc && !c.yes_means_level() ? 1.0 - *p_yes : *p_yes;
    const std::optional<double> dstar = p::decision_at_probability(params, p_target);
    if (!dstar) {
        why = fmt::format("the lapses keep P from reaching {:.3f}", p_target);
        return std::nullopt;
    }
    // 2AFC: as true_value.h, the test on the left; P(level view chosen) = ψ(±Δ).
    const DecisionCurve& curve = table.curve(c.name, two_afc ? 1 : 0);
    const double sign = two_afc && curve.level_view == 1 ? -1.0 : 1.0;
    auto g = [&](std::size_t i) { return sign * curve.values[i] - *dstar; };
    for (std::size_t i = 0; i + 1 < curve.levels.size(); ++i) {
        const double ga = g(i), gb = g(i + 1);
        if (ga == 0.0) return curve.levels[i];
        if (!std::isfinite(ga) || !std::isfinite(gb)) {
            if ((ga < 0) != (gb < 0)) return curve.levels[i + 1];  // the onset of an increment
            continue;
        }
        if ((ga < 0) != (gb < 0)) return curve.levels[i] + (curve.levels[i + 1] - curve.levels[i]) * ga / (ga - gb);
    }
    if (g(curve.levels.size() - 1) == 0.0) return curve.levels.back();
    why = fmt::format("none in [{:.4g}, {:.4g}]: the decision variable does not reach the target there",
                      curve.levels.front(), curve.levels.back());
    return std::nullopt;
}

}  // namespace atonlab::runner
