#pragma once
// Study files for the analysis tests, made without GL: a protocol's Schedule
// (protocols/) proposes every trial exactly as `atonlab run` would, a
// simulated observer with a known psychometric function answers, and the
// store records each trial with a stimulus JSON in the runner's format
// (docs/running.md "What each trial stores"). The true PSE / threshold is a
// parameter here, so the analysis can be checked against it.
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <optional>
#include <string>

#include "atonlab/protocols/protocol_file.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/protocols/rng.h"
#include "atonlab/store/json.h"
#include "atonlab/store/store.h"

namespace atonlab::analysis::test_data {

/// The runner's stimulus JSON for a scheduled trial (the keys analysis reads).
inline std::string stimulus_json(const protocols::Condition& c, const protocols::ScheduledTrial& t) {
    namespace p = atonlab::protocols;
    using Json = nlohmann::ordered_json;
    Json frames = Json::array();
    for (const p::Frame& fr : t.stimulus.frames)
        frames.push_back(Json{{"role", fr.role ? std::string(p::to_string(*fr.role)) : std::string("both")},
                              {"time_s", 0},
                              {"overrides", fr.override_texts()}});
    Json views = Json::array();
    for (const p::StimulusView& v : t.stimulus.views)
        views.push_back(Json{{"frame", v.frame}, {"light", v.light}, {"role", p::to_string(v.role)}});
    return store::dump_json(Json{{"task", p::to_string(c.task)},
                                 {"presentation", p::to_string(c.presentation)},
                                 {"level_key", c.level_key},
                                 {"level_scale", p::to_string(c.level_scale)},
                                 {"level_on", p::to_string(c.level_on)},
                                 {"level", t.stimulus.level},
                                 {"scene_value", t.stimulus.scene_value},
                                 {"frames", std::move(frames)},
                                 {"views", std::move(views)}});
}

/// A simulated observer: P(outcome) = gamma + (1 - gamma) Phi((level - mu) / sigma)
/// (the outcome of dataset.h: 2AFC "chose the stimulus the level is on", yes-no "yes").
struct SimObserver {
    std::string code = "SIM";
    double mu = 2.0;
    double sigma = 0.1;
    double gamma = 0.0;
    std::uint64_t seed = 1;
    /// Stored as the session's SessionStart::simulation_json (a simulated
    /// session, docs/simulate.md); empty: an ordinary session.
    std::string simulation_json;
    /// Stored as the session's SessionStart::displayability_json (the check
    /// before the first trial, docs/running.md "Displayability"); empty: none.
    std::string displayability_json;
};

/// A SimObserver (named arguments without designated initializers, which warn when partial).
inline SimObserver sim(std::string code, double mu = 2.0, double sigma = 0.1, std::uint64_t seed = 1,
                       double gamma = 0.0) {
    SimObserver o;
    o.code = std::move(code);
    o.mu = mu;
    o.sigma = sigma;
    o.seed = seed;
    o.gamma = gamma;
    return o;
}

inline double phi(double z) {
    return 0.5 * std::erfc(-z / std::sqrt(2.0));
}

/// The scene the simulated sessions store (schema v6, docs/store.md
/// `scenes`): the lights the test protocols name, all white and fixed, so
/// that a protocol whose test and reference differ in glare alone is a
/// glare comparison.
inline const std::string kWhiteLightsScene = R"(
[display]
width_px = 320
height_px = 180
width_m = 0.1
viewing_distance_m = 0.9

[[light]]
name = "test"
position_m = [0.0, 3.0, -500.0]
intensity_cd = 100.0
colour = "white"

[[light]]
name = "reference"
position_m = [0.0, 3.0, -500.0]
intensity_cd = 100.0

[[light]]
name = "flash"
position_m = [0.0, 3.0, -500.0]
intensity_cd = 1.0
)";

