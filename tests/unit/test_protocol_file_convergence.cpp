// The protocol -> schedule -> stimulus -> observer -> procedure wiring, end to
// end, without GL: with the model observer answering against a toy renderer,
// every example's procedures converge on the observer's true PSE or threshold.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <numbers>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "atonlab/protocols/observer.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/stimuli/scene_file.h"
#include "protocol_file_test_support.h"

namespace {

using namespace atonlab::protocols;                      // NOLINT: the test exercises the whole namespace
using namespace atonlab::protocols::protocol_file_test;  // NOLINT: the shared examples and readers
namespace fs = std::filesystem;

// ---- A toy renderer ---------------------------------------------------------
//
// It reads the scene overrides a protocol produces and draws each lit light as
// a Gaussian blob carrying I/d² lux on a uniform field: no glare -> 0.02° wide;
// any glare model -> 0.06° per mm of pupil (K2012 eq 3.15 from the adaptation
// level), so glare spreads the same energy wider; the "perceptual" tone mapper
// compresses luminance around the adaptation level (L' = La (L/La)^0.85); a
// flashing rhythm halves the effective energy. Not a model of anything: it
// only has to react to the overrides the way the renderer will, so that
// conditions have different true PSEs that the procedures must find.

constexpr int kToySize = 64;
constexpr double kToyDegPerPx = 0.04;

struct ToyLight {
    std::string name;
    double intensity_cd = 0.0;
    std::array<double, 3> position_m{};
    bool flashing = false;
    std::string glare;  ///< its own glare model; empty: the eye's
};

struct ToyScene {
    std::array<double, 3> camera_m{0.0, 3.0, 0.0};
    double background_cd_m2 = 0.0;
    double adaptation_cd_m2 = 0.001;
    std::string glare = "none";
    std::string tonemap = "empirical";
    std::vector<ToyLight> lights;
};

ToyScene toy_from_scene(const fs::path& scene_file) {
    const atonlab::stimuli::Scene s = atonlab::stimuli::load_scene(scene_file);
    ToyScene t;
    t.camera_m = {s.camera.position_m.x, s.camera.position_m.y, s.camera.position_m.z};
    t.background_cd_m2 = s.environment.luminance_cd_m2;
    t.adaptation_cd_m2 = s.adaptation_cd_m2;
    t.glare = std::string(atonlab::stimuli::glare_model_name(s.glare.model));
    for (const auto& l : s.lights)
        t.lights.push_back({l.name,
                            l.intensity_cd,
                            {l.position_m.x, l.position_m.y, l.position_m.z},
                            l.rhythm_period_s > 0.0,
                            l.glare ? std::string(atonlab::stimuli::glare_model_name(
                                          l.glare.value_or(atonlab::stimuli::GlareModel::none)))
                                    : std::string()});
    return t;
}

std::string unquote(const std::string& v) {
    return v.size() >= 2 && v.front() == '"' && v.back() == '"' ? v.substr(1, v.size() - 2) : v;
}

std::array<double, 3> parse_vec3(const std::string& v) {
    std::array<double, 3> out{};
    std::string s = v.substr(1, v.size() - 2);
    std::size_t pos = 0;
    for (double& x : out) {
        const std::size_t comma = s.find(',', pos);
        x = std::stod(s.substr(pos, comma - pos));
        pos = comma == std::string::npos ? s.size() : comma + 1;
    }
    return out;
}

ToyLight& toy_light(ToyScene& t, const std::string& name) {
    for (ToyLight& l : t.lights)
        if (l.name == name) return l;
    throw std::runtime_error("toy renderer: no light " + name);
}

void apply(ToyScene& t, const std::string& text) {
    const auto eq = text.find('=');
    const std::string key = text.substr(0, eq);
    const std::string value = text.substr(eq + 1);
    if (key.starts_with("display.")) return;  // the toy has its own pixels
    if (key == "eye.glare") {
        t.glare = unquote(value);
    } else if (key == "eye.adaptation_cd_m2") {
        t.adaptation_cd_m2 = std::stod(value);
    } else if (key == "environment.luminance_cd_m2") {
        t.background_cd_m2 = std::stod(value);
    } else if (key == "tonemap.operator") {
        t.tonemap = unquote(value);
    } else if (key.starts_with("light.")) {
        const std::size_t dot = key.rfind('.');
        const std::string name = key.substr(6, dot - 6);
        const std::string field = key.substr(dot + 1);
        ToyLight& l = toy_light(t, name);
        if (field == "intensity_cd")
            l.intensity_cd = std::stod(value);
        else if (field == "position_m")
            l.position_m = parse_vec3(value);
        else if (field == "rhythm")
            l.flashing = unquote(value) != "F";
        else if (field == "glare")
            l.glare = unquote(value);
        else
            throw std::runtime_error("toy renderer: unknown light key " + key);
    } else {
        throw std::runtime_error("toy renderer: unknown key " + key);
    }
}

ToyScene toy_with(const ToyScene& base, const std::vector<std::string>& overrides) {
    ToyScene t = base;
    for (const std::string& o : overrides) apply(t, o);
    return t;
}

/// The light's image position: centre of the image is straight ahead (north, level).
glm::dvec2 toy_pixel(const ToyScene& t, const std::string& light) {
    const double c = kToySize / 2.0;
    if (light.empty()) return {c, c};
    const ToyLight& l = toy_light(const_cast<ToyScene&>(t), light);
    const double dx = l.position_m[0] - t.camera_m[0];
    const double dy = l.position_m[1] - t.camera_m[1];
    const double dz = -(l.position_m[2] - t.camera_m[2]);
    const double az = std::atan2(dx, dz) * 180.0 / std::numbers::pi;
    const double el = std::atan2(dy, std::hypot(dx, dz)) * 180.0 / std::numbers::pi;
    return {c + az / kToyDegPerPx, c - el / kToyDegPerPx};
}

DisplayedImage toy_render(const ToyScene& t) {
    DisplayedImage img;
    img.width = kToySize;
    img.height = kToySize;
    img.deg_per_px = kToyDegPerPx;
    std::vector<double> l(static_cast<std::size_t>(kToySize * kToySize), t.background_cd_m2);
    const double pupil_mm = 4.9 - 3.0 * std::tanh(0.4 * (std::log10(t.adaptation_cd_m2) + 1.0));  // K2012 eq 3.15
    for (const ToyLight& light : t.lights) {
        if (light.intensity_cd <= 0.0) continue;
        const std::string& glare = light.glare.empty() ? t.glare : light.glare;
        const double sigma_deg = glare == "none" ? 0.02 : 0.06 * pupil_mm;
        const double sigma_px = sigma_deg / kToyDegPerPx;
        const double sigma_rad = sigma_deg * std::numbers::pi / 180.0;
        const double dx = light.position_m[0] - t.camera_m[0];
        const double dy = light.position_m[1] - t.camera_m[1];
        const double dz = light.position_m[2] - t.camera_m[2];
        const double e_lux = light.intensity_cd / (dx * dx + dy * dy + dz * dz) * (light.flashing ? 0.5 : 1.0);
        const double peak = e_lux / (2.0 * std::numbers::pi * sigma_rad * sigma_rad);  // cd/m²
        const glm::dvec2 c = toy_pixel(t, light.name);
        for (int y = 0; y < kToySize; ++y)
            for (int x = 0; x < kToySize; ++x) {
                const double rx = x + 0.5 - c.x;
                const double ry = y + 0.5 - c.y;
                l[static_cast<std::size_t>(y * kToySize + x)] +=
                    peak * std::exp(-(rx * rx + ry * ry) / (2.0 * sigma_px * sigma_px));
            }
    }
    const auto tonemap = [&](double v) {
        return t.tonemap == "perceptual" ? t.adaptation_cd_m2 * std::pow(v / t.adaptation_cd_m2, 0.85) : v;
    };
    img.luminance_cd_m2.resize(l.size());
    for (std::size_t i = 0; i < l.size(); ++i) img.luminance_cd_m2[i] = static_cast<float>(tonemap(l[i]));
    // What the screen shows with the lights off, as the runner gives the model
    // observer (observer.h DisplayedImage::background_cd_m2).
    img.background_cd_m2.assign(l.size(), static_cast<float>(tonemap(t.background_cd_m2)));
    return img;
}

/// Renders a stimulus and shows it to an observer.
struct Rendered {
    std::vector<DisplayedImage> images;
    Shown shown;
};

Rendered render_stimulus(const ToyScene& base, const Stimulus& stimulus, Task task) {
    Rendered r;
    std::vector<ToyScene> scenes;
    for (const Frame& f : stimulus.frames) {
        scenes.push_back(toy_with(base, f.override_texts()));
        r.images.push_back(toy_render(scenes.back()));
    }
    r.shown.task = task;
    for (const StimulusView& v : stimulus.views)
        r.shown.views.push_back({&r.images[v.frame], toy_pixel(scenes[v.frame], v.light)});
    r.shown.adjusted_view = stimulus.adjusted_view;
    return r;
}

struct DriveResult {
    std::size_t steps = 0;   ///< answers given (adjustment actions count one each)
    std::size_t trials = 0;  ///< trials (an adjustment match counts one)
    std::vector<TrackResult> results;
};

DriveResult drive(const Protocol& p, std::uint64_t seed, Observer& observer) {
    const ToyScene base = toy_from_scene(p.scene);
    Schedule s(p, seed);
    DriveResult out;
    std::set<std::pair<std::string, std::size_t>> trials;
    while (auto t = s.next()) {
        Rendered r = render_stimulus(base, t->stimulus, t->task);
        // r.images must not move after views point into it.
        for (std::size_t i = 0; i < r.shown.views.size(); ++i)
            r.shown.views[i].image = &r.images[t->stimulus.views[i].frame];
        trials.insert({t->procedure_id, t->proposal.trial});
        s.record(observer.answer(r.shown).response);
        ++out.steps;
        if (out.steps > 100000) throw std::runtime_error("the schedule does not end");
    }
    out.trials = trials.size();
    out.results = s.results();
    return out;
}

// ---- Convergence with the model observer -------------------------------------------

/// A condition's frames in the toy renderer, as a function of the level.
struct ToyCondition {
    const Protocol& protocol;
    const Condition& condition;
    const ToyScene& base;

