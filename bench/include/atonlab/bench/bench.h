#pragma once
// `atonlab bench`: run time against error for every quality knob of the
// pipeline (docs/bench.md). Each bench varies one knob, times it (median of
// repeated runs after a warm-up, IQR and min–max reported; GL timer queries
// for GPU stages) and measures its error against a reference computed at the
// highest quality in double precision, in units that matter: relative L2 of
// the PSF, display code values after tone mapping, a light's energy in %.
// Results: bench.csv, bench.md, scaling.csv, pareto.png, scaling.png, machine.txt.
#include <string>
#include <vector>

#include "atonlab/stimuli/gl/context.h"

namespace atonlab::bench {

struct BenchOptions {
    bool quick = false;              ///< a reduced set that runs in seconds (the test suite's form)
    std::string out_dir;             ///< created if missing
    std::vector<std::string> only;   ///< bench names to run (bench_names()); empty: all
    std::string device_label;        ///< names the machine in the results; empty: the GL renderer string
    bool plots = true;               ///< write the gnuplot plots (when gnuplot is installed)
    bool verbose = true;             ///< one progress line per measurement on stdout
};

/// The benches, in the order they run.
std::vector<std::string> bench_names();

struct BenchSummary {
    int rows = 0;                            ///< knob settings measured
    std::vector<std::string> off_front;      ///< "bench: setting" of defaults not on their Pareto front
    std::vector<std::string> files;          ///< what was written
    bool plotted = false;                    ///< gnuplot ran
};

/// Runs the benches with the current GL 4.5 context (context: what it is, for
/// the machine description). Throws InputError for an unknown bench name or an
/// output directory that cannot be written.
BenchSummary run_bench(const BenchOptions& options, const gl::ContextInfo& context);

}  // namespace atonlab::bench
