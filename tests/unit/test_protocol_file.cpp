// The protocol file and the schedule: every example protocol parses, its scene
// takes every condition's overrides, its schedule is a pure function of (protocol,
// seed, responses) and replays exactly; every malformed file is one sentence
// naming the file, the line and the key; and with the model observer answering
// against a toy renderer, every example's procedures converge on the observer's
// true PSE or threshold (the protocol -> schedule -> stimulus -> observer ->
// procedure wiring, end to end, without GL).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <numbers>
#include <numeric>
#include <set>
#include <string>
#include <vector>

#include "atonlab/protocols/observer.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/common/input_error.h"
#include "atonlab/stimuli/scene_file.h"

namespace {

using namespace atonlab::protocols;  // NOLINT: the test exercises the whole namespace
namespace fs = std::filesystem;

fs::path source_dir() {
    return fs::path(ATONLAB_SOURCE_DIR);
}
fs::path example(std::string_view name) {
    return source_dir() / "protocols" / "examples" / name;
}

const std::vector<std::string> kExamples = {"glare_brightness_2afc.toml", "glare_brightness_adjust.toml",
                                            "glare_constant_stimuli.toml", "flash_detection.toml",
                                            "glare_side_by_side.toml"};

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

// ---- Examples ----------------------------------------------------------------

TEST(ProtocolExamples, ParseWithTheDocumentedShape) {
    for (const std::string& name : kExamples) {
        SCOPED_TRACE(name);
        const Protocol p = load_protocol(example(name));
        EXPECT_FALSE(p.name.empty());
        EXPECT_TRUE(fs::is_regular_file(p.scene)) << p.scene;
        EXPECT_EQ(p.display.width_px, 1920);
        EXPECT_FALSE(p.blocks.empty());
        for (const Block& b : p.blocks) EXPECT_FALSE(b.conditions.empty());
    }
    const Protocol p = load_protocol(example("glare_brightness_2afc.toml"));
    ASSERT_EQ(p.blocks.size(), 3u);
    EXPECT_EQ(p.blocks[0].adaptation_s, 300.0);  // its own
    EXPECT_EQ(p.blocks[1].adaptation_s, 120.0);  // [protocol] adaptation_s
    const Condition& c = p.blocks[0].conditions[1];
    EXPECT_EQ(c.name, "L0.001-perceptual");
    EXPECT_EQ(c.task, Task::TwoAfc);
    EXPECT_EQ(c.presentation, Presentation::TwoInterval);
    EXPECT_EQ(c.level_key, "light.reference.intensity_cd");
    EXPECT_EQ(c.level_scale, LevelScale::Log10);
    EXPECT_EQ(c.choice, ChoiceMapping::ChoseReference);
    // set: the block's, then the condition's.
    ASSERT_EQ(c.set.size(), 4u);
    EXPECT_EQ(c.set[0].text(), "eye.adaptation_cd_m2=0.001");
    EXPECT_EQ(c.set[2].text(), "light.test.intensity_cd=0.0005");
    EXPECT_EQ(c.set[3].text(), "tonemap.operator=\"perceptual\"");
    ASSERT_EQ(c.procedure.kind, ProcedureKind::Staircase);
    // The block's inline procedure table merges key by key into [defaults.procedure].
    EXPECT_EQ(c.procedure.track_starts, (std::vector<double>{-2.8, -3.8}));
    const auto& sp = std::get<StaircaseParams>(c.procedure.params);
    EXPECT_EQ(sp.step_sizes, (std::vector<double>{0.2, 0.1, 0.05}));
    EXPECT_EQ(sp.step_type, StepType::Lin);
    EXPECT_EQ(sp.max_trials, 24);
    EXPECT_EQ(sp.min_level, -4.3);
    EXPECT_EQ(sp.max_level, -2.3);
    EXPECT_EQ(p.responses.keys_of(Action::Left), (std::vector<std::string>{"left", "1"}));
    EXPECT_EQ(p.responses.key_action(Task::TwoAfc, "2"), Action::Right);
    EXPECT_EQ(p.responses.key_action(Task::TwoAfc, "escape"), Action::Quit);
    EXPECT_EQ(p.responses.key_action(Task::TwoAfc, "y"), std::nullopt);  // not a 2AFC answer
    EXPECT_EQ(p.responses.button_action(Task::TwoAfc, "dpad_right"), Action::Right);
    EXPECT_EQ(p.responses.screen_key_action("space"), Action::Continue);
}

TEST(ProtocolExamples, TheDocumentsCompleteExampleParses) {
    std::ifstream in(source_dir() / "docs" / "protocol-file.md");
    const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string marker = "## A complete example\n\n```toml\n";
    const auto begin = doc.find(marker);
    ASSERT_NE(begin, std::string::npos);
    const auto end = doc.find("```", begin + marker.size());
    const std::string text = doc.substr(begin + marker.size(), end - begin - marker.size());
    // Named as if it sat next to the examples, so that its scene resolves there.
    const Protocol p = parse_protocol(text, example("complete-example.toml").string());
    EXPECT_TRUE(fs::is_regular_file(p.scene));
    ASSERT_EQ(p.blocks.size(), 1u);
    EXPECT_EQ(p.blocks[0].conditions.size(), 2u);
    EXPECT_EQ(p.blocks[0].conditions[1].procedure.tracks(), 2u);
}

TEST(ProtocolExamples, TheSceneTakesEveryConditionsOverrides) {
    // Each frame's overrides, applied by the scene loader itself, so every key
    // and value a condition sets is checked as strictly as the scene file. Only
    // while the scene loader still refuses the [tonemap] table as "not available
    // yet" are the tonemap.* overrides (which the protocol passes on opaquely)
    // left out.
    using atonlab::stimuli::SceneOverride;
    const auto load = [](const fs::path& scene, const std::vector<std::string>& texts, bool with_tonemap) {
        std::vector<SceneOverride> overrides;
        for (const std::string& o : texts)
            if (with_tonemap || !o.starts_with("tonemap.")) overrides.push_back(SceneOverride::parse(o));
        (void)atonlab::stimuli::load_scene(scene, overrides);
    };
    for (const std::string& name : kExamples) {
        SCOPED_TRACE(name);
        const Protocol p = load_protocol(example(name));
        for (const Block& b : p.blocks)
            for (const Condition& c : b.conditions) {
                SCOPED_TRACE(c.name);
                const auto proc = make_procedure(c, 1);
                const Stimulus s = make_stimulus(p, c, *proc->next());
                for (const Frame& f : s.frames) {
                    try {
                        try {
                            load(p.scene, f.override_texts(), true);
                        } catch (const atonlab::InputError& e) {
                            const bool tonemap_not_yet = e.where() && e.where()->key.starts_with("tonemap") &&
                                                         e.message().find("not available yet") != std::string::npos;
                            if (!tonemap_not_yet) throw;
                            load(p.scene, f.override_texts(), false);
                        }
                    } catch (const atonlab::InputError& e) {
                        ADD_FAILURE() << e.what();
                    }
                }
            }
    }
}

TEST(ProtocolExamples, StimuliFollowThePresentation) {
    const Protocol p = load_protocol(example("glare_brightness_2afc.toml"));
    const Condition& c = p.blocks[0].conditions[0];
    Proposal prop;
    prop.level = 2.0;
    prop.test_on_left = false;  // the reference goes first
    const Stimulus s = make_stimulus(p, c, prop);
    ASSERT_EQ(s.frames.size(), 2u);
    EXPECT_EQ(s.frames[0].role, Role::Reference);
    EXPECT_EQ(s.frames[1].role, Role::Test);
    EXPECT_EQ(s.scene_value, 100.0);
    const auto& ref = s.frames[0].override_texts();
    EXPECT_EQ(ref.front(), "display.width_px=1920");
    EXPECT_EQ(ref.back(), "light.reference.intensity_cd=100");
    EXPECT_NE(std::find(ref.begin(), ref.end(), "eye.glare=\"none\""), ref.end());
    const auto& test = s.frames[1].override_texts();
    EXPECT_NE(std::find(test.begin(), test.end(), "eye.glare=\"wave-optics\""), test.end());
    EXPECT_EQ(std::find(test.begin(), test.end(), "light.reference.intensity_cd=100"), test.end());
    ASSERT_EQ(s.views.size(), 2u);
    EXPECT_EQ(s.views[0].light, "reference");
    EXPECT_EQ(s.views[1].light, "test");
}

// ---- The schedule ---------------------------------------------------------------

/// A response the task takes, drawn from `rng`.
Response random_response(Task task, Rng& rng) {
    switch (task) {
        case Task::TwoAfc:
            return rng.coin() ? Response::Left : Response::Right;
        case Task::YesNo:
            return rng.coin() ? Response::Yes : Response::No;
        case Task::Adjust: {
            constexpr Response kActions[] = {Response::CoarseUp, Response::CoarseDown, Response::FineUp,
                                             Response::FineDown, Response::Confirm};
            return kActions[rng.below(5)];
        }
    }
    return Response::No;
}

struct Step {
    std::string procedure_id;
    double level = 0.0;
    std::optional<bool> test_on_left;
    std::string state;
    bool operator==(const Step&) const = default;
};

/// Runs the schedule on random answers (their own stream, `answers_seed`) and
/// logs each trial shown, up to `max_steps`.
std::vector<Step> run_random(const Protocol& p, std::uint64_t seed, std::uint64_t answers_seed,
                             std::vector<Response>* responses = nullptr, std::size_t max_steps = 100000) {
    Schedule s(p, seed);
    Rng rng(answers_seed);
    std::vector<Step> steps;
    while (auto t = s.next()) {
        if (steps.size() >= max_steps) break;
        steps.push_back({t->procedure_id, t->proposal.level, t->proposal.test_on_left, s.state()});
        const Response r = random_response(t->task, rng);
        if (responses) responses->push_back(r);
        s.record(r);
    }
    return steps;
}

TEST(ProtocolSchedule, IsAPureFunctionOfTheSeedAndTheAnswers) {
    for (const std::string& name : kExamples) {
        SCOPED_TRACE(name);
        const Protocol p = load_protocol(example(name));
        const auto a = run_random(p, p.seed, 5);
        const auto b = run_random(p, p.seed, 5);
        EXPECT_EQ(a, b);
        const auto c = run_random(p, p.seed + 1, 5);
        EXPECT_NE(a, c);
        // A different seed changes the order of the trials, not only the levels.
        std::vector<std::string> ida, idc;
        for (const Step& s : a) ida.push_back(s.procedure_id);
        for (const Step& s : c) idc.push_back(s.procedure_id);
        EXPECT_NE(ida, idc);
    }
}

TEST(ProtocolSchedule, ReplayOfAPrefixResumesExactly) {
    for (const std::string& name : kExamples) {
        SCOPED_TRACE(name);
        const Protocol p = load_protocol(example(name));
        std::vector<Response> responses;
        const auto whole = run_random(p, 99, 17, &responses);
        ASSERT_GT(whole.size(), 40u);
        for (std::size_t k :
             {std::size_t{0}, std::size_t{1}, std::size_t{7}, whole.size() / 3, whole.size() / 2, whole.size() - 1}) {
            SCOPED_TRACE(k);
            const Schedule resumed = Schedule::replay(p, 99, std::span(responses).first(k));
            const auto t = resumed.next();
            ASSERT_TRUE(t.has_value());
            EXPECT_EQ(t->step, k);
            EXPECT_EQ(t->procedure_id, whole[k].procedure_id);
            EXPECT_EQ(t->proposal.level, whole[k].level);  // bit for bit
            EXPECT_EQ(t->proposal.test_on_left, whole[k].test_on_left);
            EXPECT_EQ(resumed.state(), whole[k].state);
        }
        const Schedule done = Schedule::replay(p, 99, responses);
        EXPECT_TRUE(done.finished());
        std::vector<Response> too_many = responses;
        too_many.push_back(Response::Left);
        EXPECT_THROW((void)Schedule::replay(p, 99, too_many), ProcedureError);
    }
}

TEST(ProtocolSchedule, BlocksRunInOrderWithTheirRepetitions) {
    Protocol p = load_protocol(example("glare_brightness_2afc.toml"));
    p.blocks[1].repetitions = 2;
    Schedule s(p, 3);
    ASSERT_EQ(s.block_runs().size(), 4u);
    EXPECT_EQ(s.block_runs()[2].block, 1u);
    EXPECT_EQ(s.block_runs()[2].repetition, 1);
    Rng rng(1);
    std::vector<std::size_t> runs;
    std::size_t starts = 0;
    while (auto t = s.next()) {
        if (runs.empty() || runs.back() != t->run) runs.push_back(t->run);
        starts += t->starts_run ? 1 : 0;
        EXPECT_EQ(t->block, s.block_runs()[t->run].block);
        s.record(random_response(t->task, rng));
    }
    EXPECT_EQ(runs, (std::vector<std::size_t>{0, 1, 2, 3}));
    EXPECT_EQ(starts, 4u);
    // Every track of every run finished: 4 runs x 2 conditions x 2 tracks.
    const auto results = s.results();
    EXPECT_EQ(results.size(), 16u);
    for (const TrackResult& r : results) EXPECT_TRUE(r.finished) << r.procedure_id;
    EXPECT_EQ(results[4].procedure_id, "L0.03-empirical/r0/t0");
    EXPECT_EQ(results[8].procedure_id, "L0.03-empirical/r1/t0");
}

TEST(ProtocolSchedule, RefusesAnswersTheTaskDoesNotTake) {
    const Protocol p = load_protocol(example("glare_brightness_2afc.toml"));
    Schedule s(p, 1);
    const std::string before = s.state();
    EXPECT_THROW(s.record(Response::Yes), ProcedureError);
    EXPECT_EQ(s.state(), before);
    EXPECT_TRUE(s.history().empty());
}

TEST(ProtocolSchedule, MakeProcedureBuildsTheSameTracksAsTheSchedule) {
    const Protocol p = load_protocol(example("glare_brightness_2afc.toml"));
    const Condition& c = p.blocks[0].conditions[0];
    const auto proc = make_procedure(c, 11);
    EXPECT_EQ(proc->kind(), "interleaved");  // two tracks
    const auto track = make_track(c, 1, derive_seed(11, 1));
    EXPECT_EQ(track->kind(), "2afc");
    EXPECT_EQ(track->next()->level, -3.8);
    EXPECT_TRUE(track->next()->test_on_left.has_value());
    EXPECT_THROW((void)make_track(c, 2, 0), std::out_of_range);
}

// ---- Schema details (inline protocols) --------------------------------------------

const char* const kHeader = R"([protocol]
scene = "scene.toml"
seed = 5

[display]
width_px = 800
height_px = 600
width_m = 0.4
viewing_distance_m = 0.6
)";

