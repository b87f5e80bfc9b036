// `atonlab bench [--quick] --out DIR [--only NAME...] [--device-label TEXT]`:
// run time against error for every quality knob (docs/bench.md). Headless
// (EGL): Mesa llvmpipe without a GPU, the vendor driver with one; the GL
// renderer is recorded with the results.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "atonlab/bench/bench.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/gl/context.h"
#include "bench_command.h"

namespace atonlab::runner {

void add_bench_command(CLI::App& app, BenchCommandOptions& o) {
    CLI::App* cmd = app.add_subcommand("bench", "Measure run time against error for every quality knob (docs/bench.md)");
    cmd->add_flag("--quick", o.quick, "A reduced set that runs in seconds (what the test suite runs)");
    cmd->add_option("--out", o.out_dir, "Directory for bench.csv, bench.md, scaling.csv, pareto.png, scaling.png")
        ->required();
    cmd->add_option("--only", o.only, fmt::format("Run only these benches: {}", fmt::join(bench::bench_names(), ", ")));
    cmd->add_option("--device-label", o.device_label,
                    "Name the machine in the results (default: the GL renderer string)");
    cmd->add_flag("--no-plots", o.no_plots, "Do not run gnuplot");
    cmd->add_flag("-q,--quiet", o.quiet, "No progress lines");
}

int run_bench(const BenchCommandOptions& o) {
    bench::BenchOptions options;
    options.quick = o.quick;
    options.out_dir = o.out_dir;
    options.only = o.only;
    options.device_label = o.device_label;
    options.plots = !o.no_plots;
    options.verbose = !o.quiet;
    // Bad names are bad input before any GL work (run_bench checks them again).
    const std::vector<std::string> names = bench::bench_names();
    for (const std::string& n : o.only)
        if (std::find(names.begin(), names.end(), n) == names.end())
            throw InputError(SourceLocation{"", 0, 0, "--only"},
                             fmt::format("there is no bench \"{}\"; the benches are {}.", n, fmt::join(names, ", ")));
    auto context = gl::create_headless_context();
    const gl::ContextInfo& info = context->info();
    if (options.verbose)
        std::printf("atonlab bench on %s (%s, %s)\n", info.renderer.c_str(), info.version.c_str(),
                    info.platform.c_str());
    const bench::BenchSummary s = bench::run_bench(options, info);
    std::printf("%d settings measured; wrote", s.rows);
    for (const std::string& f : s.files) std::printf(" %s", f.c_str());
    std::printf("\n");
    if (options.plots && !s.plotted) std::printf("no plots: gnuplot is not installed (Debian package gnuplot-nox)\n");
    for (const std::string& d : s.off_front) std::printf("default not on its Pareto front: %s\n", d.c_str());
    return 0;
}

}  // namespace atonlab::runner
