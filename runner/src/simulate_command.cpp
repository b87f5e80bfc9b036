// `atonlab simulate` (simulate_command.h; docs/simulate.md): designs read and
// checked, the folder checked, decision tables loaded or built, then the
// sessions still missing run on a pool of worker threads.
#include "simulate_command.h"

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "atonlab/common/atomic_file.h"
#include "atonlab/common/input_error.h"
#include "atonlab/runner/analyze_command.h"
#include "atonlab/runner/session/run_session.h"
#include "atonlab/runner/session/stop_signals.h"
#include "atonlab/stimuli/gl/context.h"
#include "atonlab/store/error.h"
#include "atonlab/store/sha256.h"
#include "atonlab/store/store.h"
#include "session/progress.h"
#include "simulate/cluster_jobs.h"
#include "simulate/simulation_designs.h"
#include "simulate/simulation_folder.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace fs = std::filesystem;

namespace {

struct Pending {
    const SimulationDesign* design;
    std::size_t index;
    fs::path file;
};

analysis::SimulationManifest manifest_of(const std::vector<SimulationDesign>& designs, const SimulateOptions& o,
                               std::uint64_t seed) {
    analysis::SimulationManifest m;
    for (const SimulationDesign& d : designs)
        m.designs.push_back(analysis::ManifestDesign{d.label, d.protocol_path, store::sha256_hex(d.protocol_text), d.overrides,
                                           o.render_every_trial ? std::string() : d.table_key});
    m.seed = seed;
    m.sessions = o.sessions;
    nlohmann::ordered_json observer;
    for (const auto& [key, value] : p::observer_values(designs.front().observer)) observer[key] = value;
    m.observer_json = observer.dump();
    m.decisions = o.render_every_trial ? "rendered" : "table";
    m.software_version = ATONLAB_VERSION;
    return m;
}

/// Sessions done, per second, and the time left, on stderr: one line rewritten.
void print_progress(std::size_t done, std::size_t total, std::size_t before, double seconds, bool last) {
    const double rate = seconds > 0 ? static_cast<double>(done) / seconds : 0.0;
    const double left = rate > 0 ? static_cast<double>(total - done) / rate : 0.0;
    std::fprintf(stderr, "\rsimulate: %zu of %zu sessions (%zu done before), %.1f sessions/s, %s left   %s",
                 done + before, total + before, before, rate, clock_text(left).c_str(), last ? "\n" : "");
    std::fflush(stderr);
}

/// Runs the pending sessions from the decision tables on `jobs` threads.
/// Returns the trials stored; rethrows the first worker's error.
std::size_t run_from_tables(const std::vector<Pending>& todo, std::uint64_t seed, std::size_t jobs, bool quiet,
                            std::size_t before, const fs::path& dir) {
    SessionCommitter committer(dir);
    std::atomic<std::size_t> next{0}, done{0}, trials{0};
    std::exception_ptr error;
    std::mutex error_mutex;
    auto work = [&] {
        while (stop_signal() == 0) {
            const std::size_t k = next++;
            if (k >= todo.size()) return;
            try {
                trials += simulate_session(*todo[k].design, todo[k].index, seed + todo[k].index, todo[k].file);
                committer.add(todo[k].file);
                ++done;
            } catch (...) {
                const std::lock_guard<std::mutex> lock(error_mutex);
                if (!error) error = std::current_exception();
                request_stop(SIGTERM);
                return;
            }
        }
    };
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> workers;
    for (std::size_t j = 0; j < std::min(jobs, todo.size()); ++j) workers.emplace_back(work);
    while (done + (error ? 1 : 0) < todo.size() && stop_signal() == 0) {
        std::this_thread::sleep_for(std::chrono::milliseconds(250));
        if (!quiet) print_progress(done, todo.size(), before, seconds_since(start), false);
    }
    for (std::thread& w : workers) w.join();
    committer.flush();  // the sessions finished before a signal or an error are kept
    if (error) std::rethrow_exception(error);
    if (!quiet) print_progress(done, todo.size(), before, seconds_since(start), true);
    return trials;
}

/// Runs the pending sessions one by one through `atonlab run`'s engine,
/// every trial rendered (the reference the tables are tested against).
std::size_t run_rendered(const std::vector<Pending>& todo, std::uint64_t seed, bool quiet, std::size_t before) {
    const std::unique_ptr<gl::Context> context = gl::create_headless_context();
    const auto start = std::chrono::steady_clock::now();
    std::size_t trials = 0;
    for (std::size_t k = 0; k < todo.size() && stop_signal() == 0; ++k) {
        const Pending& s = todo[k];
        remove_partial(s.file);
        RunOptions ro;
        ro.protocol = s.design->protocol_path;
        ro.protocol_text = s.design->protocol_text;
        ro.db = partial_path(s.file).string();
        ro.model_observer = true;
        ro.observer = simulated_observer_code(s.design->index, s.index);
        ro.headless = true;
        ro.seed = seed + s.index;
        ro.quiet = true;
        ro.true_pse = false;
        ro.no_profiles = true;
        ro.gl_context_current = true;
        ro.model_params = s.design->observer.model;
        ro.simulation_json = simulation_json(*s.design, s.index, seed + s.index, "rendered");
        const int status = run_session(ro);
        if (status != 0) return trials;  // a signal: the session stays .partial and is run again next time
        trials += store::Store::open_read_only(ro.db).trial_count(store::SessionId{1});
        fs::rename(ro.db, s.file);
        if (!quiet) print_progress(k + 1, todo.size(), before, seconds_since(start), k + 1 == todo.size());
    }
    return trials;
}

/// --first I --count K: a share inside a simulation set up before (its
/// manifest written), within its sessions.
void check_share(const SimulateOptions& o, const std::optional<analysis::SimulationManifest>& existing) {
    if (!existing)
        throw InputError(SourceLocation::command_line("--first"),
                         fmt::format("{} holds no simulation.json: a share of the sessions (--first) runs inside a "
                                     "simulation set up before; run the command without --first and --count, or "
                                     "with --slurm or --print-commands, first.",
                                     o.out));
    if (o.sessions > existing->sessions)
        throw InputError(SourceLocation::command_line("--sessions"),
                         fmt::format("--sessions {} is more than the {} of {}'s simulation.json: a share (--first) "
                                     "never changes the manifest; extend the simulation without --first first.",
                                     o.sessions, existing->sessions, o.out));
    if (*o.first >= o.sessions || o.count.value_or(0) < 1)
        throw InputError(SourceLocation::command_line("--first"),
                         fmt::format("--first {} --count {} holds no session of the {} per design (indices 0 to {}).",
                                     *o.first, o.count.value_or(0), o.sessions, o.sessions - 1));
}

/// --status DIR and --resubmit DIR.
int run_folder_command(const SimulateOptions& o) {
    if (!o.status_dir.empty() && !o.resubmit_dir.empty())
        throw InputError(SourceLocation::command_line("--status"), "give --status or --resubmit, not both.");
    const std::string option = o.status_dir.empty() ? "--resubmit" : "--status";
    if (!o.protocols.empty() || !o.out.empty() || o.slurm || o.print_commands)
        throw InputError(SourceLocation::command_line(option),
                         fmt::format("{} DIR takes the folder alone: its job's script and record are in it.", option));
    return o.status_dir.empty() ? resubmit_slurm_tasks(o.resubmit_dir) : print_slurm_status(o.status_dir);
}

}  // namespace