Protocol parse(const std::string& body) {
    return parse_protocol(std::string(kHeader) + body, "inline.toml");
}

std::string error_of(const std::string& body) {
    try {
        (void)parse(body);
    } catch (const atonlab::InputError& e) {
        return e.what();
    }
    return "(no InputError)";
}

TEST(ProtocolSchema, SideBySideSwapsThePositionsWithTheForcedChoice) {
    const Protocol p = parse(R"(
[[block]]
[[block.condition]]
name = "colour"
task = "2afc"
presentation = "side-by-side"
test_light = "red"
reference_light = "white"
left_position_m = [-10.0, 3.0, -500.0]
right_position_m = [10.0, 3.0, -500.0]
level_key = "light.white.intensity_cd"
procedure = { kind = "weighted-staircase", start = 2.0, target = 0.75, step_sizes = 0.05, step_type = "lin", n_trials = 30 }
)");
    EXPECT_EQ(p.scene, fs::path("scene.toml"));
    EXPECT_EQ(p.blocks[0].name, "block0");
    const Condition& c = p.blocks[0].conditions[0];
    Proposal prop;
    prop.level = 1.0;
    prop.test_on_left = true;
    Stimulus s = make_stimulus(p, c, prop);
    ASSERT_EQ(s.frames.size(), 1u);
    EXPECT_FALSE(s.frames[0].role.has_value());
    const auto& o = s.frames[0].override_texts();
    EXPECT_NE(std::find(o.begin(), o.end(), "light.red.position_m=[-10, 3, -500]"), o.end());
    EXPECT_NE(std::find(o.begin(), o.end(), "light.white.position_m=[10, 3, -500]"), o.end());
    EXPECT_NE(std::find(o.begin(), o.end(), "light.white.intensity_cd=10"), o.end());
    EXPECT_EQ(s.views[0].light, "red");
    EXPECT_EQ(s.views[1].light, "white");
    prop.test_on_left = false;
    s = make_stimulus(p, c, prop);
    const std::vector<std::string> swapped = s.frames[0].override_texts();
    EXPECT_NE(std::find(swapped.begin(), swapped.end(), "light.red.position_m=[10, 3, -500]"), swapped.end());
    EXPECT_EQ(s.views[0].light, "white");
    EXPECT_EQ(make_track(c, 0, 1)->kind(), "2afc");
}

