// The procedures' common machinery: the random number generator (published
// test vectors), the method of adjustment and the method of constant stimuli
// (worked by hand), forced choice (its answer mapping, and convergence of a
// matching staircase on a known PSE), interleaving, and exact replay of every
// procedure from its logged responses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <numeric>
#include <optional>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "atonlab/protocols/procedures.h"
#include "procedure_error.h"

namespace {

using namespace atonlab::protocols;  // NOLINT: the test exercises the whole namespace

using atonlab::test::expect_bad;

double normal_cdf(double z) {
    return 0.5 * std::erfc(-z / std::sqrt(2.0));
}

// ---- Rng ---------------------------------------------------------------------

// splitmix64 from state 0: first output 0xE220A8397B1DCDAF (Vigna's reference splitmix64.c).
// xoshiro256** from state {1, 2, 3, 4}, by hand from the algorithm:
//  out1 = rotl(2*5, 7)*9 = 1280*9 = 11520; then s = {7, 0, 262146, rotl(6, 45)}
//  out2 = rotl(0*5, 7)*9 = 0;              then s1 = 262146 ^ 7 = 262149
//  out3 = rotl(262149*5, 7)*9 = 1310745*128*9 = 1509978240.
TEST(Rng, MatchesReferenceVectors) {
    std::uint64_t state = 0;
    EXPECT_EQ(splitmix64(state), 0xE220A8397B1DCDAFULL);
    Rng r = Rng::from_state(1, 2, 3, 4);
    EXPECT_EQ(r.next_u64(), 11520u);
    EXPECT_EQ(r.next_u64(), 0u);
    EXPECT_EQ(r.next_u64(), 1509978240u);
}

TEST(Rng, UniformAndBoundedDraws) {
    Rng r(42);
    // uniform(): the top 53 bits times 2^-53, so in [0, 1) with mean 1/2 and variance 1/12.
    double sum = 0, sum2 = 0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
        const double u = r.uniform();
        ASSERT_GE(u, 0.0);
        ASSERT_LT(u, 1.0);
        sum += u;
        sum2 += u * u;
    }
    EXPECT_NEAR(sum / n, 0.5, 4 * std::sqrt(1.0 / 12 / n));
    EXPECT_NEAR(sum2 / n - (sum / n) * (sum / n), 1.0 / 12, 0.002);
    // below(7): chi-square with 6 degrees of freedom; 22.5 is its 0.999 quantile.
    std::vector<int> counts(7, 0);
    for (int i = 0; i < 70000; ++i) ++counts[static_cast<std::size_t>(r.below(7))];
    double chi2 = 0;
    for (int c : counts) chi2 += (c - 10000.0) * (c - 10000.0) / 10000.0;
    EXPECT_LT(chi2, 22.5);
    // shuffle() permutes.
    std::vector<int> v(20);
    std::iota(v.begin(), v.end(), 0);
    r.shuffle(v);
    std::vector<int> sorted = v;
    std::sort(sorted.begin(), sorted.end());
    for (int i = 0; i < 20; ++i) EXPECT_EQ(sorted[static_cast<std::size_t>(i)], i);
    EXPECT_FALSE(std::is_sorted(v.begin(), v.end()));
    // Same seed, same stream; derived seeds differ.
    EXPECT_EQ(Rng(5).next_u64(), Rng(5).next_u64());
    EXPECT_NE(derive_seed(5, 0), derive_seed(5, 1));
}

// ---- Method of adjustment ---------------------------------------------------------

AdjustmentParams adjustment_params() {
    AdjustmentParams p;
    p.start_min = -1;
    p.start_max = 1;
    p.coarse_step = 0.1;
    p.fine_step = 0.01;
    p.min_level = -1.5;
    p.max_level = 1.2;
    p.n_trials = 2;
    return p;
}

