#pragma once
// `atonlab bench` (docs/bench.md): run time against error for every quality knob.
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace atonlab::runner {

/// `atonlab bench` (docs/bench.md).
struct BenchCommandOptions {
    bool quick = false;
    std::string out_dir;
    std::vector<std::string> only;
    std::string device_label;
    bool no_plots = false;
    bool quiet = false;
};

void add_bench_command(CLI::App& app, BenchCommandOptions& options);
int run_bench(const BenchCommandOptions& options);

}  // namespace atonlab::runner
