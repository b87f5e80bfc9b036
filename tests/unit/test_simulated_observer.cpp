// Simulated observers for planning a study (protocols/simulated_observer.h):
// each departure from the model observer against its analytic definition.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/protocols/simulated_observer.h"

namespace {

using namespace atonlab;
using namespace atonlab::protocols;

double phi(double z) {
    return 0.5 * std::erfc(-z / std::numbers::sqrt2);
}

TEST(SimulatedObserver, KeysOutOfRangeOrUnknownAreRefusedNamingTheKey) {
    SimulatedObserverParams p;
    const SourceLocation where = SourceLocation::command_line("--observer", "eta");
    EXPECT_THROW(set_observer_key(p, "eta", 1.0, where), InputError);  // η < 1
    EXPECT_THROW(set_observer_key(p, "eta", -0.1, where), InputError);
    EXPECT_THROW(set_observer_key(p, "lapse_rate", 1.0, where), InputError);
    EXPECT_THROW(set_observer_key(p, "fluctuation_decay", 1.0, where), InputError);
    EXPECT_THROW(set_observer_key(p, "learning_tau_trials", 0.0, where), InputError);
    EXPECT_THROW(set_observer_key(p, "noise_sd_log10", std::nan(""), where), InputError);
    try {
        set_observer_key(p, "etta", 0.2, where);
        FAIL() << "an unknown key was taken";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--observer"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("eta"), std::string::npos) << e.what();  // the keys it takes
    }
    set_observer_key(p, "eta", 0.2, where);
    set_observer_key(p, "lapse_rate", 0.04, where);
    EXPECT_EQ(p.departures.eta, 0.2);
    EXPECT_EQ(p.model.lapse_rate, 0.04);
    EXPECT_EQ(observer_values(p).size(), observer_keys().size());
}

TEST(SimulatedObserver, TheProtocolsObserverTableIsReadAndCheckedAtItsLine) {
    const std::string head = R"(
[protocol]
name = "t"
scene = "s.toml"
seed = 1
[display]
width_px = 640
height_px = 360
width_m = 0.5
viewing_distance_m = 0.9
[defaults]
task = "2afc"
presentation = "two-interval"
test_light = "test"
reference_light = "reference"
level_key = "light.reference.intensity_cd"
level_scale = "log10"
choice = "chose-reference"
[defaults.procedure]
kind = "staircase"
start = -2.0
step_sizes = [0.1]
step_type = "lin"
max_trials = 10
[[block]]
name = "b"
[[block.condition]]
name = "c"
)";
    const Protocol ok = parse_protocol(head + "[observer]\nnoise_sd_log10 = 0.05\neta = 0.2\n", "t.toml");
    const SimulatedObserverParams p = observer_params(ok);
    EXPECT_EQ(p.model.noise_sd_log10, 0.05);
    EXPECT_EQ(p.departures.eta, 0.2);
    try {
        parse_protocol(head + "[observer]\neta = 1.5\n", "t.toml");
        FAIL() << "eta = 1.5 was taken";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("t.toml"), std::string::npos) << what;
        EXPECT_NE(what.find("observer.eta"), std::string::npos) << what;
    }
    EXPECT_THROW(parse_protocol(head + "[observer]\nlapse = 0.1\n", "t.toml"), InputError);
}

TEST(SimulatedObserver, AnIdealObserversChoicesFollowTheModelsPsychometricFunction) {
    // P(view 0) = λ/2 + (1 − λ)Φ(Δ/σ) (observer.h), over 20,000 seeded trials.
    SimulatedObserverParams p;
    p.model.noise_sd_log10 = 0.03;
    p.model.lapse_rate = 0.04;
    for (double delta : {-0.04, 0.0, 0.02}) {
        const int n = 20000;
        int first = 0;
        for (int i = 0; i < n; ++i)
            first += simulated_answer(p, Task::TwoAfc, delta, derive_seed(7, i), 0).response == Response::Left;
        const double expected = 0.02 + 0.96 * phi(delta / 0.03);
        const double sd = std::sqrt(expected * (1 - expected) / n);
        EXPECT_NEAR(static_cast<double>(first) / n, expected, 4 * sd) << "delta " << delta;
    }
}