// Trial 0 starts at s0 = -1 + 2 u0 (u0 the seed's first uniform draw); CoarseUp, CoarseUp,
// FineDown put it at s0 + 0.19; Confirm records that match and starts trial 1 at
// s1 = -1 + 2 u1; 30 CoarseUp hit the 1.2 ceiling; FineDown -> 1.19; Confirm -> match 1.19.
TEST(Adjustment, ActionsByHand) {
    Rng draws(7);
    const double s0 = -1 + 2 * draws.uniform();
    const double s1 = -1 + 2 * draws.uniform();

    Adjustment a(adjustment_params(), 7);
    EXPECT_EQ(a.next()->level, s0);
    EXPECT_EQ(a.next()->trial, 0u);
    EXPECT_FALSE(a.mid_trial());
    a.record(Response::CoarseUp);
    EXPECT_TRUE(a.mid_trial());
    a.record(Response::CoarseUp);
    a.record(Response::FineDown);
    EXPECT_NEAR(a.next()->level, s0 + 0.19, 1e-12);
    a.record(Response::Confirm);
    EXPECT_FALSE(a.mid_trial());
    ASSERT_EQ(a.matches().size(), 1u);
    EXPECT_NEAR(a.matches()[0], s0 + 0.19, 1e-12);
    EXPECT_EQ(a.next()->level, s1);
    EXPECT_EQ(a.next()->trial, 1u);
    for (int i = 0; i < 30; ++i) a.record(Response::CoarseUp);
    EXPECT_EQ(a.next()->level, 1.2);
    a.record(Response::FineDown);
    a.record(Response::Confirm);
    EXPECT_TRUE(a.finished());
    EXPECT_FALSE(a.next().has_value());
    EXPECT_NEAR(a.matches()[1], 1.19, 1e-12);
    EXPECT_EQ(a.starts(), (std::vector<double>{s0, s1}));
    const Estimate e = a.estimate();
    EXPECT_EQ(e.n, 2u);
    EXPECT_NEAR(e.value, (s0 + 0.19 + 1.19) / 2, 1e-12);
    EXPECT_NEAR(e.sd, std::abs(s0 + 0.19 - 1.19) / std::sqrt(2.0), 1e-12);
    EXPECT_THROW(a.record(Response::Confirm), std::logic_error);
}

TEST(Adjustment, FloorAndBadAnswers) {
    Adjustment a(adjustment_params(), 3);
    for (int i = 0; i < 40; ++i) a.record(Response::CoarseDown);
    EXPECT_EQ(a.level(), -1.5);
    const std::string before = a.state();
    expect_bad([&] { a.record(Response::Yes); }, "response");
    EXPECT_EQ(a.state(), before);
}

TEST(Adjustment, BadParametersNameTheParameter) {
    const auto with = [](auto change) {
        return [change] {
            AdjustmentParams p = adjustment_params();
            change(p);
            Adjustment a(p, 1);
        };
    };
    expect_bad(with([](AdjustmentParams& p) { p.start_min = 2; }), "start_min");
    expect_bad(with([](AdjustmentParams& p) { p.start_max = NAN; }), "start_max");
    expect_bad(with([](AdjustmentParams& p) { p.coarse_step = 0; }), "coarse_step");
    expect_bad(with([](AdjustmentParams& p) { p.fine_step = -0.01; }), "fine_step");
    expect_bad(with([](AdjustmentParams& p) { p.fine_step = 0.5; }), "fine_step");
    expect_bad(with([](AdjustmentParams& p) { p.n_trials = 0; }), "n_trials");
    expect_bad(with([](AdjustmentParams& p) {
                   p.min_level = 2;
                   p.max_level = 1;
               }),
               "min_level");
    expect_bad(with([](AdjustmentParams& p) { p.min_level = -0.5; }), "start_min");
    expect_bad(with([](AdjustmentParams& p) { p.max_level = 0.5; }), "start_max");
}

// ---- Method of constant stimuli ------------------------------------------------------

ConstantStimuliParams constant_params(ConstantOrder order) {
    ConstantStimuliParams p;
    p.levels = {1, 2, 3, 4, 5};
    p.repetitions = 4;
    p.order = order;
    return p;
}

