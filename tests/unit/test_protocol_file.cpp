// The protocol file and the schedule: every example protocol parses, its scene
// takes every condition's overrides, and its schedule is a pure function of
// (protocol, seed, responses) and replays exactly. The schema's details and
// errors: test_protocol_file_schema.cpp; conditions files and where overrides
// were written: test_protocol_file_conditions.cpp; the procedures' convergence
// on a toy renderer: test_protocol_file_convergence.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/protocols/rng.h"
#include "atonlab/stimuli/scene_file.h"
#include "protocol_file_test_support.h"

namespace {

using namespace atonlab::protocols;                      // NOLINT: the test exercises the whole namespace
using namespace atonlab::protocols::protocol_file_test;  // NOLINT: the shared examples and readers
namespace fs = std::filesystem;

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

}  // namespace
