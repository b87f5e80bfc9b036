// make_simulation_folder DIR SESSIONS [REPETITIONS] [DISTINCT]
// Writes a simulation folder as `atonlab simulate` does (docs/simulate.md):
// DIR/simulation.json and DIR/sessions/00/session-NNNNNN.db, one simulated
// session each, answered by an observer with a known PSE (2.0 log10 cd, SD
// 0.1; tests/unit/analysis_test_data.h) on the two-condition constant-stimuli
// glare protocol (7 levels × REPETITIONS, default 10). With DISTINCT < SESSIONS
// only the first DISTINCT sessions are simulated and the others are byte
// copies of them (the bench's 10,000-file folders: analysis reads each file
// whole whatever it holds). For the e2e tests and the bench, not installed.
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "analysis_test_data.h"
#include "atonlab/store/json.h"

namespace fs = std::filesystem;
namespace td = atonlab::analysis::test_data;

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: make_simulation_folder DIR SESSIONS [REPETITIONS] [DISTINCT]\n");
        return 2;
    }
    const fs::path dir = argv[1];
    const int n = std::stoi(argv[2]);
    const int reps = argc > 3 ? std::stoi(argv[3]) : 10;
    const int distinct = argc > 4 ? std::min(n, std::stoi(argv[4])) : n;
    fs::create_directories(dir / "sessions" / "00");
    using Json = nlohmann::ordered_json;
    std::ofstream(dir / "simulation.json") << atonlab::store::dump_json(
        Json{{"format", "atonlab-simulation"},
             {"version", 1},
             {"protocol", "sim.toml"},
             {"protocol_sha256", "0"},
             {"designs", Json::array({Json{{"label", ""}, {"overrides", Json::array()}}})}},
        2);
    const std::string protocol = td::constant_stimuli_protocol(reps);
    for (int i = 0; i < n; ++i) {
        const fs::path file = dir / "sessions" / "00" / fmt::format("session-{:06}.db", i);
        if (i >= distinct) {
            fs::copy_file(dir / "sessions" / "00" / fmt::format("session-{:06}.db", i % distinct), file,
                          fs::copy_options::overwrite_existing);
            continue;
        }
        td::SimObserver obs = td::sim(fmt::format("sim-d00-{:06}", i), 2.0, 0.1, 7919u * static_cast<unsigned>(i + 1));
        Json truth;
        for (const char* c : {"night-empirical", "night-perceptual"})
            truth[c] = {{"value", 2.0}, {"what", "pse"}, {"p", 0.5}};
        obs.simulation_json = atonlab::store::dump_json(Json{{"design", ""},
                                                             {"design_index", 0},
                                                             {"index", i},
                                                             {"seed", i + 1},
                                                             {"true", truth},
                                                             {"decisions", "table"}});
        td::run_simulated(file, protocol, obs, static_cast<std::uint64_t>(i + 1));
    }
    return 0;
}