    /// The scene and the light of `role`'s view at `level` (test shown first).
    std::pair<ToyScene, std::string> view(double level, Role role) const {
        Proposal prop;
        prop.level = level;
        prop.test_on_left = true;
        const Stimulus s = make_stimulus(protocol, condition, prop);
        for (const StimulusView& v : s.views)
            if (v.role == role) return {toy_with(base, s.frames[v.frame].override_texts()), v.light};
        throw std::runtime_error("no view");
    }
    DisplayedImage image(double level, Role role) const { return toy_render(view(level, role).first); }
    glm::dvec2 pixel(Role role) const {
        const auto [scene, light] = view(0.0, role);
        return toy_pixel(scene, light);
    }
};

/// The observer's true value for a condition: the PSE (2AFC and adjust: the
/// reference level matching the test in brightness) or the threshold (yes-no:
/// the level seen with QUEST's p_threshold).
double truth(const ToyCondition& tc, const ModelObserverParams& params) {
    const auto image_at = [&](Role role) { return [&tc, role](double level) { return tc.image(level, role); }; };
    if (tc.condition.task == Task::YesNo)
        return true_threshold(image_at(Role::Test), tc.pixel(Role::Test),
                              std::get<QuestParams>(tc.condition.procedure.params).p_threshold, -3.0, 3.0, params);
    // Search 3 log10 units either side of where the procedure starts (the
    // examples centre it on each block's test intensity).
    double centre = 0.0;
    const ProcedureSpec& spec = tc.condition.procedure;
    if (!spec.track_starts.empty()) {
        centre = 0.5 * (*std::min_element(spec.track_starts.begin(), spec.track_starts.end()) +
                        *std::max_element(spec.track_starts.begin(), spec.track_starts.end()));
    } else if (const auto* a = std::get_if<AdjustmentParams>(&spec.params)) {
        centre = 0.5 * (a->start_min + a->start_max);
    } else if (const auto* cs = std::get_if<ConstantStimuliParams>(&spec.params)) {
        centre = 0.5 * (cs->levels.front() + cs->levels.back());
    }
    return true_pse(image_at(Role::Reference), tc.pixel(Role::Reference), tc.image(0.0, Role::Test),
                    tc.pixel(Role::Test), centre - 3.0, centre + 3.0, params);
}

/// The standard error of the PSE that N binary trials at the constant-stimuli
/// levels can give at best (Cramér-Rao: 1/sqrt(Σ n_i P_i'² / (P_i (1 − P_i)))),
/// from the model's exact P(reference chosen) at each level.
double constant_stimuli_se(const ToyCondition& tc, const ModelObserverParams& params) {
    const auto& cp = std::get<ConstantStimuliParams>(tc.condition.procedure.params);
    const DisplayedImage test = tc.image(0.0, Role::Test);
    const View test_view{&test, tc.pixel(Role::Test)};
    const auto p_ref = [&](double level) {
        const DisplayedImage ref = tc.image(level, Role::Reference);
        return model_p_first(params, View{&ref, tc.pixel(Role::Reference)}, test_view);
    };
    double information = 0.0;
    for (double level : cp.levels) {
        const double h = 1e-3;
        const double slope = (p_ref(level + h) - p_ref(level - h)) / (2 * h);
        const double p = p_ref(level);
        information += cp.repetitions * slope * slope / (p * (1 - p));
    }
    return 1.0 / std::sqrt(information);
}

struct ConditionOutcome {
    double estimate = 0.0;
    double ci = 0.0;  ///< half-width of the interval the estimate claims
};

/// A condition's estimate (the mean of its tracks') and the half-width of a
/// 99.7% interval for it:
///  - staircases: 3 x (sd of the reversal levels)/sqrt(reversals), plus one
///    final step (reversal levels are autocorrelated and quantised to the step,
///    so the naive standard error alone is too small);
///  - adjustment: 3 x sd/sqrt(n) of the matches, the sd pooled over the run's
///    conditions, plus one fine step (the model observer confirms on a
///    reversal, up to a step past equality on the side it came from);
///  - QUEST: 3 posterior sd;
///  - constant stimuli: 3 x the Cramér-Rao standard error of the PSE for the
///    design, plus a quarter of the level spacing (estimate() interpolates
///    linearly between levels instead of fitting).
std::map<std::string, ConditionOutcome> outcomes(const Protocol& p, const ToyScene& base, const DriveResult& r,
                                                 const ModelObserverParams& params) {
    std::map<std::string, ConditionOutcome> out;
    std::map<std::string, std::vector<const TrackResult*>> by;
    for (const TrackResult& t : r.results) by[t.condition_id].push_back(&t);
    // The spread of one observer's matches is the same in every condition (its
    // noise): pooled over the run, it is known far better than from 6 matches.
    double adjustment_var = 0.0;
    std::size_t adjustment_tracks = 0;
    for (const TrackResult& t : r.results)
        if (p.find_condition(t.condition_id)->procedure.kind == ProcedureKind::Adjustment) {
            adjustment_var += t.estimate.sd * t.estimate.sd;
            ++adjustment_tracks;
        }
    const double pooled_adjustment_sd =
        adjustment_tracks > 0 ? std::sqrt(adjustment_var / static_cast<double>(adjustment_tracks)) : 0.0;
    for (const auto& [name, tracks] : by) {
        const Condition& c = *p.find_condition(name);
        ConditionOutcome o;
        double sum = 0, var = 0;
        std::size_t n = 0;
        for (const TrackResult* t : tracks) {
            EXPECT_TRUE(t->finished) << t->procedure_id;
            sum += t->estimate.value;
            var += t->estimate.sd * t->estimate.sd;
            n += t->estimate.n;
        }
        const double k = static_cast<double>(tracks.size());
        o.estimate = sum / k;
        const double sd = std::sqrt(var / k);
        const double root_n = std::sqrt(static_cast<double>(n));
        switch (c.procedure.kind) {
            case ProcedureKind::Staircase:
                o.ci = 3.0 * sd / root_n + std::get<StaircaseParams>(c.procedure.params).step_sizes.back();
                break;
            case ProcedureKind::WeightedStaircase:
                o.ci = 3.0 * sd / root_n + std::get<WeightedStaircaseParams>(c.procedure.params).step_sizes.back();
                break;
            case ProcedureKind::Adjustment:
                o.ci = 3.0 * pooled_adjustment_sd / root_n + std::get<AdjustmentParams>(c.procedure.params).fine_step;
                break;
            case ProcedureKind::Quest:
                o.ci = 3.0 * sd;
                break;
            case ProcedureKind::ConstantStimuli: {
                const auto& cp = std::get<ConstantStimuliParams>(c.procedure.params);
                o.ci = 3.0 * constant_stimuli_se(ToyCondition{p, c, base}, params) +
                       0.25 * std::abs(cp.levels[1] - cp.levels[0]);
                break;
            }
        }
        out[name] = o;
    }
    return out;
}

TEST(ProtocolConvergence, EveryExampleFindsTheModelObserversTruePoint) {
    ModelObserverParams params;
    params.noise_sd_log10 = 0.03;
    params.lapse_rate = 0.02;
    for (const std::string& name : kExamples) {
        // Its lights stand 5° either side of the centre, outside the toy's
        // 2.56° field; tests/gl/test_example_convergence.cpp runs it on the
        // real renderer (GL.ExampleConvergence.GlareSideBySide).
        if (name == "glare_side_by_side.toml") continue;
        const Protocol p = load_protocol(example(name));
        const ToyScene base = toy_from_scene(p.scene);
        std::map<std::string, double> truths;
        for (const Block& b : p.blocks)
            for (const Condition& c : b.conditions) truths[c.name] = truth(ToyCondition{p, c, base}, params);
        for (std::uint64_t seed : {1u, 2u, 3u}) {
            SCOPED_TRACE(name + " seed " + std::to_string(seed));
            ModelObserver observer(params, 1000 + seed);
            const DriveResult r = drive(p, seed, observer);
            EXPECT_LE(r.trials, 300u);
            for (const auto& [condition, o] : outcomes(p, base, r, params)) {
                const double t = truths.at(condition);
                std::printf(
                    "%-30s seed %llu  %-20s true %.3f  estimate %.3f  error %+.3f  ci %.3f  trials %zu steps %zu\n",
                    name.c_str(), static_cast<unsigned long long>(seed), condition.c_str(), t, o.estimate,
                    o.estimate - t, o.ci, r.trials, r.steps);
                EXPECT_NEAR(o.estimate, t, o.ci) << condition;
            }
        }
    }
}

}  // namespace