TEST(ProtocolSchema, ConditionsInheritAndAProcedureOfAnotherKindStartsAfresh) {
    const Protocol p = parse(R"(
[defaults]
task = "yes-no"
level_key = "light.l.intensity_cd"
set = ["eye.glare=\"none\""]
procedure = { kind = "quest", t_guess = 0.0, n_trials = 20 }

[[block]]
name = "b"
set = ["eye.adaptation_cd_m2=0.01"]
procedure = { n_trials = 25 }

[[block.condition]]
name = "inherits"

[[block.condition]]
name = "staircase"
level_scale = "linear"
set = "light.l.rhythm=\"Fl 2s\""
[block.condition.procedure]
kind = "staircase"
start = 5.0
step_type = "lin"
step_sizes = [1.0]
n_trials = 10
)");
    const Condition& a = p.blocks[0].conditions[0];
    EXPECT_EQ(a.task, Task::YesNo);
    EXPECT_EQ(a.presentation, Presentation::Single);
    EXPECT_EQ(a.level_on, Role::Test);
    EXPECT_EQ(a.set.size(), 2u);
    EXPECT_EQ(std::get<QuestParams>(a.procedure.params).n_trials, 25);
    const Condition& b = p.blocks[0].conditions[1];
    EXPECT_EQ(b.set.size(), 3u);
    EXPECT_EQ(b.set[2].text(), "light.l.rhythm=\"Fl 2s\"");
    ASSERT_EQ(b.procedure.kind, ProcedureKind::Staircase);
    EXPECT_EQ(std::get<StaircaseParams>(b.procedure.params).n_trials, 10);
    EXPECT_EQ(b.scene_value(5.0), 5.0);
    EXPECT_EQ(a.scene_value(1.0), 10.0);
}

