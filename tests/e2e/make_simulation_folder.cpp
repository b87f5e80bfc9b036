// make_simulation_folder DIR SESSIONS [REPETITIONS[,REPETITIONS...]] [DISTINCT]
// Writes a simulation folder as `atonlab simulate` does (docs/simulate.md):
// DIR/simulation.json and DIR/sessions/00/session-NNNNNN.db, one simulated
// session each, answered by an observer with a known PSE (2.0 log10 cd, SD
// 0.1; tests/unit/analysis_test_data.h) on the two-condition constant-stimuli
// glare protocol (7 levels × REPETITIONS, default 10; a list "4,8,16" makes one
// design per count, SESSIONS each, in sessions/00, 01, ...). With DISTINCT < SESSIONS
// only the first DISTINCT sessions are simulated and the others are byte
// copies of them (the bench's 10,000-file folders: analysis reads each file
// whole whatever it holds). For the e2e tests and the bench, not installed.
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "analysis_test_data.h"
#include "atonlab/analysis/simulation_manifest.h"
#include "atonlab/store/json.h"

namespace fs = std::filesystem;
namespace td = atonlab::analysis::test_data;

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: make_simulation_folder DIR SESSIONS [REPETITIONS[,REPETITIONS...]] [DISTINCT]\n");
        return 2;
    }
    const fs::path dir = argv[1];
    const int n = std::stoi(argv[2]);
    // One design per repetition count ("4,8,16": three designs, as simulate's --vary makes them).
    std::vector<int> designs;
    for (std::string list = argc > 3 ? argv[3] : "10"; !list.empty();) {
        const auto comma = list.find(',');
        designs.push_back(std::stoi(list.substr(0, comma)));
        list = comma == std::string::npos ? std::string() : list.substr(comma + 1);
    }
    const int distinct = argc > 4 ? std::min(n, std::stoi(argv[4])) : n;
    using Json = nlohmann::ordered_json;
    atonlab::analysis::SimulationManifest manifest;
    for (const int reps : designs) {
        const std::string label = designs.size() > 1 ? fmt::format("repetitions={}", reps) : std::string();
        manifest.designs.push_back(atonlab::analysis::ManifestDesign{
            label, "sim.toml", "0", label.empty() ? std::vector<std::string>{} : std::vector<std::string>{label}, ""});
    }
    manifest.sessions = static_cast<std::size_t>(n);
    manifest.observer_json = "{}";
    manifest.decisions = "table";
    fs::create_directories(dir);
    std::ofstream(atonlab::analysis::simulation_manifest_path(dir)) << manifest.json();
    for (std::size_t d = 0; d < designs.size(); ++d) {
        const fs::path folder = atonlab::analysis::simulation_session_file(dir, d, 0).parent_path();
        fs::create_directories(folder);
        const std::string protocol = td::constant_stimuli_protocol(designs[d]);
        for (int i = 0; i < n; ++i) {
            const fs::path file = folder / fmt::format("session-{:06}.db", i);
            if (i >= distinct) {
                fs::copy_file(folder / fmt::format("session-{:06}.db", i % distinct), file,
                              fs::copy_options::overwrite_existing);
                continue;
            }
            td::SimObserver obs = td::sim(fmt::format("sim-d{:02}-{:06}", d, i), 2.0, 0.1,
                                          7919u * static_cast<unsigned>(i + 1) + static_cast<unsigned>(d));
            Json truth;
            for (const char* c : {"night-empirical", "night-perceptual"})
                truth[c] = {{"value", 2.0}, {"what", "pse"}, {"p", 0.5}};
            obs.simulation_json = atonlab::store::dump_json(Json{{"design", manifest.designs[d].label},
                                                                 {"design_index", d},
                                                                 {"index", i},
                                                                 {"seed", i + 1},
                                                                 {"true", truth},
                                                                 {"decisions", "table"}});
            td::run_simulated(file, protocol, obs, static_cast<std::uint64_t>(i + 1));
        }
    }
    return 0;
}