std::vector<double> shown_levels(const ConstantStimuli& c) {
    std::vector<double> v;
    for (std::size_t i : c.schedule()) v.push_back(c.params().levels[i]);
    return v;
}

TEST(ConstantStimuli, BlockedKeepsEachLevelsRepeatsTogether) {
    std::set<std::vector<double>> orders;
    for (std::uint64_t seed = 0; seed < 10; ++seed) {
        const ConstantStimuli c(constant_params(ConstantOrder::Blocked), seed);
        const auto v = shown_levels(c);
        ASSERT_EQ(v.size(), 20u);
        std::vector<double> block_order;
        for (std::size_t b = 0; b < 5; ++b) {
            for (std::size_t k = 1; k < 4; ++k) EXPECT_EQ(v[4 * b + k], v[4 * b]);
            block_order.push_back(v[4 * b]);
        }
        std::sort(block_order.begin(), block_order.end());
        EXPECT_EQ(block_order, (std::vector<double>{1, 2, 3, 4, 5}));  // each level one block
        orders.insert(shown_levels(c));
    }
    EXPECT_GT(orders.size(), 5u);  // the block order is shuffled by the seed
}

TEST(ConstantStimuli, PassesAreShuffledPermutations) {
    const ConstantStimuli c(constant_params(ConstantOrder::Passes), 4);
    const auto v = shown_levels(c);
    ASSERT_EQ(v.size(), 20u);
    for (std::size_t pass = 0; pass < 4; ++pass) {
        std::vector<double> chunk(v.begin() + static_cast<std::ptrdiff_t>(5 * pass),
                                  v.begin() + static_cast<std::ptrdiff_t>(5 * pass + 5));
        std::sort(chunk.begin(), chunk.end());
        EXPECT_EQ(chunk, (std::vector<double>{1, 2, 3, 4, 5}));
    }
}

TEST(ConstantStimuli, RandomOrderShowsEachLevelRepetitionsTimes) {
    const ConstantStimuli c(constant_params(ConstantOrder::Random), 9);
    auto v = shown_levels(c);
    EXPECT_FALSE(std::is_sorted(v.begin(), v.end()));
    for (double level : {1.0, 2.0, 3.0, 4.0, 5.0}) EXPECT_EQ(std::count(v.begin(), v.end(), level), 4);
    // Same seed, same order; another seed, another order.
    EXPECT_EQ(c.schedule(), ConstantStimuli(constant_params(ConstantOrder::Random), 9).schedule());
    EXPECT_NE(c.schedule(), ConstantStimuli(constant_params(ConstantOrder::Random), 10).schedule());
}

// Levels 1..5, 4 repetitions; the observer says Yes to the first k presentations of each
// level, k = 0, 1, 3, 4, 4: proportions 0, .25, .75, 1, 1. The 0.5 crossing lies between
// levels 2 (.25) and 3 (.75): 2 + (.5 - .25)/(.75 - .25) = 2.5.
TEST(ConstantStimuli, TalliesAndCrossingByHand) {
    ConstantStimuli c(constant_params(ConstantOrder::Random), 2);
    const int yes_first[] = {0, 1, 3, 4, 4};
    std::vector<int> seen(5, 0);
    std::size_t trials = 0;
    while (auto p = c.next()) {
        EXPECT_EQ(p->trial, trials++);
        const auto i = static_cast<std::size_t>(p->level) - 1;
        c.record(binary(seen[i]++ < yes_first[i]));
    }
    EXPECT_EQ(trials, 20u);
    EXPECT_EQ(c.shown(), (std::vector<int>{4, 4, 4, 4, 4}));
    EXPECT_EQ(c.yes(), (std::vector<int>{0, 1, 3, 4, 4}));
    EXPECT_NEAR(c.estimate().value, 2.5, 1e-12);
    EXPECT_EQ(c.estimate().n, 20u);
}

