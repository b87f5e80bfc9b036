// `atonlab simulate`'s GL-free parts (runner/src/simulate/): protocol
// variants, the decision table's interpolation and true values, a session
// written from a table, the folder's manifest. The renders behind a table are
// tested in tests/gl/test_simulate.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "atonlab/common/input_error.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/store/store.h"
#include "simulate/decision_table.h"
#include "simulate/protocol_variant.h"
#include "simulate/simulation_designs.h"
#include "simulate/simulation_folder.h"

namespace {

using namespace atonlab;
using namespace atonlab::runner;
namespace fs = std::filesystem;
namespace p = atonlab::protocols;

std::string source(const std::string& rel) {
    const char* dir = std::getenv("ATONLAB_SOURCE_DIR");
    return std::string(dir ? dir : ATONLAB_SOURCE_DIR) + "/" + rel;
}

fs::path fresh_dir(const std::string& name) {
    const fs::path d = fs::temp_directory_path() / ("atonlab-simulate-parts-" + name);
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

TEST(SimulateParts, ProtocolKeysAreSetInTheTomlTreeAndABareKeyIsTheDefaultProcedures) {
    const std::string text = "[protocol]\nname = \"x\"\n\n[defaults.procedure]\nkind = \"staircase\"\nmax_trials = 16\n";
    const std::string out = protocol_with(text, "x.toml",
                                          {parse_protocol_set("max_trials=40", "--vary"),
                                           parse_protocol_set("display.width_px=2560", "--set")},
                                          "--set");
    const toml::table t = toml::parse(out);
    EXPECT_EQ(t["defaults"]["procedure"]["max_trials"].value<int>(), 40);
    EXPECT_EQ(t["display"]["width_px"].value<int>(), 2560);
    EXPECT_EQ(t["defaults"]["procedure"]["kind"].value<std::string>(), "staircase");
    EXPECT_EQ(protocol_with(text, "x.toml", {}, "--set"), text);  // no sets: the text byte for byte
    EXPECT_THROW(protocol_with(text, "x.toml", {parse_protocol_set("protocol.name.x=1", "--set")}, "--set"),
                 InputError);  // "name" is a string, not a table
    EXPECT_THROW(parse_protocol_set("max_trials", "--set"), InputError);
    EXPECT_THROW(parse_protocol_set("kind=quest", "--set"), InputError);  // a string needs quotes
    const std::vector<ProtocolSet> v = parse_vary("start=[-2.1, -3.1],[-2.0, -3.0]");
    ASSERT_EQ(v.size(), 2u);
    EXPECT_EQ(v[0].key, "defaults.procedure.start");
    EXPECT_EQ(v[1].value, "[-2.0, -3.0]");
    EXPECT_THROW(parse_vary("max_trials=20"), InputError);  // nothing to compare
}

TEST(SimulateParts, ACurveIsLinearBetweenItsLevelsAndFlatBeyondThem) {
    DecisionCurve c;
    c.levels = {-3.0, -2.0, -1.0};
    c.values = {-std::numeric_limits<double>::infinity(), 0.2, 0.6};
    EXPECT_DOUBLE_EQ(c.at(-1.5), 0.4);
    EXPECT_DOUBLE_EQ(c.at(-2.0), 0.2);
    EXPECT_DOUBLE_EQ(c.at(0.0), 0.6);
    EXPECT_EQ(c.at(-2.5), -std::numeric_limits<double>::infinity());  // no increment on one side
    DecisionTable t;
    t.key = "k";
    t.bound = 0.001;
    t.stated_bound = 0.004;
    c.condition = "c";
    t.curves.push_back(c);
    const DecisionTable back = DecisionTable::parse(t.json());
    EXPECT_EQ(back.key, "k");
    EXPECT_EQ(back.stated_bound, 0.004);
    EXPECT_EQ(back.curves.at(0).values.front(), -std::numeric_limits<double>::infinity());
    EXPECT_DOUBLE_EQ(back.curve("c", 0).at(-1.5), 0.4);
    EXPECT_THROW(DecisionTable::parse("{}"), std::runtime_error);
}

/// The quick start's design with a linear decision table: Δ = −s·(level − x0)
/// for the test on the left (the reference, whose level this is, on the
/// right: view 1), +s·(level − x0) with it on the right.
std::vector<SimulationDesign> quickstart_with_linear_table(double x0, double s = 0.33) {
    SimulateOptions o;
    o.protocols = {source("protocols/examples/quickstart.toml")};
    std::vector<SimulationDesign> designs = read_designs(o);
    SimulationDesign& d = designs.front();
    d.table.key = "synthetic";
    d.table.bound = d.table.stated_bound = 0.001;
    for (int arrangement : {0, 1}) {
        DecisionCurve c;
        c.condition = "twilight";
        c.arrangement = arrangement;
        c.level_view = arrangement == 1 ? 1 : 0;
        c.levels = {-3.6, -1.6};
        const double sign = arrangement == 1 ? -1.0 : 1.0;
        c.values = {sign * s * (-3.6 - x0), sign * s * (-1.6 - x0)};
        d.table.curves.push_back(c);
    }
    std::string why;
    d.model_true["twilight"] = *table_true_value(d.table, d.protocol.blocks[0].conditions[0], d.observer.model, why);
    return designs;
}

TEST(SimulateParts, TheTablesTrueValueIsWhereTheDecisionVariableMeetsTheTarget) {
    const auto designs = quickstart_with_linear_table(-2.6);
    EXPECT_NEAR(designs.front().model_true.at("twilight"), -2.6, 1e-12);  // a 1-up-1-down staircase: P = 0.5
}

TEST(SimulateParts, ASessionFromATableIsWholeRecomputableAndStoresItsObserverAndTruth) {
    std::vector<SimulationDesign> designs = quickstart_with_linear_table(-2.6);
    SimulationDesign& d = designs.front();
    d.observer.departures.bias_log10 = 0.1;
    const fs::path dir = fresh_dir("session");
    const fs::path a = dir / "a.db", b = dir / "b.db";
    const std::size_t n = simulate_session(d, 3, 1003, a);
    simulate_session(d, 3, 1003, b);
    EXPECT_FALSE(fs::exists(a));  // written under its partial name until committed
    {
        SessionCommitter committer(dir);
        committer.add(a);
        committer.add(b);
        committer.flush();
    }
    ASSERT_TRUE(fs::exists(a));
    EXPECT_FALSE(fs::exists(partial_path(a)));
    const store::Store sa = store::Store::open_read_only(a), sb = store::Store::open_read_only(b);
    const auto sessions = sa.sessions();
    ASSERT_EQ(sessions.size(), 1u);
    EXPECT_EQ(sessions[0].status, store::SessionStatus::completed);
    EXPECT_EQ(sessions[0].observer_code, "sim-d00-000003");
    EXPECT_EQ(sessions[0].seed, 1003u);
    const auto ta = sa.trials(sessions[0].id), tb = sb.trials(sb.sessions()[0].id);
    ASSERT_EQ(ta.size(), n);
    ASSERT_EQ(ta.size(), tb.size());
    for (std::size_t i = 0; i < ta.size(); ++i) {
        EXPECT_EQ(ta[i].level, tb[i].level);
        EXPECT_EQ(ta[i].response, tb[i].response);
        EXPECT_EQ(ta[i].test_on_left, tb[i].test_on_left);
    }
    // The responses replay into the same schedule (what analysis and resume rely on).
    std::vector<p::Response> responses;
    for (const auto& t : ta) responses.push_back(*p::parse_response_word(t.response));
    const p::Schedule replayed = p::Schedule::replay(d.protocol, 1003, responses);
    EXPECT_TRUE(replayed.finished());
    const nlohmann::json sim = nlohmann::json::parse(*sessions[0].simulation_json);
    EXPECT_EQ(sim["index"], 3);
    EXPECT_EQ(sim["decisions"], "table");
    EXPECT_NEAR(sim["true"]["twilight"]["value"].get<double>(), -2.5, 1e-12);  // the model's −2.6 + the bias
    EXPECT_NEAR(sim["true"]["twilight"]["model_value"].get<double>(), -2.6, 1e-12);
    EXPECT_EQ(sim["observer"]["bias_log10"], 0.1);
}

TEST(SimulateParts, AFolderHoldsOneSimulationAndSaysHowAnotherDiffers) {
    analysis::SimulationManifest m;
    m.designs = {analysis::ManifestDesign{"", "q.toml", "abc", {}, "t1"}};
    m.seed = 1;
    m.sessions = 10;
    m.observer_json = "{\"eta\":0.0}";
    m.decisions = "table";
    const analysis::SimulationManifest back = analysis::SimulationManifest::parse(m.json(), "simulation.json");
    EXPECT_EQ(back.identity_difference(m), "");
    EXPECT_EQ(back.protocol(), "q.toml");
    analysis::SimulationManifest more = m;
    more.sessions = 20;  // more sessions continue the same simulation
    EXPECT_EQ(m.identity_difference(more), "");
    analysis::SimulationManifest other = m;
    other.designs[0].protocol_sha256 = "def";
    EXPECT_NE(m.identity_difference(other).find("design 0"), std::string::npos);
    other = m;
    other.observer_json = "{\"eta\":0.2}";
    EXPECT_NE(m.identity_difference(other).find("observer"), std::string::npos);

    const fs::path dir = fresh_dir("folder");
    EXPECT_FALSE(read_manifest(dir));  // empty: a new simulation
    std::ofstream(dir / "notes.txt") << "mine";
    EXPECT_THROW(read_manifest(dir), InputError);  // someone else's files
    EXPECT_THROW(check_writable("/proc/atonlab-simulation"), InputError);
    EXPECT_THROW(check_writable("/dev/null/x"), InputError);
    EXPECT_EQ(analysis::simulation_session_file("D", 2, 17), fs::path("D/sessions/02/session-000017.db"));
    // What is not a manifest is refused naming the key.
    EXPECT_THROW(analysis::SimulationManifest::parse("{\"format\":\"atonlab-simulation\",\"version\":2}", "m"),
                 InputError);
    try {
        analysis::SimulationManifest::parse("{\"format\":\"atonlab-simulation\",\"version\":1,\"designs\":[]}", "m");
        ADD_FAILURE() << "a manifest without designs was read";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("designs"), std::string::npos) << e.what();
    }
}

}  // namespace
