#pragma once
// A simulation run as a Slurm job array, and the commands of its tasks
// (docs/simulate-cluster.md). The folder gains:
//
//   DIR/simulate.sbatch          the job array's script (readable; resubmitted as it is)
//   DIR/slurm/jobs.json          the tasks' shares and every job submitted, in order
//   DIR/slurm/task-JOB_TASK.out  each array task's output
//
// Tasks only read DIR/simulation.json and the tables: the submitting command
// writes them before the first task can start.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "simulate/simulate_options.h"

namespace atonlab::runner {

/// What DIR/slurm/jobs.json holds.
struct SlurmJobs {
    std::size_t sessions = 0;  ///< per design
    std::size_t designs = 0;
    std::size_t sessions_per_task = 0;  ///< K
    std::size_t tasks = 0;              ///< ⌈sessions / K⌉
    struct Job {
        std::string id;     ///< sbatch --parsable's job id
        std::string array;  ///< the task ids it ran, sbatch --array's form
        std::string submitted_utc;
    };
    std::vector<Job> jobs;  ///< in the order submitted
};

/// The words of one task's command, less --first and --count: the atonlab
/// binary (/proc/self/exe) and every path absolute, the seed explicit, and
/// `jobs` worker threads ("" leaves --jobs out).
std::vector<std::string> task_command(const SimulateOptions& o, std::uint64_t seed, const std::string& jobs);

/// Refuses (InputError naming `option`) what --slurm, --print-commands and
/// --first cannot do together, a malformed --time, --partition or
/// --sbatch-arg; for --slurm a missing sbatch or squeue, and a folder whose
/// job is still queued or running. Writes nothing. Returns K, the sessions a task runs.
std::size_t check_cluster_options(const SimulateOptions& o);

/// --print-commands: one command per task on stdout.
void print_task_commands(const SimulateOptions& o, std::uint64_t seed, std::size_t per_task);

/// --slurm: writes DIR/simulate.sbatch, submits it and records the job.
/// Returns the exit status (2 where sbatch refused it, its words on stderr).
int submit_slurm_array(const SimulateOptions& o, std::uint64_t seed, std::size_t designs, std::size_t per_task);

/// --status DIR: the tasks done, running, pending, failed and missing.
int print_slurm_status(const std::filesystem::path& dir);

/// --resubmit DIR: an array of the failed and missing tasks only.
int resubmit_slurm_tasks(const std::filesystem::path& dir);

}  // namespace atonlab::runner