TEST(ConstantStimuli, BadParametersNameTheParameter) {
    const auto with = [](auto change) {
        return [change] {
            ConstantStimuliParams p = constant_params(ConstantOrder::Random);
            change(p);
            ConstantStimuli c(p, 1);
        };
    };
    expect_bad(with([](ConstantStimuliParams& p) { p.levels = {}; }), "levels");
    expect_bad(with([](ConstantStimuliParams& p) { p.levels = {1, 2, 1}; }), "levels");
    expect_bad(with([](ConstantStimuliParams& p) { p.levels = {1, INFINITY}; }), "levels");
    expect_bad(with([](ConstantStimuliParams& p) { p.repetitions = 0; }), "repetitions");
    expect_bad(with([](ConstantStimuliParams& p) { p.criterion = 1; }), "criterion");
    expect_bad([] { parse_constant_order("shuffled"); }, "order");
}

// ---- Forced choice -----------------------------------------------------------------

// The mapping by hand: the observer chose the test iff (chose Left) == (test on the left).
TEST(ForcedChoice, AnswerMappingTable) {
    using M = ChoiceMapping;
    EXPECT_EQ(ForcedChoice::inner_response(Response::Left, true, M::ChoseTest), Response::Yes);
    EXPECT_EQ(ForcedChoice::inner_response(Response::Right, true, M::ChoseTest), Response::No);
    EXPECT_EQ(ForcedChoice::inner_response(Response::Left, false, M::ChoseTest), Response::No);
    EXPECT_EQ(ForcedChoice::inner_response(Response::Right, false, M::ChoseTest), Response::Yes);
    EXPECT_EQ(ForcedChoice::inner_response(Response::Left, true, M::ChoseReference), Response::No);
    EXPECT_EQ(ForcedChoice::inner_response(Response::Right, true, M::ChoseReference), Response::Yes);
    EXPECT_EQ(ForcedChoice::inner_response(Response::Left, false, M::ChoseReference), Response::Yes);
    EXPECT_EQ(ForcedChoice::inner_response(Response::Right, false, M::ChoseReference), Response::No);
    expect_bad([] { ForcedChoice::inner_response(Response::Yes, true, M::ChoseTest); }, "response");
    expect_bad([] { parse_choice_mapping("test"); }, "mapping");
}

StaircaseParams lin_staircase(double start, int n_down, int n_reversals) {
    StaircaseParams p;
    p.start = start;
    p.step_sizes = {0.4, 0.2, 0.1, 0.05};
    p.step_type = StepType::Lin;
    p.n_up = 1;
    p.n_down = n_down;
    p.n_reversals = n_reversals;
    return p;
}

double mean_last(const std::vector<double>& v, std::size_t n) {
    double s = 0;
    for (std::size_t i = v.size() - n; i < v.size(); ++i) s += v[i];
    return s / static_cast<double>(n);
}

// Brightness matching. The test light is fixed at log level 0 and looks 0.2 log units
// brighter than a reference of the same level (e.g. glare), so the PSE is a reference at
// 0.2. The observer picks the side that looks brighter, with Gaussian decision noise
// sd 0.1: P(picks the reference) = Phi((ref - 0.2) / 0.1), answering with a SIDE. A
// 1-up/1-down staircase on the reference level, told Yes when the reference was picked,
// must settle on 0.2; the test side is random and about half the time on the left.
TEST(ForcedChoice, MatchingStaircaseConvergesOnThePse) {
    double total = 0;
    int left = 0, trials = 0;
    const int runs = 30;
    for (int run = 0; run < runs; ++run) {
        ForcedChoice fc(std::make_unique<Staircase>(lin_staircase(1.0, 1, 40)), ChoiceMapping::ChoseReference,
                        derive_seed(77, static_cast<std::uint64_t>(run)));
        Rng observer(500 + static_cast<std::uint64_t>(run));
        while (auto p = fc.next()) {
            ASSERT_TRUE(p->test_on_left.has_value());
            left += *p->test_on_left ? 1 : 0;
            ++trials;
            const bool picks_reference = observer.uniform() < normal_cdf((p->level - 0.2) / 0.1);
            const bool picks_left = picks_reference ? !*p->test_on_left : *p->test_on_left;
            fc.record(picks_left ? Response::Left : Response::Right);
        }
        const auto& inner = dynamic_cast<const Staircase&>(fc.inner());
        total += mean_last(inner.reversal_levels(), 30);
        EXPECT_EQ(fc.estimate().n, inner.estimate().n);
    }
    EXPECT_NEAR(total / runs, 0.2, 0.02);
    // Binomial(trials, 1/2): 4 sd either side.
    EXPECT_NEAR(left, trials / 2.0, 4 * std::sqrt(trials / 4.0));
}

