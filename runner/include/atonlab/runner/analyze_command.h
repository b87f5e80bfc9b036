#pragma once
// `atonlab analyze` (docs/analysis.md): study files to a report folder.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace atonlab::runner {

/// `atonlab analyze` (docs/analysis.md). Exit status: 0 done, 2 bad input, 4 a
/// study file could not be read, 5 the report was written without some figures.
struct AnalyzeOptions {
    std::vector<std::string> studies;  ///< study files, opened read-only
    std::vector<std::string> csv;      ///< long-format CSVs of trials (--csv)
    std::string out;                   ///< output folder
    std::optional<int> bootstrap;      ///< resamples per fit (default 999)
    std::optional<std::uint64_t> seed;
    std::string family;                ///< normal, logistic, weibull, gumbel (default normal)
    int last_reversals = 6;
    std::optional<int> threads;
    std::string gnuplot = "gnuplot";
    bool quiet = false;
    bool salvage = false;  ///< read what is left of a damaged study file instead of refusing it
    // A simulation folder (analysis/simulation.h; docs/analysis.md "The simulation report"):
    std::string intervals;  ///< "profile" (default) or "bootstrap"
    std::optional<double> effect;  ///< --effect D, log10 units: the power to detect it
    std::string effect_between;    ///< --effect-between A,B; empty: each glare condition's enhancement
};

void add_analyze_command(CLI::App& app, AnalyzeOptions& options);
/// Creates `out` (the report folder) if absent; false, with one sentence on
/// stderr, when it cannot be made (the caller exits 2).
bool make_output_folder(const std::string& out);
int run_analyze(const AnalyzeOptions& options);
/// `atonlab analyze DIR` for a simulation folder (analyze_simulation.cpp).
int run_analyze_simulation(const AnalyzeOptions& options);

}  // namespace atonlab::runner
