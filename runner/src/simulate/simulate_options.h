#pragma once
// The options of `atonlab simulate` (docs/simulate.md).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace atonlab::runner {

/// Exit status: 0 every session done, 2 bad input (nothing written), 3 no GL
/// for a table that is not cached, 4 a session's study file could not be
/// written, 128 + N stopped by signal N (finished sessions kept; run again to continue).
struct SimulateOptions {
    std::vector<std::string> protocols;  ///< one or more protocol files, compared side by side
    std::size_t sessions = 0;            ///< N: sessions per design
    std::string out;                     ///< DIR
    std::optional<std::uint64_t> seed;   ///< S: session i has seed S + i (default: the first protocol's seed)
    std::size_t jobs = 0;                ///< worker threads (0: every core)
    std::vector<std::string> sets;       ///< protocol keys set for every design (KEY=VALUE)
    std::vector<std::string> observer;   ///< observer keys (KEY=VALUE) over the protocol's [observer]
    std::vector<std::string> vary;       ///< KEY=v1,v2,…: one design per value (several: every combination)
    bool render_every_trial = false;     ///< render each trial instead of the decision table
    double table_bound = 0.001;          ///< the decision table's interpolation error bound, log10 brightness
    std::string table_cache;             ///< a folder of tables shared between simulations (default DIR/tables)
    bool quiet = false;
    bool report = false;          ///< --report: `atonlab analyze DIR --out DIR/report` once every session is done
    std::optional<double> effect;  ///< --effect D for the report (log10 units)

    // A share of the sessions and a cluster (docs/simulate-cluster.md).
    std::optional<std::size_t> first;       ///< --first I: run session indices [I, I + count) of every design only
    std::optional<std::size_t> count;       ///< --count K (with --first)
    bool slurm = false;                     ///< submit the sessions as a Slurm job array
    bool print_commands = false;            ///< print one `atonlab simulate … --first I --count K` per task
    std::string partition;                  ///< --partition P (sbatch's)
    std::string time;                       ///< --time T, each task's limit in Slurm's format
    std::size_t cpus_per_task = 1;          ///< --cpus-per-task C: the task's worker threads too
    std::size_t sessions_per_task = 0;      ///< --sessions-per-task K (0: chosen, docs/simulate-cluster.md)
    std::vector<std::string> sbatch_args;   ///< --sbatch-arg ARG: written into the script as #SBATCH ARG
    std::string status_dir;                 ///< --status DIR
    std::string resubmit_dir;               ///< --resubmit DIR
};

}  // namespace atonlab::runner
