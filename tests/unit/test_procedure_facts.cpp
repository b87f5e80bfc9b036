// The procedure facts the runner and the analysis both read from the protocol
// types (protocol.h, procedure.h, protocol_schedule.h): the probability a
// procedure converges on, what its Yes means, its level bounds, how many
// trials it can take, and the words its answers are stored as. Each is checked
// against an independent account: a simulated staircase for the target
// probability (Levitt 1971), a finished schedule's own trial count for the
// bound, the action words of docs/protocol-file.md for the responses.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "atonlab/protocols/protocol.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/protocols/rng.h"
#include "atonlab/protocols/staircase.h"
#include "normal_distribution.h"

namespace {

namespace p = atonlab::protocols;

using atonlab::test::normal_cdf;
using atonlab::test::normal_quantile;

p::ProcedureSpec spec_of(p::ProcedureKind kind, p::ProcedureParams params, std::vector<double> starts = {}) {
    return p::ProcedureSpec{kind, std::move(params), std::move(starts)};
}

p::StaircaseParams staircase(int n_up, int n_down) {
    p::StaircaseParams s;
    s.start = 2.5;
    s.step_sizes = {0.8, 0.4, 0.2, 0.1};
    s.step_type = p::StepType::Lin;
    s.n_up = n_up;
    s.n_down = n_down;
    s.n_reversals = 60;
    return s;
}

/// Where a staircase settles with a yes/no observer P(Yes | x) = Phi(x): the
/// mean over 40 seeded runs of the mean of each run's last 50 reversal levels.
double converged_level(const p::StaircaseParams& params) {
    double total = 0;
    constexpr int kRuns = 40, kLast = 50;
    for (int run = 0; run < kRuns; ++run) {
        p::Staircase s(params);
        p::Rng observer(7000 + static_cast<std::uint64_t>(run));
        while (auto next = s.next()) s.record(p::binary(observer.uniform() < normal_cdf(next->level)));
        const auto& rev = s.reversal_levels();
        EXPECT_GE(rev.size(), static_cast<std::size_t>(kLast));
        double sum = 0;
        for (std::size_t i = rev.size() - kLast; i < rev.size(); ++i) sum += rev[i];
        total += sum / kLast;
    }
    return total / kRuns;
}

// The runner once took an n-up/1-down staircase to have no target (its true
// value was left out) while the analysis took it to converge on
// 1 - 0.5^(1/n). A simulated observer settles the question: a 2-up/1-down
// staircase settles where P(Yes) = 0.293 (x = -0.545 sigma), a 3-up/1-down
// where P(Yes) = 0.206 (x = -0.819 sigma), mirror images of 1-up/2-down and
// 1-up/3-down. Tolerance 0.05 sigma: the transformed rule's bias at a final
// step of 0.1 sigma is a few hundredths, the standard error about 0.01.
TEST(ProcedureFacts, StaircaseTargetProbabilityIsWhereASimulatedObserverSettles) {
    for (const auto& [n_up, n_down] : std::vector<std::pair<int, int>>{{1, 1}, {1, 2}, {1, 3}, {2, 1}, {3, 1}}) {
        SCOPED_TRACE(std::to_string(n_up) + "-up/" + std::to_string(n_down) + "-down");
        const std::optional<double> target =
            spec_of(p::ProcedureKind::Staircase, staircase(n_up, n_down)).target_p_yes();
        ASSERT_TRUE(target.has_value());
        EXPECT_NEAR(converged_level(staircase(n_up, n_down)), normal_quantile(*target), 0.05);
    }
    // Levitt's closed forms, written out.
    EXPECT_NEAR(*spec_of(p::ProcedureKind::Staircase, staircase(2, 1)).target_p_yes(), 1.0 - std::sqrt(0.5), 1e-15);
    EXPECT_NEAR(*spec_of(p::ProcedureKind::Staircase, staircase(1, 3)).target_p_yes(), std::cbrt(0.5), 1e-15);
}

TEST(ProcedureFacts, StaircasesWithoutAClosedFormHaveNoTarget) {
    EXPECT_FALSE(spec_of(p::ProcedureKind::Staircase, staircase(2, 2)).target_p_yes().has_value());
    p::StaircaseParams weighted_steps = staircase(1, 3);
    weighted_steps.up_step_ratio = 2.0;
    EXPECT_FALSE(spec_of(p::ProcedureKind::Staircase, weighted_steps).target_p_yes().has_value());
}

TEST(ProcedureFacts, OtherProceduresStateTheirOwnTarget) {
    p::WeightedStaircaseParams w;
    w.target = 0.8;
    EXPECT_EQ(spec_of(p::ProcedureKind::WeightedStaircase, w).target_p_yes(), 0.8);
    p::QuestParams q;
    q.p_threshold = 0.82;
    EXPECT_EQ(spec_of(p::ProcedureKind::Quest, q).target_p_yes(), 0.82);
    p::ConstantStimuliParams c;
    c.levels = {0.0, 1.0};
    c.criterion = 0.6;
    EXPECT_EQ(spec_of(p::ProcedureKind::ConstantStimuli, c).target_p_yes(), 0.6);
    EXPECT_EQ(spec_of(p::ProcedureKind::Adjustment, p::AdjustmentParams{}).target_p_yes(), 0.5);
}

// Yes means "chose the level stimulus" exactly when the 2AFC choice names the
// role the level is on; yes-no and adjustment answers are always about it.
TEST(ProcedureFacts, YesMeansTheLevelStimulusWhenTheChoiceNamesItsRole) {
    p::Condition c;
    c.task = p::Task::TwoAfc;
    for (const p::Role on : {p::Role::Test, p::Role::Reference}) {
        for (const p::ChoiceMapping choice : {p::ChoiceMapping::ChoseTest, p::ChoiceMapping::ChoseReference}) {
            c.level_on = on;
            c.choice = choice;
            const bool names_it = (on == p::Role::Test) == (choice == p::ChoiceMapping::ChoseTest);
            EXPECT_EQ(c.yes_means_level(), names_it);
        }
    }
    c.level_on = p::Role::Reference;
    c.choice = p::ChoiceMapping::ChoseTest;
    for (const p::Task t : {p::Task::YesNo, p::Task::Adjust}) {
        c.task = t;
        EXPECT_TRUE(c.yes_means_level());
    }
}

TEST(ProcedureFacts, LevelBoundsAndSearchRanges) {
    p::StaircaseParams s = staircase(1, 3);
    EXPECT_TRUE(spec_of(p::ProcedureKind::Staircase, s).level_bounds().empty());
    // Unbounded: the starts (all tracks) +- 3.
    const auto [lo, hi] = spec_of(p::ProcedureKind::Staircase, s, {1.0, 4.0}).search_range();
    EXPECT_EQ(lo, -2.0);
    EXPECT_EQ(hi, 7.0);
    s.min_level = -1.0;
    s.max_level = 3.0;
    const p::ProcedureSpec bounded = spec_of(p::ProcedureKind::Staircase, s);
    EXPECT_EQ(bounded.level_bounds(), (std::vector<double>{-1.0, 3.0}));
    EXPECT_EQ(bounded.search_range(), (std::pair<double, double>{-1.0, 3.0}));
    p::ConstantStimuliParams c;
    c.levels = {0.3, -0.2, 0.1};
    const p::ProcedureSpec constant = spec_of(p::ProcedureKind::ConstantStimuli, c);
    EXPECT_EQ(constant.level_bounds(), (std::vector<double>{-0.2, 0.3}));
    EXPECT_EQ(constant.search_range(), (std::pair<double, double>{-1.2, 1.3}));
    // level_range: both bounds where given (in either order), else the search range.
    EXPECT_EQ(constant.level_range(), (std::pair<double, double>{-0.2, 0.3}));
    EXPECT_EQ(bounded.level_range(), (std::pair<double, double>{-1.0, 3.0}));
    s.min_level = 5.0;
    s.max_level = -1.0;
    EXPECT_EQ(spec_of(p::ProcedureKind::Staircase, s).level_range(), (std::pair<double, double>{-1.0, 5.0}));
    s.max_level.reset();
    EXPECT_EQ(spec_of(p::ProcedureKind::Staircase, s, {1.0, 4.0}).level_range(),
              (std::pair<double, double>{5.0, 7.0}))
        << "one bound: the search range, with that bound kept";
}

// The bound is checked against the schedule itself: answered to the end, the
// constant-stimuli example takes exactly the trials max_trials() promised.
TEST(ProcedureFacts, ScheduleTrialBoundIsTheTrialsAFinishedScheduleTook) {
    const p::Protocol protocol =
        p::load_protocol(std::string(ATONLAB_SOURCE_DIR) + "/protocols/examples/glare_constant_stimuli.toml");
    p::Schedule schedule(protocol);
    const std::optional<std::size_t> bound = schedule.max_trials();
    ASSERT_TRUE(bound.has_value());
    EXPECT_EQ(*bound, 6u * 7u * 6u);  // the file's header: 6 conditions x 7 levels x 6 repetitions
    p::Rng answers(3);
    std::size_t trials = 0;
    while (!schedule.finished()) {
        schedule.record(answers.uniform() < 0.5 ? p::Response::Left : p::Response::Right);
        ++trials;
    }
    EXPECT_EQ(trials, *bound);
    // A staircase without max_trials has no bound.
    p::Protocol unbounded = protocol;
    unbounded.blocks[0].conditions[0].procedure = spec_of(p::ProcedureKind::Staircase, staircase(1, 2));
    EXPECT_FALSE(p::Schedule(unbounded).max_trials().has_value());
}

// The store's words are the action words of docs/protocol-file.md.
TEST(ProcedureFacts, ResponseWordsRoundTrip) {
    const std::vector<std::pair<p::Response, std::string>> words{{p::Response::No, "no"},
                                                                 {p::Response::Yes, "yes"},
                                                                 {p::Response::Left, "left"},
                                                                 {p::Response::Right, "right"},
                                                                 {p::Response::CoarseUp, "coarse_up"},
                                                                 {p::Response::CoarseDown, "coarse_down"},
                                                                 {p::Response::FineUp, "fine_up"},
                                                                 {p::Response::FineDown, "fine_down"},
                                                                 {p::Response::Confirm, "confirm"}};
    for (const auto& [r, w] : words) {
        EXPECT_EQ(p::response_word(r), w);
        EXPECT_EQ(p::parse_response_word(w), r);
        // The same word names the protocol's action for it.
        for (std::size_t a = 0; a < p::kActionCount; ++a) {
            if (p::response_of(static_cast<p::Action>(a)) == r) {
                EXPECT_EQ(p::to_string(static_cast<p::Action>(a)), w);
            }
        }
    }
    for (const char* other : {"", "Left", "first", "timeout", "quit", "continue"})
        EXPECT_FALSE(p::parse_response_word(other).has_value()) << other;
}

}  // namespace

namespace {

// The stored words of docs/store.md ("response" column): every answer word
// reads back as its Response and is counted; "timeout" and "missed" are the
// two words of trials the procedure never took, and neither names a Response.
TEST(ProcedureFacts, ResponseWordsRoundTripAndOnlyTimeoutAndMissedGoUncounted) {
    for (const p::Response r : {p::Response::No, p::Response::Yes, p::Response::Left, p::Response::Right,
                                p::Response::CoarseUp, p::Response::CoarseDown, p::Response::FineUp,
                                p::Response::FineDown, p::Response::Confirm}) {
        const std::string_view word = p::response_word(r);
        EXPECT_EQ(p::parse_response_word(word), r) << word;
        EXPECT_TRUE(p::is_counted_response_word(word)) << word;
    }
    EXPECT_EQ(p::kTimeoutWord, "timeout");
    EXPECT_EQ(p::kMissedWord, "missed");
    EXPECT_FALSE(p::is_counted_response_word("timeout"));
    EXPECT_FALSE(p::is_counted_response_word("missed"));
    EXPECT_FALSE(p::parse_response_word("timeout").has_value());
    EXPECT_FALSE(p::parse_response_word("missed").has_value());
}

}  // namespace
