#pragma once
// How a simulation is cut into tasks for a cluster (docs/simulate-cluster.md):
// task t runs session indices [t·K, t·K + K) of every design, K sessions per
// task, the last task fewer. Pure functions: no process is started here.
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace atonlab::runner {

/// Session indices [first, first + count) of every design.
struct TaskShare {
    std::size_t first = 0;
    std::size_t count = 0;
};

/// Slurm's own default MaxArraySize (slurm.conf(5)): task ids 0 … 1000.
inline constexpr std::size_t default_max_array_size = 1001;

/// The shares of `sessions` sessions per design, `per_task` each: ⌈sessions / per_task⌉ tasks.
std::vector<TaskShare> task_shares(std::size_t sessions, std::size_t per_task);

/// --sessions-per-task's default: at least 100 sessions a task (a task costs
/// the scheduler seconds to start, 100 sessions of the quick start a core
/// about 0.5 s), more where that would make more tasks than the array may
/// hold, min(1000, max_array_size).
std::size_t default_sessions_per_task(std::size_t sessions, std::size_t max_array_size);

/// "" when `limit` is a time limit sbatch --time accepts (MM, MM:SS, HH:MM:SS,
/// D-HH, D-HH:MM, D-HH:MM:SS, or UNLIMITED/INFINITE), else why not.
std::string slurm_time_problem(const std::string& limit);

/// MaxArraySize from `scontrol show config` output; none when it is not there.
std::optional<std::size_t> parse_max_array_size(const std::string& scontrol_output);

/// sbatch's --array list for the task ids (sorted, unique): "0-4,7,9-10".
std::string array_spec(const std::vector<std::size_t>& tasks);

/// The array tasks of the jobs `job_ids` that `squeue -h -r -o "%F %K %T"`
/// shows (one "JOBID TASKID STATE" per line): task id → state (e.g. RUNNING).
std::map<std::size_t, std::string> live_tasks(const std::string& squeue_output,
                                              const std::vector<std::string>& job_ids);

/// The array tasks' last state from `sacct -n -P -X -o JobID,State` output
/// ("JOBID_TASK|STATE" lines, later jobs of `job_ids` winning): task id → state.
std::map<std::size_t, std::string> accounted_tasks(const std::string& sacct_output,
                                                   const std::vector<std::string>& job_ids);

/// `word` quoted for a POSIX shell where it needs to be ('…', with ' as '\'').
std::string shell_quote(const std::string& word);

}  // namespace atonlab::runner