/// Runs `protocol_text` (its scene need not exist) with the simulated
/// observer into the study file `db` as one completed session, storing
/// `scene_text` as its scene (empty: none, as a file from before schema v6).
/// Returns the session's id.
inline store::SessionId run_simulated(const std::filesystem::path& db, const std::string& protocol_text,
                                      const SimObserver& obs, std::uint64_t seed = 7, bool finish = true,
                                      std::size_t max_trials = 1u << 30,
                                      std::optional<store::CalibrationId> calibration = std::nullopt,
                                      const std::string& scene_text = kWhiteLightsScene) {
    namespace p = atonlab::protocols;
    const p::Protocol protocol = p::parse_protocol(protocol_text, "sim.toml");
    p::Schedule schedule(protocol, seed);
    store::Store s = store::Store::create_or_open(db);
    store::SessionStart start;
    start.observer_code = obs.code;
    start.protocol_text = protocol_text;
    start.protocol_name = "sim.toml";
    start.seed = seed;
    start.calibration = calibration;
    start.scene_text = scene_text;
    start.scene_name = "none.scene.toml";
    start.simulation_json = obs.simulation_json;
    start.displayability_json = obs.displayability_json;
    const store::SessionId session = s.begin_session(start);
    p::Rng rng(obs.seed);
    std::size_t n = 0;
    while (!schedule.finished() && n < max_trials) {
        const p::ScheduledTrial t = *schedule.next();
        const p::Condition& c = protocol.blocks[t.block].conditions[t.condition];
        const bool outcome =
            rng.uniform() < obs.gamma + (1.0 - obs.gamma) * phi((t.proposal.level - obs.mu) / obs.sigma);
        p::Response r{};
        std::string word;
        if (c.task == p::Task::TwoAfc) {
            // The outcome is "chose the level stimulus"; Left = the test's side when test_on_left.
            const bool chose_test = c.level_on == p::Role::Test ? outcome : !outcome;
            const bool left = chose_test == *t.proposal.test_on_left;
            r = left ? p::Response::Left : p::Response::Right;
            word = left ? "left" : "right";
        } else {
            r = outcome ? p::Response::Yes : p::Response::No;
            word = outcome ? "yes" : "no";
        }
        store::TrialRecord tr;
        tr.trial_index = static_cast<std::int64_t>(t.step);
        tr.block = static_cast<int>(t.block);
        tr.condition_id = t.condition_id;
        tr.procedure_id = t.procedure_id;
        tr.level = t.proposal.level;
        tr.test_on_left = t.proposal.test_on_left;
        tr.stimulus_json = stimulus_json(c, t);
        tr.response = word;
        tr.response_time_s = 0.5;
        tr.onset_time_s = static_cast<double>(t.step) * 2.0;
        tr.procedure_state_json = R"({"schedule":"sim"})";
        schedule.record(r);
        s.record_trial(session, tr);
        ++n;
    }
    if (finish)
        s.finish_session(session, schedule.finished() ? store::SessionStatus::completed : store::SessionStatus::quit);
    return session;
}

/// A 2AFC brightness match by constant stimuli, level on the reference (log10
/// cd), glare on the test only, test at 10^2 = 100 cd: the glare protocols' shape.
inline std::string constant_stimuli_protocol(int repetitions = 10) {
    return fmt::format(R"(
[protocol]
name = "sim-constant"
scene = "none.scene.toml"
seed = 3
[display]
width_px = 320
height_px = 180
width_m = 0.1
viewing_distance_m = 0.9
[defaults]
task = "2afc"
presentation = "two-interval"
test_light = "test"
reference_light = "reference"
test_set = ['eye.glare="wave-optics"', "light.reference.intensity_cd=0", "light.test.intensity_cd=100"]
reference_set = ['eye.glare="none"', "light.test.intensity_cd=0"]
level_key = "light.reference.intensity_cd"
level_scale = "log10"
choice = "chose-reference"
[defaults.procedure]
kind = "constant-stimuli"
levels = [1.7, 1.8, 1.9, 2.0, 2.1, 2.2, 2.3]
repetitions = {}
[[block]]
name = "night"
set = ["eye.adaptation_cd_m2=0.001", "environment.luminance_cd_m2=0.001"]
[[block.condition]]
name = "night-empirical"
set = ['tonemap.operator="empirical"']
[[block.condition]]
name = "night-perceptual"
set = ['tonemap.operator="perceptual"']
)",
                       repetitions);
}

/// Two interleaved 1-up/1-down staircases (2AFC, chose-reference) on one condition.
inline std::string staircase_protocol() {
    return R"(
[protocol]
name = "sim-staircase"
scene = "none.scene.toml"
seed = 5
[display]
width_px = 320
height_px = 180
width_m = 0.1
viewing_distance_m = 0.9
[defaults]
task = "2afc"
presentation = "two-interval"
test_light = "test"
reference_light = "reference"
test_set = ['eye.glare="wave-optics"', "light.reference.intensity_cd=0"]
reference_set = ['eye.glare="none"', "light.test.intensity_cd=0"]
level_key = "light.reference.intensity_cd"
level_scale = "log10"
choice = "chose-reference"
[defaults.procedure]
kind = "staircase"
start = [2.6, 1.4]
step_sizes = [0.2, 0.1, 0.05]
step_type = "lin"
n_up = 1
n_down = 1
n_reversals = 8
max_trials = 30
estimate_reversals = 6
[[block]]
name = "dusk"
set = ["eye.adaptation_cd_m2=1.0"]
[[block.condition]]
name = "stairs"
)";
}

/// Yes-no QUEST (two conditions).
inline std::string quest_protocol() {
    return R"(
[protocol]
name = "sim-quest"
scene = "none.scene.toml"
seed = 11
[display]
width_px = 320
height_px = 180
width_m = 0.1
viewing_distance_m = 0.9
[defaults]
task = "yes-no"
presentation = "single"
test_light = "flash"
level_key = "light.flash.intensity_cd"
level_scale = "log10"
[defaults.procedure]
kind = "quest"
t_guess = 0.0
t_guess_sd = 1.5
p_threshold = 0.75
beta = 3.5
delta = 0.02
gamma = 0.02
grain = 0.01
range = 6.0
n_trials = 40
[[block]]
name = "night"
set = ["eye.adaptation_cd_m2=0.001"]
[[block.condition]]
name = "fixed"
set = ['light.flash.rhythm="F"']
[[block.condition]]
name = "flashing"
set = ['light.flash.rhythm="Fl 2s"']
)";
}

}  // namespace atonlab::analysis::test_data