void add_simulate_command(CLI::App& app, SimulateOptions& o) {
    auto* cmd = app.add_subcommand(
        "simulate",
        "Plan a study: run a protocol N times with simulated observers, one study file per session "
        "(docs/simulate.md); then `atonlab analyze DIR`");
    cmd->add_option("protocols", o.protocols, "Protocol file(s); several are compared side by side");
    cmd->add_option("--sessions", o.sessions, "Sessions per design (N >= 1)");
    cmd->add_option("--out", o.out, "The simulation's folder (created; a run into it again continues it)");
    cmd->add_option("--seed", o.seed, "Session i has seed S + i (default: the first protocol's seed)");
    cmd->add_option("--jobs", o.jobs, "Worker threads (default: every core)");
    cmd->add_option("--set", o.sets,
                    "A protocol key for every design, KEY=VALUE (e.g. display.width_px=2560; a bare key is "
                    "[defaults.procedure]'s)");
    cmd->add_option("--observer", o.observer,
                    "An observer key over the protocol's [observer] table, KEY=VALUE (e.g. eta=0.2, lapse_rate=0.02)");
    cmd->add_option("--vary", o.vary,
                    "A design per value: KEY=v1,v2,... (e.g. max_trials=20,40,80); several --vary: every combination");
    cmd->add_flag("--render-every-trial", o.render_every_trial,
                  "Render every trial (the model observer itself) instead of the decision table");
    cmd->add_option("--table-bound", o.table_bound,
                    "The decision table's interpolation error bound, log10 brightness (default 0.001)");
    cmd->add_option("--table-cache", o.table_cache,
                    "A folder of decision tables shared between simulations (default DIR/tables)");
    cmd->add_flag("--quiet", o.quiet, "Print nothing but errors");
    cmd->add_flag("--report", o.report,
                  "Then write the simulation report into DIR/report (atonlab analyze DIR --out DIR/report)");
    cmd->add_option("--effect", o.effect,
                    "With --report: the effect (log10 units) whose power to be detected the report gives");
    // A share of the sessions, and a cluster (docs/simulate-cluster.md).
    auto* first = cmd->add_option("--first", o.first,
                                  "Run session indices [I, I + K) of every design only (a task's share; the folder's "
                                  "manifest and tables must be there already)");
    cmd->add_option("--count", o.count, "K, the sessions of --first's share")->needs(first);
    first->needs("--count");
    cmd->add_flag("--slurm", o.slurm,
                  "Build the tables here, then submit the sessions as a Slurm job array (DIR/simulate.sbatch)");
    cmd->add_flag("--print-commands", o.print_commands,
                  "Build the tables here, then print one command per task (for GNU parallel) instead of running");
    cmd->add_option("--partition", o.partition, "--slurm: the partition (sbatch --partition)");
    cmd->add_option("--time", o.time, "--slurm: each task's time limit (MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS)");
    cmd->add_option("--cpus-per-task", o.cpus_per_task, "--slurm, --print-commands: a task's cores and worker threads "
                                                        "(default 1)");
    cmd->add_option("--sessions-per-task", o.sessions_per_task,
                    "--slurm, --print-commands: sessions of each design a task runs (default: at least 100, and "
                    "few enough tasks for the cluster's MaxArraySize)");
    cmd->add_option("--sbatch-arg", o.sbatch_args, "--slurm: an sbatch option written into the script, e.g. "
                                                   "--sbatch-arg=--mem=2G (repeatable)");
    cmd->add_option("--status", o.status_dir, "Show the tasks of DIR's Slurm job: done, running, failed, missing");
    cmd->add_option("--resubmit", o.resubmit_dir, "Submit DIR's failed and missing Slurm tasks again");
}