TEST(ProtocolSchema, EachErrorIsOneSentenceAtItsLine) {
    // Line numbers count the 9-line header.
    EXPECT_EQ(error_of(R"(
[[block]]
[[block.condition]]
task = "2afc"
level_key = "light.r.intensity_cd"
procedure = { kind = "staircase", start = 1.0, step_type = "lin", n_reversals = 4 }
[[block.condition]]
name = "block0-c0"
)"),
              "inline.toml:17: key 'block[0].condition[1].name': a condition called \"block0-c0\" already exists "
              "(line 12); condition names are unique in the protocol.");
    EXPECT_EQ(error_of(R"(
[[block]]
[[block.condition]]
task = "adjust"
level_key = "light.r.intensity_cd"
procedure = { kind = "staircase", start = 1.0, step_type = "lin", n_reversals = 4 }
)"),
              "inline.toml:15: key 'block[0].condition[0].procedure.kind': in condition \"block0-c0\", task = "
              "\"adjust\" needs kind = \"adjustment\", not \"staircase\".");
    EXPECT_EQ(error_of(R"(
[[block]]
[[block.condition]]
task = "yes-no"
level_key = "light.r.intensity_cd"
level_scale = "linear"
procedure = { kind = "quest", t_guess = 1.0, n_trials = 4 }
)"),
              "inline.toml:15: key 'block[0].condition[0].level_scale': in condition \"block0-c0\", QUEST works in "
              "log10 units (its Weibull is a function of log intensity): level_scale must be \"log10\".");
    EXPECT_EQ(error_of(R"(
[[block]]
[[block.condition]]
task = "2afc"
presentation = "side-by-side"
level_key = "light.r.intensity_cd"
procedure = { kind = "staircase", start = 1.0, step_type = "lin", n_reversals = 4 }
)"),
              "inline.toml:12: key 'block[0].condition[0].test_light': condition \"block0-c0\" (line 12) has no "
              "'test_light', which is required (side-by-side needs both lights and both positions); give it in "
              "the condition, its [[block]] or [defaults].");
}

// ---- Conflicting overrides (docs/protocol-file.md "When two overrides set one key") ----

/// A two-interval or side-by-side 2AFC block with the given condition keys.
std::string conflict_case(const std::string& presentation, const std::string& defaults, const std::string& block,
                          const std::string& condition) {
    return "[defaults]\ntask = \"2afc\"\npresentation = \"" + presentation +
           "\"\ntest_light = \"t\"\nreference_light = \"r\"\n" +
           (presentation == "side-by-side"
                ? "left_position_m = [-10.0, 3.0, -500.0]\nright_position_m = [10.0, 3.0, -500.0]\n"
                : "\n\n") +  // (the same line numbers either way)
           std::string("level_key = \"light.r.intensity_cd\"\n"
           "procedure = { kind = \"staircase\", start = 1.0, step_type = \"lin\", n_reversals = 4 }\n") +
           defaults + "\n[[block]]\n" + block + "\n[[block.condition]]\nname = \"c\"\n" + condition + "\n";
}

std::string conflict_error(const std::string& text) {
    try {
        (void)parse(text);
    } catch (const atonlab::InputError& e) {
        return e.what();
    }
    return "";
}

TEST(ProtocolConflicts, SideBySideTestAndReferenceSetsMustAgree) {
    // The issue's case: the eye is one for both lights of the frame.
    const std::string e = conflict_error(conflict_case(
        "side-by-side", "test_set = ['eye.glare=\"wave-optics\"']\nreference_set = ['eye.glare=\"none\"']", "", ""));
    EXPECT_NE(e.find("inline.toml:20: key 'defaults.reference_set[0]'"), std::string::npos) << e;
    EXPECT_NE(e.find("eye.glare is set to \"none\" here and to \"wave-optics\" by defaults.test_set[0] (line 19)"),
              std::string::npos)
        << e;
    // The same lists in a two-interval design switch the eye per interval: fine.
    EXPECT_EQ(conflict_error(conflict_case("two-interval",
                                           "test_set = ['eye.glare=\"wave-optics\"']\nreference_set = "
                                           "['eye.glare=\"none\"']",
                                           "", "")),
              "");
    // Each light its own model: different keys, one frame.
    const Protocol p = parse(conflict_case(
        "side-by-side", "test_set = ['light.t.glare=\"wave-optics\"']\nreference_set = ['light.r.glare=\"none\"']", "",
        ""));
    const Condition& c = p.blocks[0].conditions[0];
    Proposal prop;
    prop.level = 0.5;
    prop.test_on_left = true;
    const Stimulus stimulus = make_stimulus(p, c, prop);
    const auto& o = stimulus.frames[0].override_texts();
    EXPECT_NE(std::find(o.begin(), o.end(), "light.t.glare=\"wave-optics\""), o.end());
    EXPECT_NE(std::find(o.begin(), o.end(), "light.r.glare=\"none\""), o.end());
    // Equal values are not a conflict (numbers compare as numbers).
    EXPECT_EQ(conflict_error(conflict_case("side-by-side", "test_set = ['eye.pupil_mm=4']\nreference_set = "
                                                           "['eye.pupil_mm=4.0']",
                                           "", "")),
              "");
}