TEST(SimulatedObserver, WithoutOverdispersionItAnswersAsTheModelObserverDrawForDraw) {
    SimulatedObserverParams p;
    p.model.lapse_rate = 0.1;
    for (int i = 0; i < 200; ++i) {
        const double delta = -0.05 + 0.0005 * i;
        ModelObserver model(p.model, derive_seed(3, i));
        const Answer a = model.answer_2afc_delta(delta);
        const Answer b = simulated_answer(p, Task::TwoAfc, delta, derive_seed(3, i), 99);
        EXPECT_EQ(a.response, b.response);
        EXPECT_EQ(a.response_time_s, b.response_time_s);
    }
}

TEST(SimulatedObserver, BetaBinomialCellsHaveTheModelsMeanAndVarianceEtaSquaredPsiOneMinusPsi) {
    // Beta(ψν, (1 − ψ)ν), ν = 1/η² − 1: mean ψ, variance ψ(1 − ψ)/(ν + 1) = η²ψ(1 − ψ).
    const double psi = 0.7, eta = 0.3;
    const int n = 20000;
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
        const double q = overdispersed_probability(psi, eta, observer_cell("c", 0, 0.001 * i));
        sum += q;
        sum2 += q * q;
    }
    const double mean = sum / n, var = sum2 / n - mean * mean;
    const double expected_var = eta * eta * psi * (1 - psi);
    EXPECT_NEAR(mean, psi, 4 * std::sqrt(expected_var / n));
    EXPECT_NEAR(var, expected_var, 0.05 * expected_var);
    EXPECT_EQ(overdispersed_probability(psi, 0.0, 1), psi);
    // The same cell gives the same draw (a session sees one probability per level).
    EXPECT_EQ(overdispersed_probability(psi, eta, observer_cell("c", 1, -2.1)),
              overdispersed_probability(psi, eta, observer_cell("c", 1, -2.1)));
    EXPECT_NE(observer_cell("c", 1, -2.1), observer_cell("c", 0, -2.1));
}

TEST(SimulatedObserver, DriftIsBiasPlusLearningPlusAStationaryAr1Fluctuation) {
    ObserverDepartures d;
    d.bias_log10 = 0.05;
    d.learning_log10 = -0.1;
    d.learning_tau_trials = 20;
    ObserverDrift learning(d, 1);
    for (std::size_t t : {0u, 10u, 20u, 100u})
        EXPECT_NEAR(learning.at(t), 0.05 - 0.1 * (1 - std::exp(-static_cast<double>(t) / 20.0)), 1e-15);

    ObserverDepartures f;
    f.fluctuation_sd_log10 = 0.04;
    f.fluctuation_decay = 0.8;
    // SD σ and lag-1 autocorrelation a, over many independent series (x_0 = σε_0: stationary from the start).
    double s0 = 0, s00 = 0, s1 = 0, s11 = 0, s01 = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
        ObserverDrift drift(f, derive_seed(11, i));
        const double x = drift.at(5), y = drift.at(6);
        s0 += x, s00 += x * x, s1 += y, s11 += y * y, s01 += x * y;
    }
    const double vx = s00 / n - (s0 / n) * (s0 / n), vy = s11 / n - (s1 / n) * (s1 / n);
    const double r = (s01 / n - (s0 / n) * (s1 / n)) / std::sqrt(vx * vy);
    EXPECT_NEAR(std::sqrt(vx), 0.04, 0.04 * 0.03);
    EXPECT_NEAR(r, 0.8, 0.02);
    // The series is a pure function of the seed and the step, asked for in any order.
    ObserverDrift a(f, 5), b(f, 5);
    const double late = a.at(30);
    for (std::size_t t = 0; t <= 30; ++t) b.at(t);
    EXPECT_EQ(late, b.at(30));
}

TEST(SimulatedObserver, TheDecisionAtAProbabilityInvertsTheModelsFunction) {
    ModelObserverParams m;
    m.noise_sd_log10 = 0.05;
    m.lapse_rate = 0.1;
    for (double p : {0.1, 0.5, 0.75, 0.9}) {
        const std::optional<double> d = decision_at_probability(m, p);
        ASSERT_TRUE(d);
        EXPECT_NEAR(0.05 + 0.9 * phi(*d / 0.05), p, 1e-12);
    }
    EXPECT_FALSE(decision_at_probability(m, 0.02));  // below λ/2: out of the lapses' reach
    EXPECT_EQ(*decision_at_probability(m, 0.5), 0.0);
}

}  // namespace