int run_simulate(const SimulateOptions& o) {
    if (!o.status_dir.empty() || !o.resubmit_dir.empty()) return run_folder_command(o);
    StopSignals signals;
    if (o.protocols.empty())
        throw InputError(SourceLocation::command_line("protocols"), "give the protocol file(s) to simulate.");
    if (o.out.empty()) throw InputError(SourceLocation::command_line("--out"), "--out DIR is needed.");
    if (o.sessions < 1)
        throw InputError(SourceLocation::command_line("--sessions"), "--sessions must be at least 1.");
    if (o.effect && !o.report)
        throw InputError(SourceLocation::command_line("--effect"), "--effect is the report's: give --report too.");
    const std::size_t per_task = check_cluster_options(o);  // before anything is made or written
    if (!(o.table_bound > 0.0 && o.table_bound <= 0.1))
        throw InputError(SourceLocation::command_line("--table-bound"),
                         fmt::format("--table-bound must be in (0, 0.1] log10 brightness, not {}.", o.table_bound));
    std::vector<SimulationDesign> designs = read_designs(o);
    if (o.render_every_trial)
        for (const SimulationDesign& d : designs)
            if (d.observer.departures != p::ObserverDepartures{})
                throw InputError(SourceLocation::command_line("--render-every-trial"),
                                 "--render-every-trial answers with the model observer itself; a bias, eta, "
                                 "learning or fluctuation needs the decision table (leave --render-every-trial out).");
    const fs::path dir = o.out;
    check_writable(dir);
    const std::optional<analysis::SimulationManifest> existing = read_manifest(dir);
    if (o.first) check_share(o, existing);
    const std::uint64_t seed = o.seed.value_or(designs.front().protocol.seed);
    analysis::SimulationManifest manifest = manifest_of(designs, o, seed);
    if (existing) {
        if (const std::string diff = existing->identity_difference(manifest); !diff.empty())
            throw InputError(SourceLocation::command_line("--out"),
                             fmt::format("{} holds another simulation: {}. Nothing in it was changed; give another "
                                         "--out.",
                                         dir.string(), diff));
        manifest.sessions = std::max(manifest.sessions, existing->sessions);
    }
    // The tables (or, rendering every trial, the true values): renders, once
    // the folder is known to take this simulation.
    const fs::path cache = o.table_cache.empty() ? tables_dir(dir) : fs::path(o.table_cache);
    SimulateOptions table_options = o;
    table_options.quiet = o.quiet || o.print_commands;  // stdout holds the commands only
    if (o.render_every_trial) {
        render_true_values(designs);
    } else if (!prepare_tables(designs, table_options, cache)) {
        return 2;
    }
    // Every check has passed: from here on the folder is written. A share
    // (--first) only reads the manifest and tables: tasks of one array may
    // start at once, and the command that cut them into shares wrote both.
    fs::create_directories(dir);
    if (!o.first) {
        if (!o.render_every_trial) save_tables(designs, cache);
        files::write_file_atomically(analysis::simulation_manifest_path(dir), manifest.json());
    }
    if (o.slurm) return submit_slurm_array(o, seed, designs.size(), per_task);
    if (o.print_commands) {
        print_task_commands(o, seed, per_task);
        return 0;
    }
    const std::size_t lo = o.first.value_or(0);
    const std::size_t hi = o.first ? std::min(o.sessions, lo + o.count.value_or(0)) : o.sessions;
    std::vector<Pending> todo;
    std::size_t before = 0;
    for (const SimulationDesign& d : designs) {
        fs::create_directories(analysis::simulation_session_file(dir, d.index, 0).parent_path());
        for (std::size_t i = lo; i < hi; ++i) {
            const fs::path file = analysis::simulation_session_file(dir, d.index, i);
            if (fs::exists(file)) {
                ++before;
            } else {
                remove_partial(file);  // a killed run's half-written session: done again
                todo.push_back(Pending{&d, i, file});
            }
        }
    }
    const std::size_t jobs = o.jobs > 0 ? o.jobs : std::max(1u, std::thread::hardware_concurrency());
    if (!o.quiet)
        std::printf("simulate: %zu design(s) × %zu sessions into %s: %zu to run, %zu done before; %s\n",
                    designs.size(), o.sessions, dir.string().c_str(), todo.size(), before,
                    o.render_every_trial ? "every trial rendered" : fmt::format("{} worker(s)", jobs).c_str());
    const auto start = std::chrono::steady_clock::now();
    std::size_t trials = 0;
    try {
        trials = o.render_every_trial ? run_rendered(todo, seed, o.quiet, before)
                                      : run_from_tables(todo, seed, jobs, o.quiet, before, dir);
    } catch (const store::StoreError& e) {
        std::fprintf(stderr, "atonlab: %s; the sessions finished before it are kept: run again to continue\n",
                     e.what());
        return 4;
    }
    const int stop = stop_signal();
    const double seconds = seconds_since(start);
    if (!o.quiet)
        std::printf("simulate: %s: %zu trials in %s (%.0f trials/s); analyse with: atonlab analyze %s --out %s\n",
                    stop != 0 ? "stopped (run the same command again to continue)" : "done", trials,
                    clock_text(seconds).c_str(), seconds > 0 ? static_cast<double>(trials) / seconds : 0.0,
                    dir.string().c_str(), (dir / "report").string().c_str());
    if (stop != 0) return 128 + stop;
    if (!o.report) return 0;
    AnalyzeOptions report;
    report.studies = {dir.string()};
    report.out = (dir / "report").string();
    report.effect = o.effect;
    report.quiet = o.quiet;
    return run_analyze(report);
}

}  // namespace atonlab::runner