TEST(ProtocolConflicts, ABlockAndItsConditionMustAgree) {
    const std::string e = conflict_error(
        conflict_case("two-interval", "", "set = ['tonemap.operator=\"empirical\"']", "set = ['tonemap.operator=\"perceptual\"']"));
    EXPECT_NE(e.find("key 'block[0].condition[0].set[0]'"), std::string::npos) << e;
    EXPECT_NE(e.find("tonemap.operator is set to \"perceptual\" here and to \"empirical\" by block[0].set[0]"),
              std::string::npos)
        << e;
    EXPECT_NE(e.find("a condition and its block"), std::string::npos) << e;
    // One list twice.
    EXPECT_NE(conflict_error(conflict_case("two-interval", "", "set = ['eye.pupil_mm=3', 'eye.pupil_mm=5']", ""))
                  .find("one list sets it twice"),
              std::string::npos);
}

TEST(ProtocolConflicts, DefaultsAndRoleListsReplaceByDesign) {
    // A block replaces a default, in any presentation; the default is dropped.
    for (const std::string presentation : {"two-interval", "side-by-side"}) {
        SCOPED_TRACE(presentation);
        const Protocol p = parse(conflict_case(presentation, "test_set = ['eye.pupil_mm=3']", "set = ['eye.pupil_mm=5']", ""));
        const Condition& c = p.blocks[0].conditions[0];
        Proposal prop;
        prop.level = 0.5;
        prop.test_on_left = true;
        const Stimulus s = make_stimulus(p, c, prop);
        // The test's frame (the only frame side by side): the last pupil_mm is the block's in side-by-side; in a
        // two-interval test frame the role's list replaces `set` (the default's 3).
        std::string last;
        for (const std::string& o : s.frames[0].override_texts())
            if (o.starts_with("eye.pupil_mm=")) last = o;
        if (presentation == "side-by-side") {
            EXPECT_EQ(last, "eye.pupil_mm=5");
        } else if (s.frames[0].role == Role::Test) {
            EXPECT_EQ(last, "eye.pupil_mm=3");
        }
    }
    // Two-interval: a block's set and the defaults' role list (the glare examples'
    // light.test.intensity_cd) are fine; side by side a block's set and a
    // block's reference_set on one key are not.
    EXPECT_EQ(conflict_error(conflict_case("two-interval", "reference_set = ['light.t.intensity_cd=0']",
                                           "set = ['light.t.intensity_cd=0.002']", "")),
              "");
    EXPECT_NE(conflict_error(conflict_case("side-by-side", "", "set = ['light.t.intensity_cd=0.002']",
                                           "reference_set = ['light.t.intensity_cd=0']"))
                  .find("a side-by-side frame holds both lights, and set and reference_set both apply"),
              std::string::npos);
}

TEST(ProtocolConflicts, TheLevelAndTheSideBySidePositionsAreNotOverridden) {
    const std::string level = conflict_error(conflict_case("two-interval", "", "reference_set = ['light.r.intensity_cd=5']", ""));
    EXPECT_NE(level.find("light.r.intensity_cd is set to 5 here, but it is the level_key (defaults.level_key)"),
              std::string::npos)
        << level;
    // In the frame the level is not on, the key is free.
    EXPECT_EQ(conflict_error(conflict_case("two-interval", "test_set = ['light.r.intensity_cd=0']", "", "")), "");
    EXPECT_NE(conflict_error(conflict_case("side-by-side", "test_set = ['light.r.intensity_cd=0']", "", ""))
                  .find("it is the level_key"),
              std::string::npos);
    EXPECT_NE(conflict_error(conflict_case("side-by-side", "set = ['light.t.position_m=[0, 3, -500]']", "", ""))
                  .find("a side-by-side frame places its lights at left_position_m and right_position_m"),
              std::string::npos);
}

// ---- Malformed files -------------------------------------------------------------

struct Bad {
    std::string file;
    int line;
    std::string key;
    std::string says;  ///< a phrase the message must contain
};

