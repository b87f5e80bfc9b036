// The simulation report (analysis/simulation.h): simulation folders made here
// with the store's API, each session answered by an observer whose
// psychometric function is known (analysis_test_data.h), so the report's
// bias, coverage and power can be compared with what they must be; and the
// files a folder may hold that cannot be used (unfinished, damaged, an
// ordinary study), which must be listed with their reasons.
#include <gtest/gtest.h>

#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>

#include "analysis_test_data.h"
#include "atonlab/analysis/profile_interval.h"
#include "atonlab/analysis/simulation.h"
#include "atonlab/analysis/simulation_report.h"
#include "atonlab/common/input_error.h"
#include "atonlab/protocols/rng.h"
#include "atonlab/store/json.h"

namespace atonlab::analysis {
namespace {

namespace fs = std::filesystem;
namespace td = test_data;

/// A private folder; on tmpfs where there is one, since each trial is its own
/// synchronous transaction and a few hundred study files are made here.
class Folder {
public:
    Folder() {
        const fs::path base = fs::is_directory("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
        std::string pattern = (base / "atonlab-simtest-XXXXXX").string();
        EXPECT_NE(mkdtemp(pattern.data()), nullptr);
        path_ = pattern;
    }
    ~Folder() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    Folder(const Folder&) = delete;
    Folder& operator=(const Folder&) = delete;
    const fs::path& path() const { return path_; }

private:
    fs::path path_;
};

void write_manifest(const fs::path& dir, int n_designs) {
    SimulationManifest m;
    for (int d = 0; d < n_designs; ++d) {
        const std::string o = fmt::format("repetitions={}", 10 * (d + 1));
        m.designs.push_back(ManifestDesign{o, "sim.toml", "00", {o}, ""});
    }
    m.observer_json = "{}";
    m.decisions = "rendered";
    std::ofstream(simulation_manifest_path(dir)) << m.json();
}

/// simulation_json of a session whose conditions' true PSE is `truth`.
std::string simulation_json(int design, int index, double truth) {
    nlohmann::ordered_json t;
    for (const char* c : {"night-empirical", "night-perceptual"})
        t[c] = {{"value", truth}, {"what", "pse"}, {"p", 0.5}};
    return store::dump_json(nlohmann::ordered_json{{"design", ""},
                                                   {"design_index", design},
                                                   {"index", index},
                                                   {"seed", 1000 + index},
                                                   {"observer", {{"lapse_rate", 0.0}}},
                                                   {"true", t},
                                                   {"decisions", "table"}});
}

fs::path session_file(const fs::path& dir, int design, int index) {
    const fs::path file =
        simulation_session_file(dir, static_cast<std::size_t>(design), static_cast<std::size_t>(index));
    fs::create_directories(file.parent_path());
    return file;
}

/// `n` sessions of design `design`: the constant-stimuli glare protocol
/// (2 conditions × 7 levels × `reps`), answered with PSE `mu` and SD `sigma`,
/// storing `truth` as the true PSE.
void make_sessions(const fs::path& dir, int design, int n, int reps, double mu, double sigma, double truth) {
    const std::string protocol = td::constant_stimuli_protocol(reps);
    for (int i = 0; i < n; ++i) {
        td::SimObserver obs = td::sim(fmt::format("sim-d{:02}-{:06}", design, i), mu, sigma,
                                      static_cast<std::uint64_t>(7919 * (i + 1) + design));
        obs.simulation_json = simulation_json(design, i, truth);
        td::run_simulated(session_file(dir, design, i), protocol, obs, static_cast<std::uint64_t>(i + 1));
    }
}

SimulationOptions options() {
    SimulationOptions o;
    o.n_threads = 2;
    return o;
}

// 200 sessions of an ideal observer (no lapses, the fitted family): the PSE
// is unbiased and the profile intervals cover it 95 % of the time. Binomial
// SD of the coverage over 400 intervals (2 conditions × 200 sessions):
// sqrt(0.95 × 0.05 / 400) = 1.1 %; the tolerance of 3.5 % allows 3 SD and
// the likelihood interval's own small-sample error at 70 trials.
TEST(AnalysisSimulation, IdealObserverIsUnbiasedAndItsIntervalsCover95Percent) {
    Folder f;
    write_manifest(f.path(), 1);
    const double mu = 2.0, sigma = 0.1;
    make_sessions(f.path(), 0, 200, 10, mu, sigma, mu);
    SimulationOptions o = options();
    o.effect_log10 = 0.0;  // the false-positive rate of the enhancement's test
    const SimulationResults r = analyze_simulation(f.path(), o);
    EXPECT_TRUE(r.skipped.empty()) << r.skipped.front().file << ": " << r.skipped.front().reason;
    ASSERT_EQ(r.sessions.size(), 200u);
    ASSERT_EQ(r.conditions.size(), 2u);
    int covered = 0, intervals = 0;
    for (const ConditionSummary& c : r.conditions) {
        SCOPED_TRACE(c.condition);
        ASSERT_TRUE(c.truth && c.bias && c.sd && c.coverage);
        EXPECT_DOUBLE_EQ(*c.truth, mu);
        EXPECT_FALSE(c.truth_differs);
        EXPECT_EQ(c.n_estimates, 200);
        // The PSE's SD for 70 trials at these levels is about 0.025 log10: bias within 4 SE.
        EXPECT_NEAR(*c.bias, 0.0, 4.0 * *c.sd / std::sqrt(200.0));
        EXPECT_NEAR(*c.rmse, std::sqrt(*c.bias * *c.bias + *c.sd * *c.sd * 199.0 / 200.0), 1e-12);
        EXPECT_EQ(*c.trials_median, 70.0);
        EXPECT_EQ(*c.trials_p90, 70.0);
        covered += c.n_covered;
        intervals += c.n_intervals;
    }
    ASSERT_EQ(intervals, 400);
    EXPECT_NEAR(static_cast<double>(covered) / intervals, 0.95, 0.035);
    // Power at D = 0 is the test's false-positive rate: near 5 %.
    ASSERT_EQ(r.power.size(), 2u);
    for (const PowerSummary& p : r.power) {
        ASSERT_TRUE(p.power);
        EXPECT_EQ(p.n_sessions, 200);
        EXPECT_NEAR(*p.power, 0.05, 0.045) << p.condition_a;
        EXPECT_EQ(p.what, "enhancement by glare");
    }
}

// The stored truth 0.05 above what the observer answers: the bias is −0.05.
TEST(AnalysisSimulation, ABiasedDesignShowsItsBias) {
    Folder f;
    write_manifest(f.path(), 2);
    make_sessions(f.path(), 0, 40, 10, 2.0, 0.1, 2.05);
    make_sessions(f.path(), 1, 40, 10, 2.0, 0.1, 2.0);
    const SimulationResults r = analyze_simulation(f.path(), options());
    ASSERT_EQ(r.conditions.size(), 4u);
    for (const ConditionSummary& c : r.conditions) {
        SCOPED_TRACE(c.design + " " + c.condition);
        ASSERT_TRUE(c.bias && c.sd);
        const double expected = c.design_index == 0 ? -0.05 : 0.0;
        EXPECT_NEAR(*c.bias, expected, 4.0 * *c.sd / std::sqrt(40.0));
        EXPECT_EQ(c.design, c.design_index == 0 ? "repetitions=10" : "repetitions=20");
    }
}

double normal_cdf(double z) {
    return boost::math::cdf(boost::math::normal(), z);
}

// Errors N(0, sigma²) with se = sigma: the location-shift power is the z
// test's, Phi(D/sigma − z) + Phi(−D/sigma − z) (the textbook normal power).
// 20,000 samples: binomial SD of the power at most 0.0035; tolerance 4 SD.
TEST(AnalysisSimulation, PowerIsTheNormalTheoryPowerForKnownErrors) {
    const double sigma = 0.02, z = 1.959963984540054;
    protocols::Rng rng(42);
    std::vector<DifferenceSample> samples;
    for (int i = 0; i < 20000; ++i) {
        // Box-Muller from the platform-independent Rng.
        const double u1 = rng.uniform(), u2 = rng.uniform();
        const double n = std::sqrt(-2.0 * std::log(1.0 - u1)) * std::cos(2.0 * M_PI * u2);
        samples.push_back({0.3 + sigma * n, 0.3, sigma});
    }
    for (const double effect : {0.0, 0.02, 0.05, -0.05}) {
        const PowerSummary p = power_of(samples, effect, 0.95);
        const double analytic = normal_cdf(effect / sigma - z) + normal_cdf(-effect / sigma - z);
        ASSERT_TRUE(p.power && p.power_ci);
        EXPECT_NEAR(*p.power, analytic, 0.014) << "effect " << effect;
        EXPECT_NEAR(*p.true_difference, 0.3, 1e-12);
        EXPECT_LE(p.power_ci->lower, *p.power);
        EXPECT_GE(p.power_ci->upper, *p.power);
    }
}

// Intervals 1.5 × too narrow (errors N(0, (1.5 se)²) against ±1.96 se) cover
// 2Φ(1.96/1.5) − 1 = 80.9 %; the calibrated interval widens them by ≈ 1.5
// and, with the factor found on the other half, covers ≈ 95 % of the sessions.
TEST(AnalysisSimulation, CalibratedIntervalsWidenTooNarrowIntervalsToTheirNominalCoverage) {
    const double se = 0.02, z = 1.959963984540054;
    protocols::Rng rng(7);
    std::vector<SessionSummary> sessions;
    for (int i = 0; i < 4000; ++i) {
        const double u1 = rng.uniform(), u2 = rng.uniform();
        const double n = std::sqrt(-2.0 * std::log(1.0 - u1)) * std::cos(2.0 * M_PI * u2);
        SessionSummary s;
        s.index = i;
        SessionEstimate e;
        e.condition = "c";
        e.truth = -2.0;
        e.estimate = -2.0 + 1.5 * se * n;
        e.ci = Interval{*e.estimate - z * se, *e.estimate + z * se};
        s.conditions.push_back(e);
        sessions.push_back(s);
    }
    SimulationManifest manifest;
    const std::vector<ConditionSummary> c = summarize_conditions(sessions, manifest, 0.95);
    ASSERT_EQ(c.size(), 1u);
    ASSERT_TRUE(c[0].coverage && c[0].widen_factor && c[0].calibrated_coverage);
    const double sd = std::sqrt(0.95 * 0.05 / 4000);
    EXPECT_NEAR(*c[0].coverage, 2 * normal_cdf(z / 1.5) - 1, 4 * std::sqrt(0.81 * 0.19 / 4000));
    EXPECT_NEAR(*c[0].widen_factor, 1.5, 0.08);
    EXPECT_NEAR(*c[0].calibrated_coverage, 0.95, 4 * sd);
    EXPECT_EQ(c[0].n_calibrated, 4000);
}

// With many trials the profile-likelihood interval is the Wald interval of
// the Fisher information (both are first-order the same; Pawitan 2001, sec.
// 9.5). A probit with lambda fixed at 0, alpha = 2, beta = 10, 5 levels of
// 4,000 trials with the expected counts: Var(alpha) = (I^-1)_00 with
// I_jk = sum n dPsi/dtheta_j dPsi/dtheta_k / (Psi (1 - Psi)),
// dPsi/dalpha = -beta phi(z), dPsi/dbeta = (x - alpha) phi(z). Tolerance 3 %
// of the half-width: the likelihood's small asymmetry at this n.
TEST(AnalysisSimulation, ProfileIntervalIsTheFisherIntervalWithManyTrials) {
    const double alpha = 2.0, beta = 10.0, n = 4000.0;
    std::vector<LevelCounts> data;
    double i00 = 0.0, i01 = 0.0, i11 = 0.0;
    for (const double x : {1.8, 1.9, 2.0, 2.1, 2.2}) {
        const double z = beta * (x - alpha);
        const double p = td::phi(z);
        data.push_back({x, static_cast<int>(n), static_cast<int>(std::lround(n * p))});
        const double density = std::exp(-0.5 * z * z) / std::sqrt(2.0 * M_PI);
        const double da = -beta * density, db = (x - alpha) * density;
        const double w = n / (p * (1.0 - p));
        i00 += w * da * da;
        i01 += w * da * db;
        i11 += w * db * db;
    }
    const double var_alpha = i11 / (i00 * i11 - i01 * i01);
    const double half = 1.959963984540054 * std::sqrt(var_alpha);
    FitOptions fo;
    fo.lapse = RateConstraint::fixed_at(0.0);
    const PsychometricFit fit = fit_psychometric(data, fo);
    ASSERT_TRUE(fit.estimate);
    const ProfileInterval p = profile_threshold_interval(data, fit, 0.95);
    ASSERT_TRUE(p.ci) << p.reason;
    EXPECT_FALSE(p.lower_open || p.upper_open);
    EXPECT_NEAR(fit.estimate->threshold - p.ci->lower, half, 0.03 * half);
    EXPECT_NEAR(p.ci->upper - fit.estimate->threshold, half, 0.03 * half);
}

// Clopper-Pearson at the ends has a closed form: k = 0 gives
// [0, 1 − (α/2)^(1/n)], k = n gives [(α/2)^(1/n), 1].
TEST(AnalysisSimulation, ClopperPearsonHasItsClosedFormAtTheEnds) {
    const auto none = clopper_pearson(0, 10, 0.95);
    ASSERT_TRUE(none);
    EXPECT_DOUBLE_EQ(none->lower, 0.0);
    EXPECT_NEAR(none->upper, 1.0 - std::pow(0.025, 0.1), 1e-12);
    const auto all = clopper_pearson(10, 10, 0.95);
    ASSERT_TRUE(all);
    EXPECT_NEAR(all->lower, std::pow(0.025, 0.1), 1e-12);
    EXPECT_DOUBLE_EQ(all->upper, 1.0);
    EXPECT_FALSE(clopper_pearson(0, 0, 0.95));
    EXPECT_EQ(*nearest_rank({1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, 0.9), 9.0);
    EXPECT_EQ(*nearest_rank({1, 2, 3}, 0.9), 3.0);
}

// Every file that cannot be used is listed with its reason; the good ones are read.
TEST(AnalysisSimulation, UnusableFilesAreListedWithTheirReasons) {
    Folder f;
    write_manifest(f.path(), 1);
    make_sessions(f.path(), 0, 3, 2, 2.0, 0.1, 2.0);
    const std::string protocol = td::constant_stimuli_protocol(2);
    // Unfinished: still named .partial.
    {
        td::SimObserver obs = td::sim("sim-d00-000003", 2.0, 0.1, 3);
        obs.simulation_json = simulation_json(0, 3, 2.0);
        td::run_simulated(f.path() / "sessions/00/session-000003.db.partial", protocol, obs);
    }
    // Damaged: a finished file cut to half its length.
    {
        td::SimObserver obs = td::sim("sim-d00-000004", 2.0, 0.1, 4);
        obs.simulation_json = simulation_json(0, 4, 2.0);
        const fs::path p = session_file(f.path(), 0, 4);
        td::run_simulated(p, protocol, obs);
        fs::resize_file(p, fs::file_size(p) / 2);
    }
    // An ordinary study (no simulation_json).
    td::run_simulated(session_file(f.path(), 0, 5), protocol, td::sim("person-1"));
    // A session that was not finished.
    {
        td::SimObserver obs = td::sim("sim-d00-000006", 2.0, 0.1, 6);
        obs.simulation_json = simulation_json(0, 6, 2.0);
        td::run_simulated(session_file(f.path(), 0, 6), protocol, obs, 7, false, 5);
    }
    // A design the manifest does not name, and a stray file.
    {
        td::SimObserver obs = td::sim("sim-d03-000000", 2.0, 0.1, 7);
        obs.simulation_json = simulation_json(3, 0, 2.0);
        td::run_simulated(session_file(f.path(), 3, 0), protocol, obs);
        std::ofstream(f.path() / "sessions/00/notes.txt") << "hello\n";
    }
    const SimulationResults r = analyze_simulation(f.path(), options());
    EXPECT_EQ(r.sessions.size(), 3u);
    EXPECT_EQ(r.files_found, 9u);
    std::map<std::string, std::string> why;
    for (const SkippedFile& s : r.skipped) why[fs::path(s.file).filename().string()] = s.reason;
    ASSERT_EQ(why.size(), 6u);
    EXPECT_NE(why["session-000003.db.partial"].find("unfinished"), std::string::npos);
    EXPECT_NE(why["session-000004.db"].find("refused"), std::string::npos);
    EXPECT_NE(why["session-000005.db"].find("not a simulated one"), std::string::npos);
    EXPECT_NE(why["session-000006.db"].find("not completed"), std::string::npos);
    EXPECT_NE(why["session-000000.db"].find("design 3 is not in simulation.json"), std::string::npos);
    EXPECT_NE(why["notes.txt"].find("not a session file"), std::string::npos);

    // The report's files: every session × condition in sessions.csv, every skipped file in summary.json.
    Folder out;
    const PlotResult plots = make_simulation_figures(out.path(), r, [] {
        PlotOptions po;
        po.gnuplot = "atonlab-no-such-gnuplot";
        return po;
    }());
    EXPECT_TRUE(plots.gnuplot_missing);
    SimulationReportContext ctx;
    ctx.results = &r;
    ctx.plots = &plots;
    for (const fs::path& p : write_simulation_report(out.path(), ctx)) EXPECT_TRUE(fs::is_regular_file(p)) << p;
    std::ifstream sessions(out.path() / "sessions.csv");
    int lines = 0;
    for (std::string line; std::getline(sessions, line);) ++lines;
    EXPECT_EQ(lines, 1 + 3 * 2);
    std::ifstream in(out.path() / "summary.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["skipped"].size(), 6u);
    EXPECT_EQ(j["files"]["read"], 3);
}

// --effect-between A,B: one power row per design for A − B, whose true
// difference is 0 here (both conditions have the same truth); a condition
// no session has is refused, naming the option.
TEST(AnalysisSimulation, EffectBetweenTwoConditions) {
    Folder f;
    write_manifest(f.path(), 1);
    make_sessions(f.path(), 0, 20, 4, 2.0, 0.1, 2.0);
    SimulationOptions o = options();
    o.effect_log10 = 0.5;  // about 10 standard errors of the difference: every session detects it
    o.effect_between = std::pair<std::string, std::string>{"night-empirical", "night-perceptual"};
    std::vector<std::string> warnings;
    const SimulationResults r = analyze_simulation(f.path(), o);
    ASSERT_EQ(r.power.size(), 1u);
    const PowerSummary& p = r.power.front();
    EXPECT_EQ(p.what, "night-empirical − night-perceptual");
    EXPECT_NEAR(*p.true_difference, 0.0, 1e-12);
    EXPECT_EQ(p.n_sessions, 20);
    EXPECT_EQ(*p.power, 1.0);
    o.effect_between = std::pair<std::string, std::string>{"night-empirical", "no-such-condition"};
    try {
        (void)power_analyses(r.sessions, r.manifest, o, warnings);
        FAIL() << "an unknown condition was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--effect-between"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("no-such-condition"), std::string::npos) << e.what();
    }
}

TEST(AnalysisSimulation, AFolderWithoutAManifestIsRefused) {
    Folder f;
    EXPECT_FALSE(is_simulation_folder(f.path()));
    EXPECT_THROW(analyze_simulation(f.path(), options()), InputError);
    std::ofstream(f.path() / "simulation.json") << R"({"format": "something-else", "version": 1})";
    try {
        read_simulation_manifest(f.path());
        FAIL() << "a manifest of another format was read";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("format"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace atonlab::analysis