// 2AFC detection: P(correct) = 1/2 + 1/2 Phi(x). 1-up/3-down on "correct" tracks
// P(correct) = 0.794, i.e. Phi(x) = 2*0.794 - 1 = 0.587, x = 0.221.
TEST(ForcedChoice, DetectionStaircaseTracksThe794PercentPoint) {
    const double target_phi = 2 * std::pow(0.5, 1.0 / 3.0) - 1;
    double lo = -5, hi = 5;
    for (int i = 0; i < 200; ++i) {
        const double mid = (lo + hi) / 2;
        (normal_cdf(mid) < target_phi ? lo : hi) = mid;
    }
    const double target = (lo + hi) / 2;
    EXPECT_NEAR(target, 0.2206, 1e-3);
    double total = 0;
    const int runs = 30;
    for (int run = 0; run < runs; ++run) {
        StaircaseParams sp = lin_staircase(1.0, 3, 80);
        sp.step_sizes = {0.4, 0.2, 0.1};
        ForcedChoice fc(std::make_unique<Staircase>(sp), ChoiceMapping::ChoseTest, static_cast<std::uint64_t>(run));
        Rng observer(900 + static_cast<std::uint64_t>(run));
        while (auto p = fc.next()) {
            const bool correct = observer.uniform() < 0.5 + 0.5 * normal_cdf(p->level);
            const bool picks_left = correct == *p->test_on_left;
            fc.record(picks_left ? Response::Left : Response::Right);
        }
        total += mean_last(dynamic_cast<const Staircase&>(fc.inner()).reversal_levels(), 70);
    }
    // The 2AFC function is shallow, so one run's reversal mean scatters by ~0.1-0.14;
    // 30 runs put the standard error near 0.02 (the step bias at step 0.1 is ~-0.015).
    EXPECT_NEAR(total / runs, target, 0.07);
}

// ---- Interleaving ----------------------------------------------------------------------

std::vector<std::unique_ptr<Procedure>> two_constant_blocks() {
    std::vector<std::unique_ptr<Procedure>> v;
    ConstantStimuliParams a;
    a.levels = {1, 2};
    a.repetitions = 1;
    ConstantStimuliParams b;
    b.levels = {10, 20, 30, 40};
    b.repetitions = 1;
    v.push_back(std::make_unique<ConstantStimuli>(a, 1));
    v.push_back(std::make_unique<ConstantStimuli>(b, 2));
    return v;
}

// Sequential: A (2 trials) and B (4 trials) alternate until A is done, then B alone:
// streams 0 1 0 1 1 1.
TEST(Interleaver, SequentialOrderByHand) {
    Interleaver in(two_constant_blocks(), InterleaveOrder::Sequential, 0);
    std::vector<std::size_t> streams;
    while (auto p = in.next()) {
        streams.push_back(p->stream);
        EXPECT_EQ(p->level < 5, p->stream == 0);  // A's levels are 1, 2; B's are 10..40
        in.record(Response::Yes);
    }
    EXPECT_EQ(streams, (std::vector<std::size_t>{0, 1, 0, 1, 1, 1}));
    EXPECT_TRUE(in.procedure(0).finished());
    EXPECT_TRUE(in.procedure(1).finished());
    EXPECT_EQ(in.estimate().n, 2u);
}