TEST(ProtocolErrors, EveryMalformedFileNamesFileLineAndKey) {
    const std::vector<Bad> cases = {
        {"syntax-error.toml", 14, "", "TOML syntax error"},
        {"unknown-key.toml", 13, "timing.stimulus",
         "unknown key 'stimulus' in the [timing] table. Did you mean 'stimulus_s'?"},
        {"unknown-procedure-key.toml", 23, "block[0].condition[0].procedure.step_size",
         "unknown key 'step_size' in a staircase procedure. Did you mean 'step_sizes'?"},
        {"wrong-type.toml", 14, "block[0].repetitions", "expected an integer, got a string."},
        {"wrong-type-procedure.toml", 21, "defaults.procedure.n_reversals",
         "expected an integer, got a floating-point number."},
        {"negative-duration.toml", 13, "timing.inter_trial_s", "inter_trial_s must be at least 0, got -1."},
        {"negative-adaptation.toml", 14, "block[0].adaptation_s", "adaptation_s must be at least 0, got -30."},
        {"min-above-max.toml", 25, "block[0].condition[0].procedure.min_level",
         "min_level (3) is greater than max_level (1)."},
        {"p-threshold-below-gamma.toml", 24, "block[0].condition[0].procedure.p_threshold", "p_threshold"},
        {"bad-step-type.toml", 23, "block[0].condition[0].procedure.step_type",
         "step_type must be \"db\", \"log\" or \"lin\", not \"log2\"."},
        {"staircase-without-stop-rule.toml", 20, "block[0].condition[0].procedure",
         "the staircase procedure has no stop rule: give n_reversals, n_trials or max_trials."},
        {"quest-without-stop-rule.toml", 16, "defaults.procedure",
         "the quest procedure has no stop rule: give n_trials"},
        {"unquoted-override.toml", 18, "block[0].condition[0].set[1]",
         "the value of 'eye.glare' is not one TOML value (a string needs quotes, as in 'eye.glare=\"wave-optics\"')"},
        {"missing-level-key.toml", 15, "block[0].condition[0].level_key",
         "condition \"c\" (line 15) has no 'level_key', which is required"},
        {"key-conflict.toml", 14, "responses.keys.right",
         "the key \"x\" is bound to both 'left' and 'right', which are used together."},
        {"unknown-key-name.toml", 13, "responses.keys.yes", "\"enterr\" is not a key name. Did you mean 'enter'?"},
        {"missing-scene.toml", 3, "protocol.scene", "the scene file \"no-such-scene.toml\" does not exist"},
        {"negative-seed.toml", 4, "protocol.seed", "seed must be at least 0, got -3."},
        {"no-blocks.toml", 0, "block", "the protocol file has no [[block]], which is required"},
        // Extreme values: each refused where it is read, none reaching an internal error.
        {"duration-two-to-the-31.toml", 13, "timing.stimulus_s",
         "stimulus_s must be at most 86400 s (a day; durations are counted in whole refreshes), got 2147483648."},
        {"duration-1e9.toml", 13, "timing.inter_stimulus_s",
         "inter_stimulus_s must be at most 86400 s (a day; durations are counted in whole refreshes), got 1000000000."},
        {"block-adaptation-1e9.toml", 14, "block[0].adaptation_s", "adaptation_s must be at most 86400 s"},
        {"display-too-wide.toml", 7, "display.width_px", "width_px must be between 1 and 16384, got 16385."},
        {"yes-no-two-interval.toml", 19, "block[0].condition[0].presentation",
         "a yes-no task shows one stimulus: presentation must be \"single\", got \"two-interval\"."},
    };
    const fs::path dir = source_dir() / "tests" / "data" / "protocols";
    std::set<std::string> covered;
    for (const Bad& b : cases) {
        SCOPED_TRACE(b.file);
        covered.insert(b.file);
        const fs::path path = dir / b.file;
        try {
            (void)load_protocol(path);
            ADD_FAILURE() << "no InputError";
        } catch (const atonlab::InputError& e) {
            const std::string what = e.what();
            EXPECT_EQ(e.where()->file, path.string());
            EXPECT_EQ(e.where()->line, b.line) << what;
            EXPECT_EQ(e.where()->key, b.key) << what;
            EXPECT_NE(what.find(b.says), std::string::npos) << what;
            // One sentence: "FILE:LINE: key 'KEY': MESSAGE." on one line, one final period.
            std::string prefix = path.string();
            if (b.line > 0) prefix += ":" + std::to_string(b.line);
            prefix += ": ";
            if (!b.key.empty()) prefix += "key '" + b.key + "': ";
            EXPECT_EQ(what.rfind(prefix, 0), 0u) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
            EXPECT_EQ(what.back(), '.') << what;
        }
    }
    // Every file in the folder is checked here.
    for (const auto& entry : fs::directory_iterator(dir))
        EXPECT_TRUE(covered.count(entry.path().filename().string())) << entry.path() << " has no expectation";
}

TEST(ProtocolErrors, AnUnreadableFileIsOneSentence) {
    try {
        (void)load_protocol("/nonexistent/protocol.toml");
        ADD_FAILURE();
    } catch (const atonlab::InputError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "/nonexistent/protocol.toml: cannot read the protocol file: No such file or directory.");
    }
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

// ---- Every error at once ------------------------------------------------------------

TEST(ProtocolErrors, FiveErrorsInDifferentPlacesAreAllReportedInFileOrder) {
    // Five mistakes in four tables; the loader reads on past each one. Line
    // numbers count the 9-line header of error_of's protocols.
    const std::string what = error_of(R"(
[timing]
stimulus = 0.5

[defaults]
task = "2afc"
levels = [1.0, 2.0]

[[block]]
name = "b"
repetitions = "two"

[[block.condition]]
name = "c1"
level_key = "light.r.intensity_cd"
procedure = { kind = "staircase", start = 1.0, step_type = "lin", n_reversals = 4, step_size = 0.1 }

[[block.condition]]
name = "c2"
level_key = "light.r.intensity_cd"
procedure = { kind = "constant-stimuli", levels = [50.0, 100.0, 200.0], repetitions = 4 }
)");
    std::vector<std::string> lines;
    for (std::size_t at = 0; at <= what.size();) {
        const std::size_t end = std::min(what.find('\n', at), what.size());
        lines.push_back(what.substr(at, end - at));
        at = end + 1;
    }
    ASSERT_EQ(lines.size(), 5u) << what;
    const std::vector<std::pair<std::string, std::string>> expected = {
        {"inline.toml:12: key 'timing.stimulus'",
         "unknown key 'stimulus' in the [timing] table. Did you mean 'stimulus_s'?"},
        {"inline.toml:16: key 'defaults.levels'", "'levels' belongs in [defaults.procedure]"},
        {"inline.toml:20: key 'block[0].repetitions'", "expected an integer, got a string."},
        {"inline.toml:25: key 'block[0].condition[0].procedure.step_size'", "Did you mean 'step_sizes'?"},
        {"inline.toml:30: key 'block[0].condition[1].procedure.levels'", "These look like linear values"},
    };
    for (std::size_t i = 0; i < expected.size(); ++i) {
        SCOPED_TRACE(i);
        EXPECT_EQ(lines[i].rfind(expected[i].first, 0), 0u) << lines[i];
        EXPECT_NE(lines[i].find(expected[i].second), std::string::npos) << lines[i];
    }
}