TEST(Interleaver, RandomOrderVisitsAllAndFinishesAll) {
    std::vector<std::unique_ptr<Procedure>> v;
    for (int i = 0; i < 3; ++i) {
        ConstantStimuliParams c;
        c.levels = {static_cast<double>(i)};
        c.repetitions = 200;
        v.push_back(std::make_unique<ConstantStimuli>(c, static_cast<std::uint64_t>(i)));
    }
    Interleaver in(std::move(v), InterleaveOrder::Random, 123);
    std::vector<int> first300(3, 0);
    int t = 0;
    while (auto p = in.next()) {
        if (t++ < 300) ++first300[p->stream];
        EXPECT_EQ(p->level, static_cast<double>(p->stream));
        in.record(Response::No);
    }
    EXPECT_EQ(t, 600);
    for (int c : first300) EXPECT_NEAR(c, 100, 35);  // uniform choice among three while all are open
}

TEST(Interleaver, AnAdjustmentKeepsTheFloorUntilConfirm) {
    std::vector<std::unique_ptr<Procedure>> v;
    AdjustmentParams a = adjustment_params();
    a.n_trials = 3;
    v.push_back(std::make_unique<Adjustment>(a, 1));
    v.push_back(std::make_unique<Adjustment>(a, 2));
    Interleaver in(std::move(v), InterleaveOrder::Random, 5);
    Rng actions(6);
    std::size_t stream = in.next()->stream;
    bool confirmed = true;
    while (auto p = in.next()) {
        if (!confirmed) {
            EXPECT_EQ(p->stream, stream) << "switched mid-trial";
        }
        stream = p->stream;
        const std::uint64_t k = actions.below(5);
        const Response r = k == 4 ? Response::Confirm : static_cast<Response>(4 + k);
        in.record(r);
        confirmed = r == Response::Confirm;
    }
    EXPECT_EQ(dynamic_cast<const Adjustment&>(in.procedure(0)).matches().size(), 3u);
    EXPECT_EQ(dynamic_cast<const Adjustment&>(in.procedure(1)).matches().size(), 3u);
}

TEST(Interleaver, RejectsBadProceduresAndAnswers) {
    expect_bad([] { Interleaver in({}, InterleaveOrder::Random, 0); }, "procedures");
    expect_bad(
        [] {
            std::vector<std::unique_ptr<Procedure>> v;
            v.push_back(nullptr);
            Interleaver in(std::move(v), InterleaveOrder::Random, 0);
        },
        "procedures");
    expect_bad(
        [] {
            auto v = two_constant_blocks();
            v[1]->record(Response::Yes);
            Interleaver in(std::move(v), InterleaveOrder::Random, 0);
        },
        "procedures");
    Interleaver in(two_constant_blocks(), InterleaveOrder::Random, 0);
    const std::string before = in.state();
    expect_bad([&] { in.record(Response::Left); }, "response");
    EXPECT_EQ(in.state(), before);
    EXPECT_TRUE(in.history().empty());
    expect_bad([] { parse_interleave_order("shuffle"); }, "interleave");
    expect_bad([] { ForcedChoice fc(nullptr, ChoiceMapping::ChoseTest, 0); }, "procedure");
}

// ---- Replay -------------------------------------------------------------------------

using Answerer = std::function<Response(const Proposal&, Rng&)>;

Response coin_answer(const Proposal&, Rng& r) {
    return binary(r.coin());
}
Response side_answer(const Proposal&, Rng& r) {
    return r.coin() ? Response::Left : Response::Right;
}
Response action_answer(const Proposal&, Rng& r) {
    const std::uint64_t k = r.below(6);
    return k >= 4 ? (k == 5 ? Response::Confirm : Response::FineUp) : static_cast<Response>(4 + k);
}

void expect_same_proposal(const std::optional<Proposal>& a, const std::optional<Proposal>& b, std::size_t k) {
    ASSERT_EQ(a.has_value(), b.has_value()) << "after " << k << " responses";
    if (!a) return;
    EXPECT_EQ(a->level, b->level) << "after " << k << " responses";  // bit for bit
    EXPECT_EQ(a->test_on_left, b->test_on_left) << "after " << k << " responses";
    EXPECT_EQ(a->stream, b->stream) << "after " << k << " responses";
    EXPECT_EQ(a->trial, b->trial) << "after " << k << " responses";
}

/// Runs a copy of `fresh` with seeded random answers, remembering every proposal and
/// state; then, for every prefix of the history, replays it into another fresh copy and
/// checks the same state and the same next proposal; then continues a replayed copy with
/// the rest of the answers and checks it ends where the uninterrupted run ended.
void check_replay(const Procedure& fresh, const Answerer& answer, std::uint64_t seed, std::size_t max_responses) {
    ASSERT_TRUE(fresh.history().empty());
    const auto live = fresh.clone();
    Rng rng(seed);
    std::vector<std::optional<Proposal>> proposals;
    std::vector<std::string> states;
    while (!live->finished() && live->history().size() < max_responses) {
        proposals.push_back(live->next());
        states.push_back(live->state());
        live->record(answer(*proposals.back(), rng));
    }
    proposals.push_back(live->next());
    states.push_back(live->state());
    const std::vector<Response> history = live->history();
    ASSERT_GT(history.size(), 5u);
    EXPECT_NE(states.front(), states.back());  // state() does see the history

    for (std::size_t k = 0; k <= history.size(); ++k) {
        const auto replayed = fresh.clone();
        replay(*replayed, std::span<const Response>(history).first(k));
        ASSERT_EQ(replayed->state(), states[k]) << fresh.kind() << " after " << k << " responses";
        expect_same_proposal(replayed->next(), proposals[k], k);
        EXPECT_EQ(replayed->finished(), k == history.size() && live->finished());
    }
    // Resume in the middle: replay half, then answer the rest live.
    const auto resumed = fresh.clone();
    const std::size_t half = history.size() / 2;
    replay(*resumed, std::span<const Response>(history).first(half));
    for (std::size_t k = half; k < history.size(); ++k) {
        expect_same_proposal(resumed->next(), proposals[k], k);
        resumed->record(history[k]);
    }
    EXPECT_EQ(resumed->state(), live->state());
    EXPECT_EQ(resumed->history(), history);
    const Estimate a = resumed->estimate(), b = live->estimate();
    EXPECT_TRUE((std::isnan(a.value) && std::isnan(b.value)) || a.value == b.value);
}

TEST(Replay, Staircase) {
    StaircaseParams p;
    p.start = 0.8;
    p.step_sizes = {4, 2, 1};
    p.n_reversals = 12;
    p.n_trials = 30;
    check_replay(Staircase(p), coin_answer, 1, 1000);
    p.step_type = StepType::Lin;
    p.min_level = -3;
    p.max_level = 3;
    p.n_down = 2;
    p.apply_initial_rule = false;
    check_replay(Staircase(p), coin_answer, 2, 1000);
}

TEST(Replay, WeightedStaircase) {
    WeightedStaircaseParams p;
    p.start = 1;
    p.target = 0.8;
    p.step_sizes = {2, 1, 0.5};
    p.n_reversals = 15;
    check_replay(WeightedStaircase(p), coin_answer, 3, 1000);
}

TEST(Replay, Quest) {
    QuestParams p;
    p.t_guess = -1;
    p.t_guess_sd = 2;
    p.n_trials = 60;
    check_replay(Quest(p), coin_answer, 4, 1000);
    p.method = QuestMethod::Mode;
    p.gamma = 0;
    p.delta = 0;
    p.p_threshold = 0.6;
    p.min_level = -2;
    p.max_level = 0;
    check_replay(Quest(p), coin_answer, 5, 1000);
}

TEST(Replay, Adjustment) {
    AdjustmentParams p = adjustment_params();
    p.n_trials = 6;
    check_replay(Adjustment(p, 17), action_answer, 6, 1000);
}

TEST(Replay, ConstantStimuli) {
    for (ConstantOrder order : {ConstantOrder::Blocked, ConstantOrder::Passes, ConstantOrder::Random})
        check_replay(ConstantStimuli(constant_params(order), 8), coin_answer, 7, 1000);
}