TEST(ProtocolErrors, TheFirstErrorKeepsItsFieldsAndTheOthersFollow) {
    try {
        (void)parse(R"(
[timing]
stimulus = 0.5
inter_trial = 1.0

[[block]]
[[block.condition]]
task = "2afc"
level_key = "light.r.intensity_cd"
level_scale = "linear"
procedure = { kind = "staircase", start = -2.0, step_type = "lin", n_reversals = 4 }
)");
        ADD_FAILURE() << "no InputError";
    } catch (const atonlab::InputError& e) {
        EXPECT_EQ(e.where()->line, 12);
        EXPECT_EQ(e.where()->key, "timing.stimulus");
        ASSERT_EQ(e.further().size(), 2u) << e.what();
        EXPECT_EQ(e.further()[0].rfind("inline.toml:13: key 'timing.inter_trial'", 0), 0u) << e.further()[0];
        EXPECT_NE(e.further()[1].find("These look like log10 values"), std::string::npos) << e.further()[1];
    }
}

// ---- Conditions files ------------------------------------------------------------------

TEST(ConditionsFile, TheCsvExampleGivesTheSameScheduleAsItsTomlTwin) {
    const Protocol toml = load_protocol(example("glare_brightness_2afc.toml"));
    const Protocol csv = load_protocol(example("glare_brightness_2afc_csv.toml"));
    ASSERT_EQ(csv.blocks.size(), toml.blocks.size());
    for (std::size_t b = 0; b < toml.blocks.size(); ++b) {
        ASSERT_EQ(csv.blocks[b].conditions.size(), toml.blocks[b].conditions.size());
        for (std::size_t c = 0; c < toml.blocks[b].conditions.size(); ++c)
            EXPECT_EQ(csv.blocks[b].conditions[c].name, toml.blocks[b].conditions[c].name);
    }
    // The same trials, stimuli and procedure states on the same answers, seed for seed.
    for (const std::uint64_t seed : {toml.seed, std::uint64_t{99}}) {
        SCOPED_TRACE(seed);
        Schedule a(toml, seed), b(csv, seed);
        Rng rng(3);
        std::size_t n = 0;
        while (true) {
            const auto ta = a.next();
            const auto tb = b.next();
            ASSERT_EQ(ta.has_value(), tb.has_value());
            if (!ta) break;
            ASSERT_EQ(ta->procedure_id, tb->procedure_id) << "trial " << n;
            EXPECT_EQ(ta->proposal.level, tb->proposal.level);
            EXPECT_EQ(ta->proposal.test_on_left, tb->proposal.test_on_left);
            ASSERT_EQ(ta->stimulus.frames.size(), tb->stimulus.frames.size());
            for (std::size_t f = 0; f < ta->stimulus.frames.size(); ++f) {
                EXPECT_EQ(ta->stimulus.frames[f].override_texts(), tb->stimulus.frames[f].override_texts())
                    << "trial " << n;
            }
            EXPECT_EQ(a.state(), b.state());
            const Response r = random_response(ta->task, rng);
            a.record(r);
            b.record(r);
            ++n;
        }
        EXPECT_GT(n, 100u);
    }
}

TEST(ConditionsFile, ErrorsNameTheCsvFileRowAndColumn) {
    const fs::path dir = fs::temp_directory_path() / "atonlab-conditions-file-test";
    fs::create_directories(dir);
    {
        std::ofstream(dir / "scene.toml") << "";
        std::ofstream(dir / "c.csv") << "name,procedure.start,eye.adaptation_cd_m2,level_scale\n"
                                        "a,1.0,0.1,log10\n"
                                        "b,\"[1.0, x]\",0.1,log10\n"
                                        "c,1.0,0.1,logarithmic\n";
        std::ofstream(dir / "p.toml") << std::string(kHeader) + R"(
[defaults]
task = "2afc"
level_key = "light.r.intensity_cd"
procedure = { kind = "staircase", step_sizes = [0.1], step_type = "lin", n_reversals = 4 }

[[block]]
conditions_file = "c.csv"
)";
    }
    try {
        (void)load_protocol(dir / "p.toml");
        ADD_FAILURE() << "no InputError";
    } catch (const atonlab::InputError& e) {
        const std::string csv = (dir / "c.csv").string();
        EXPECT_EQ(e.where()->file, csv) << e.what();
        EXPECT_EQ(e.where()->line, 3) << e.what();
        ASSERT_EQ(e.further().size(), 1u) << e.what();
        EXPECT_EQ(e.further()[0].rfind(csv + ":4: column 4 'level_scale': ", 0), 0u) << e.further()[0];
    }
    {
        std::ofstream(dir / "c.csv") << "name,procedure.strat\n"
                                        "a,1.0\n";
    }
    try {
        (void)load_protocol(dir / "p.toml");
        ADD_FAILURE() << "no InputError";
    } catch (const atonlab::InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind((dir / "c.csv").string() + ":2: column 2 'procedure.strat': ", 0), 0u)
            << e.what();
    }
    {
        std::ofstream(dir / "c.csv") << "name,colour\n"
                                        "a,red\n";
    }
    try {
        (void)load_protocol(dir / "p.toml");
        ADD_FAILURE() << "no InputError";
    } catch (const atonlab::InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind((dir / "c.csv").string() + ":1: column 2 'colour': not a column", 0), 0u)
            << e.what();
    }
    fs::remove_all(dir);
}