TEST(Replay, ForcedChoice) {
    QuestParams q;
    q.n_trials = 40;
    check_replay(ForcedChoice(std::make_unique<Quest>(q), ChoiceMapping::ChoseTest, 9), side_answer, 8, 1000);
    check_replay(ForcedChoice(std::make_unique<Staircase>(lin_staircase(1, 1, 10)), ChoiceMapping::ChoseReference, 10),
                 side_answer, 9, 1000);
}

// A block mixing every kind: a staircase (Yes/No), a 2AFC QUEST (Left/Right), an
// adjustment (actions), constant stimuli (Yes/No) and a weighted staircase, chosen at random.
std::unique_ptr<Interleaver> mixed_block(InterleaveOrder order, std::uint64_t seed) {
    std::vector<std::unique_ptr<Procedure>> v;
    StaircaseParams s;
    s.start = 1;
    s.n_reversals = 6;
    v.push_back(std::make_unique<Staircase>(s, derive_seed(seed, 0)));
    QuestParams q;
    q.n_trials = 15;
    v.push_back(
        std::make_unique<ForcedChoice>(std::make_unique<Quest>(q), ChoiceMapping::ChoseTest, derive_seed(seed, 1)));
    AdjustmentParams a = adjustment_params();
    a.n_trials = 3;
    v.push_back(std::make_unique<Adjustment>(a, derive_seed(seed, 2)));
    v.push_back(std::make_unique<ConstantStimuli>(constant_params(ConstantOrder::Random), derive_seed(seed, 3)));
    WeightedStaircaseParams w;
    w.start = 1;
    w.n_reversals = 5;
    v.push_back(std::make_unique<WeightedStaircase>(w, derive_seed(seed, 4)));
    return std::make_unique<Interleaver>(std::move(v), order, seed);
}

Response mixed_answer(const Proposal& p, Rng& r) {
    switch (p.stream) {
        case 1:
            return side_answer(p, r);
        case 2:
            return action_answer(p, r);
        default:
            return coin_answer(p, r);
    }
}

TEST(Replay, Interleaver) {
    check_replay(*mixed_block(InterleaveOrder::Random, 31), mixed_answer, 10, 5000);
    check_replay(*mixed_block(InterleaveOrder::Sequential, 32), mixed_answer, 11, 5000);
}

// The typed form: replay<P>(history, constructor arguments...) gives the same object.
TEST(Replay, TypedReplayAndCopies) {
    StaircaseParams p;
    p.start = 2;
    p.n_reversals = 8;
    Staircase live(p);
    Rng r(12);
    while (live.next()) live.record(binary(r.coin()));
    const Staircase again = replay<Staircase>(live.history(), p, std::uint64_t{0});
    EXPECT_EQ(again.levels(), live.levels());
    EXPECT_EQ(again.reversal_trials(), live.reversal_trials());
    EXPECT_EQ(again.state(), live.state());

    // Copies of composite procedures are deep: advancing one leaves the other alone.
    auto block = mixed_block(InterleaveOrder::Random, 40);
    Interleaver copy = *block;
    Rng answers(13);
    block->record(mixed_answer(*block->next(), answers));
    EXPECT_NE(copy.state(), block->state());
    EXPECT_TRUE(copy.history().empty());
}

TEST(Replay, RejectsAnOverlongOrMisplacedHistory) {
    StaircaseParams p;
    p.start = 1;
    p.step_sizes = {1};
    p.n_reversals = 1;
    Staircase s(p);
    // Y (down), N: reversal 1 -> finished after two answers.
    const std::vector<Response> log = {Response::Yes, Response::No, Response::Yes};
    expect_bad([&] { replay(s, log); }, "history");
    Staircase used(p);
    used.record(Response::Yes);
    EXPECT_THROW(replay(used, std::span<const Response>(log).first(1)), std::logic_error);
    Staircase done = replay<Staircase>(std::span<const Response>(log).first(2), p);
    EXPECT_TRUE(done.finished());
    EXPECT_THROW(done.record(Response::Yes), std::logic_error);
}

}  // namespace