// Every override of a frame carries where it was written (the scene loader
// names a refused value there): a condition's own at its string's line and
// column, the display at its [display] lines, the level and the side-by-side
// positions (which the protocol makes) at the condition's line, and a
// conditions file's at its row and column.
TEST(ProtocolOverrides, EachFramesOverridesCarryWhereTheyWereWritten) {
    const std::string body = R"(
[[block]]
name = "b"

[[block.condition]]
name = "glare"
task = "2afc"
presentation = "side-by-side"
test_light = "t"
reference_light = "r"
left_position_m = [-1, 0, -10]
right_position_m = [1, 0, -10]
level_key = "light.r.intensity_cd"
set = ["eye.glare=\"none\"", "eye.adaptation_cd_m2=0.01"]
procedure = { kind = "staircase", start = 1.0, step_sizes = [0.1], step_type = "lin", n_reversals = 4 }
)";
    const std::string text = std::string(kHeader) + body;
    const Protocol p = parse(body);
    const Condition& c = p.blocks[0].conditions[0];
    const Stimulus s = make_stimulus(p, c, Proposal{1.0, true});
    ASSERT_EQ(s.frames.size(), 1u);
    const auto line = [&](const std::string& needle) {
        const auto at = text.find(needle);
        EXPECT_NE(at, std::string::npos) << needle;
        return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
    };
    std::map<std::string, atonlab::SourceLocation> origin;
    for (const atonlab::SceneOverride& o : s.frames[0].overrides) origin[o.key] = o.origin;
    for (const char* key : {"width_px", "height_px", "width_m", "viewing_distance_m"}) {
        const atonlab::SourceLocation& w = origin["display." + std::string(key)];
        EXPECT_EQ(w.file, "inline.toml") << key;
        EXPECT_EQ(w.line, line(std::string(key) + " = ")) << key;
    }
    const atonlab::SourceLocation& glare = origin["eye.glare"];
    EXPECT_EQ(glare.file, "inline.toml");
    EXPECT_EQ(glare.line, line("set = [\"eye.glare"));
    EXPECT_EQ(glare.column, static_cast<int>(std::string("set = [").size()) + 1);
    EXPECT_EQ(glare.key, "block[0].condition[0].set[0]");
    EXPECT_EQ(origin["eye.adaptation_cd_m2"].key, "block[0].condition[0].set[1]");
    EXPECT_GT(origin["eye.adaptation_cd_m2"].column, glare.column);
    for (const char* made : {"light.r.intensity_cd", "light.t.position_m", "light.r.position_m"}) {
        EXPECT_EQ(origin[made].file, "inline.toml") << made;
        EXPECT_EQ(origin[made].line, c.line) << made;
        EXPECT_FALSE(origin[made].from_command_line()) << made;
    }
    EXPECT_EQ(c.line, line("[[block.condition]]"));

    // A conditions file's override: its CSV row and column.
    const fs::path dir = fs::temp_directory_path() / "atonlab-override-origin-test";
    fs::create_directories(dir);
    {
        std::ofstream(dir / "scene.toml") << "";
        std::ofstream(dir / "c.csv") << "name,eye.adaptation_cd_m2\n"
                                        "a,0.1\n";
        std::ofstream(dir / "p.toml") << std::string(kHeader) + R"(
[defaults]
task = "2afc"
level_key = "light.r.intensity_cd"
procedure = { kind = "staircase", start = 1.0, step_sizes = [0.1], step_type = "lin", n_reversals = 4 }

[[block]]
conditions_file = "c.csv"
)";
    }
    const Protocol from_csv = load_protocol(dir / "p.toml");
    const std::vector<atonlab::SceneOverride>& set = from_csv.blocks.at(0).conditions.at(0).set;
    ASSERT_EQ(set.size(), 1u);
    EXPECT_EQ(set[0].origin.file, (dir / "c.csv").string());
    EXPECT_EQ(set[0].origin.line, 2);
    EXPECT_EQ(set[0].origin.column, 2);
    fs::remove_all(dir);
}

TEST(ConditionsFile, TheStoredTextCarriesTheCsvSoThatItParsesWithoutIt) {
    const fs::path file = example("glare_brightness_2afc_csv.toml");
    std::ifstream in(file);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string stored = with_conditions_files(text, file);
    EXPECT_NE(stored.find("\n#@conditions_file glare_brightness_2afc.conditions.csv\n#@|block,name,"),
              std::string::npos);
    // Parsed from the text alone (no such folder: the CSV cannot be opened), as analyze does.
    const Protocol p = parse_protocol(stored, "/nonexistent/glare_brightness_2afc_csv.toml");
    const Protocol twin = load_protocol(example("glare_brightness_2afc.toml"));
    ASSERT_EQ(p.blocks.size(), twin.blocks.size());
    for (std::size_t b = 0; b < p.blocks.size(); ++b) {
        ASSERT_EQ(p.blocks[b].conditions.size(), twin.blocks[b].conditions.size());
        for (std::size_t c = 0; c < p.blocks[b].conditions.size(); ++c) {
            std::vector<std::string> a, t;
            for (const atonlab::SceneOverride& o : p.blocks[b].conditions[c].set) a.push_back(o.text());
            for (const atonlab::SceneOverride& o : twin.blocks[b].conditions[c].set) t.push_back(o.text());
            EXPECT_EQ(a, t);
        }
    }
    // A protocol without a conditions file is stored as it is.
    const std::string plain = "[protocol]\nscene = \"s.toml\"\n";
    EXPECT_EQ(with_conditions_files(plain, "p.toml"), plain);
    // Without the CSV and without the stored copy, the error names the key.
    try {
        (void)parse_protocol(text, "/nonexistent/glare_brightness_2afc_csv.toml");
        ADD_FAILURE() << "no InputError";
    } catch (const atonlab::InputError& e) {
        EXPECT_EQ(e.where()->key, "block[0].conditions_file") << e.what();
        EXPECT_NE(std::string(e.what()).find("cannot read the conditions file"), std::string::npos) << e.what();
    }
}
