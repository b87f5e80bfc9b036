// A simulation run as a Slurm job array (cluster_jobs.h; docs/simulate-cluster.md).
#include "simulate/cluster_jobs.h"

#include <fcntl.h>
#include <fmt/chrono.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "atonlab/common/atomic_file.h"
#include "atonlab/common/input_error.h"
#include "atonlab/common/read_file.h"
#include "simulate/cluster_tasks.h"
#include "simulate/simulation_folder.h"

extern char** environ;

namespace atonlab::runner {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

fs::path script_path(const fs::path& dir) {
    return dir / "simulate.sbatch";
}
fs::path jobs_path(const fs::path& dir) {
    return dir / "slurm" / "jobs.json";
}

bool on_path(const std::string& program) {
    const char* path = std::getenv("PATH");
    if (path == nullptr) return false;
    std::string entries = path;
    for (std::size_t start = 0; start <= entries.size();) {
        const std::size_t end = std::min(entries.find(':', start), entries.size());
        const fs::path candidate = fs::path(start == end ? "." : entries.substr(start, end - start)) / program;
        if (::access(candidate.c_str(), X_OK) == 0) return true;
        start = end + 1;
    }
    return false;
}

struct ProgramOutput {
    int status = -1;     ///< the exit status; -1 when it could not be started
    std::string output;  ///< stdout and stderr together
};

/// Runs `argv` (argv[0] found on PATH) and waits for it.
ProgramOutput run_program(const std::vector<std::string>& argv) {
    ProgramOutput out;
    int pipe_fds[2];
    if (::pipe(pipe_fds) != 0) return out;
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 1);
    posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 2);
    posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);
    pid_t pid = 0;
    const int rc = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(pipe_fds[1]);
    if (rc == 0) {
        char buffer[4096];
        for (ssize_t n; (n = ::read(pipe_fds[0], buffer, sizeof buffer)) > 0;) out.output.append(buffer, n);
        int wstatus = 0;
        ::waitpid(pid, &wstatus, 0);
        out.status = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 128 + WTERMSIG(wstatus);
    }
    ::close(pipe_fds[0]);
    while (!out.output.empty() && out.output.back() == '\n') out.output.pop_back();
    return out;
}

std::string utc_now() {
    return fmt::format("{:%Y-%m-%dT%H:%M:%SZ}",
                       std::chrono::floor<std::chrono::seconds>(std::chrono::system_clock::now()));
}

void write_jobs(const fs::path& dir, const SlurmJobs& s) {
    Json j;
    j["sessions"] = s.sessions;
    j["designs"] = s.designs;
    j["sessions_per_task"] = s.sessions_per_task;
    j["tasks"] = s.tasks;
    j["jobs"] = Json::array();
    for (const SlurmJobs::Job& job : s.jobs)
        j["jobs"].push_back(Json{{"id", job.id}, {"array", job.array}, {"submitted_utc", job.submitted_utc}});
    fs::create_directories(jobs_path(dir).parent_path());
    files::write_file_atomically(jobs_path(dir), j.dump(2) + "\n");
}

std::optional<SlurmJobs> read_jobs(const fs::path& dir) {
    std::error_code ec;
    if (!fs::exists(jobs_path(dir), ec)) return std::nullopt;
    try {
        const Json j = Json::parse(files::read_text(jobs_path(dir), "Slurm jobs"));
        SlurmJobs s;
        s.sessions = j.at("sessions").get<std::size_t>();
        s.designs = j.at("designs").get<std::size_t>();
        s.sessions_per_task = j.at("sessions_per_task").get<std::size_t>();
        s.tasks = j.at("tasks").get<std::size_t>();
        for (const Json& job : j.at("jobs"))
            s.jobs.push_back(SlurmJobs::Job{job.at("id").get<std::string>(), job.at("array").get<std::string>(),
                                            job.value("submitted_utc", "")});
        if (s.sessions_per_task == 0) throw std::runtime_error("sessions_per_task is 0");
        return s;
    } catch (const std::exception& e) {
        throw InputError(
            SourceLocation{jobs_path(dir).string(), 0, 0, ""},
            fmt::format("{} is not a job record this atonlab reads ({}).", jobs_path(dir).string(), e.what()));
    }
}

std::vector<std::string> job_ids(const SlurmJobs& s) {
    std::vector<std::string> ids;
    for (const SlurmJobs::Job& j : s.jobs) ids.push_back(j.id);
    return ids;
}

/// The array tasks squeue shows queued or running: task id → state. Throws
/// InputError naming `option` where squeue is missing or fails.
std::map<std::size_t, std::string> queued_tasks(const SlurmJobs& s, const std::string& option) {
    const ProgramOutput q = run_program({"squeue", "-h", "-r", "-o", "%F %K %T"});
    if (q.status != 0)
        throw InputError(SourceLocation::command_line(option),
                         q.status < 0 ? std::string("squeue is not on PATH: Slurm's client commands are needed "
                                                    "to see the job's tasks.")
                                      : fmt::format("squeue failed (exit {}): {}", q.status, q.output));
    return live_tasks(q.output, job_ids(s));
}

bool task_done(const fs::path& dir, const SlurmJobs& s, std::size_t task) {
    const TaskShare share = task_shares(s.sessions, s.sessions_per_task).at(task);
    std::error_code ec;
    for (std::size_t d = 0; d < s.designs; ++d)
        for (std::size_t i = share.first; i < share.first + share.count; ++i)
            if (!fs::exists(analysis::simulation_session_file(dir, d, i), ec)) return false;
    return true;
}

/// Whether some job of this folder left an output file for `task` (it started).
bool task_started(const fs::path& dir, const SlurmJobs& s, std::size_t task) {
    std::error_code ec;
    for (const SlurmJobs::Job& j : s.jobs)
        if (fs::exists(dir / "slurm" / fmt::format("task-{}_{}.out", j.id, task), ec)) return true;
    return false;
}

struct TaskStates {
    std::vector<std::size_t> done, running, pending, failed, missing;
    std::map<std::size_t, std::string> accounted;  ///< sacct's last state, where accounting exists
};

TaskStates task_states(const fs::path& dir, const SlurmJobs& s, const std::string& option) {
    TaskStates out;
    const std::map<std::size_t, std::string> queued = queued_tasks(s, option);
    const ProgramOutput acct = run_program(
        {"sacct", "-n", "-P", "-X", "-o", "JobID,State", "-j", fmt::format("{}", fmt::join(job_ids(s), ","))});
    if (acct.status == 0) out.accounted = accounted_tasks(acct.output, job_ids(s));
    for (std::size_t t = 0; t < s.tasks; ++t) {
        const auto q = queued.find(t);
        if (task_done(dir, s, t))
            out.done.push_back(t);
        else if (q != queued.end())
            (q->second == "PENDING" ? out.pending : out.running).push_back(t);
        else if (task_started(dir, s, t) || out.accounted.count(t) > 0)
            out.failed.push_back(t);
        else
            out.missing.push_back(t);
    }
    return out;
}

std::string listed(const std::vector<std::size_t>& tasks) {
    return tasks.empty() ? std::string() : ": " + array_spec(tasks);
}

/// Submits DIR/simulate.sbatch (the array of `array`, or the script's own where empty); returns the job id.
std::optional<std::string> sbatch(const fs::path& dir, const std::string& array) {
    std::vector<std::string> argv{"sbatch", "--parsable"};
    if (!array.empty()) argv.push_back("--array=" + array);
    argv.push_back(script_path(dir).string());
    const ProgramOutput r = run_program(argv);
    std::string id =
        r.output.substr(r.output.find_last_of('\n') == std::string::npos ? 0 : r.output.find_last_of('\n') + 1);
    id = id.substr(0, id.find(';'));  // --parsable: "JOBID" or "JOBID;CLUSTER"
    if (r.status != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos) {
        std::fprintf(stderr, "atonlab: sbatch refused %s (exit %d): %s\n", script_path(dir).c_str(), r.status,
                     r.output.c_str());
        return std::nullopt;
    }
    return id;
}

std::string script_text(const SimulateOptions& o, std::uint64_t seed, const SlurmJobs& s) {
    const fs::path dir = fs::absolute(o.out);
    // One line per protocol and per option with its value.
    std::string words;
    const std::vector<std::string> command = task_command(o, seed, "");
    for (std::size_t i = 0; i < command.size(); ++i) {
        const bool value = i > 0 && command[i - 1].rfind("--", 0) == 0 && command[i].rfind("--", 0) != 0;
        words += (i == 0 ? "" : value || i == 1 ? " " : " \\\n  ") + shell_quote(command[i]);
    }
    std::string sbatch_lines = fmt::format(
        "#SBATCH --job-name=atonlab-simulate\n#SBATCH --array=0-{}\n"
        "#SBATCH --output={}\n#SBATCH --cpus-per-task={}\n",
        s.tasks - 1, (dir / "slurm" / "task-%A_%a.out").string(), o.cpus_per_task);
    if (!o.partition.empty()) sbatch_lines += "#SBATCH --partition=" + o.partition + "\n";
    if (!o.time.empty()) sbatch_lines += "#SBATCH --time=" + o.time + "\n";
    for (const std::string& a : o.sbatch_args) sbatch_lines += "#SBATCH " + a + "\n";
    return fmt::format(
        "#!/bin/bash\n"
        "# `atonlab simulate` as a Slurm job array (docs/simulate-cluster.md), written {} by\n"
        "# atonlab {} --slurm. Array task t runs session indices [t*{}, t*{} + {}) of each of the\n"
        "# {} design(s), {} sessions per design in all; each session is written to its own file\n"
        "# under {}/sessions/ (a .partial name until it is complete), so tasks never share a file.\n"
        "# The decision tables were built before submission; a task never builds one.\n"
        "#   see the tasks:        atonlab simulate --status {}\n"
        "#   run the failed ones:  atonlab simulate --resubmit {}\n"
        "#   merge the results:    atonlab analyze {} --out REPORT_DIR\n"
        "{}"
        "set -euo pipefail\n"
        "per_task={}  # sessions per task (--sessions-per-task)\n"
        "sessions={}  # sessions per design (--sessions)\n"
        "first=$(( SLURM_ARRAY_TASK_ID * per_task ))\n"
        "count=$(( sessions - first < per_task ? sessions - first : per_task ))\n"
        "echo \"atonlab simulate: task $SLURM_ARRAY_TASK_ID on $(hostname): sessions $first to $(( first + count - 1 "
        "))\"\n"
        "# exec: atonlab itself receives scancel's and the time limit's SIGTERM, and keeps the sessions it\n"
        "# finished (a shell in between would die first, and Slurm then kills what is left of the task).\n"
        "exec {} \\\n  --jobs \"${{SLURM_CPUS_PER_TASK:-1}}\" --first \"$first\" --count \"$count\" --quiet\n",
        utc_now(), ATONLAB_VERSION, s.sessions_per_task, s.sessions_per_task, s.sessions_per_task, s.designs,
        s.sessions, dir.string(), shell_quote(dir.string()), shell_quote(dir.string()), shell_quote(dir.string()),
        sbatch_lines, s.sessions_per_task, s.sessions, words);
}

}  // namespace

std::vector<std::string> task_command(const SimulateOptions& o, std::uint64_t seed, const std::string& jobs) {
    std::vector<std::string> w{fs::read_symlink("/proc/self/exe").string(), "simulate"};
    for (const std::string& p : o.protocols) w.push_back(fs::absolute(p).string());
    auto add = [&](const std::string& option, const std::string& value) {
        w.push_back(option);
        w.push_back(value);
    };
    add("--sessions", fmt::format("{}", o.sessions));
    add("--out", fs::absolute(o.out).string());
    add("--seed", fmt::format("{}", seed));
    for (const std::string& s : o.sets) add("--set", s);
    for (const std::string& s : o.observer) add("--observer", s);
    for (const std::string& s : o.vary) add("--vary", s);
    add("--table-bound", fmt::format("{}", o.table_bound));
    if (!o.table_cache.empty()) add("--table-cache", fs::absolute(o.table_cache).string());
    if (o.render_every_trial) w.push_back("--render-every-trial");
    if (!jobs.empty()) add("--jobs", jobs);
    return w;
}

std::size_t check_cluster_options(const SimulateOptions& o) {
    auto refuse = [](const std::string& option, const std::string& why) {
        throw InputError(SourceLocation::command_line(option), why);
    };
    if (o.first && (o.slurm || o.print_commands))
        refuse("--first",
               "--first runs one share of the sessions; --slurm and --print-commands cut all of them "
               "into shares: give one or the other.");
    if (o.slurm && o.print_commands)
        refuse("--print-commands",
               "--print-commands prints the tasks' commands instead of submitting them: give "
               "--slurm or --print-commands, not both.");
    if (!o.slurm) {
        for (const auto& [option, given] :
             {std::pair{"--partition", !o.partition.empty()}, std::pair{"--time", !o.time.empty()},
              std::pair{"--sbatch-arg", !o.sbatch_args.empty()}})
            if (given) refuse(option, fmt::format("{} is sbatch's: it needs --slurm.", option));
    }
    if (!o.time.empty())
        if (const std::string why = slurm_time_problem(o.time); !why.empty()) refuse("--time", "--time " + why + ".");
    if (!o.partition.empty() && o.partition.find_first_of(" \t\n'\"\\$`") != std::string::npos)
        refuse("--partition",
               fmt::format("--partition '{}' is not a partition name (it holds a space or a quote).", o.partition));
    for (const std::string& a : o.sbatch_args)
        if (a.empty() || a.front() != '-' || a.find('\n') != std::string::npos)
            refuse("--sbatch-arg", fmt::format("--sbatch-arg '{}' is not an sbatch option: give one option a time, "
                                               "e.g. --sbatch-arg=--mem=4G.",
                                               a));
    if (o.cpus_per_task < 1) refuse("--cpus-per-task", "--cpus-per-task must be at least 1.");
    std::size_t max_array = default_max_array_size;
    if (o.slurm) {
        for (const char* tool : {"sbatch", "squeue"})
            if (!on_path(tool))
                refuse("--slurm", fmt::format("{} is not on PATH: --slurm submits with Slurm's sbatch and watches "
                                              "with squeue (run it on the cluster's login node, or use "
                                              "--print-commands). Nothing was written.",
                                              tool));
        if (const std::optional<SlurmJobs> s = read_jobs(o.out))
            if (const auto queued = queued_tasks(*s, "--slurm"); !queued.empty())
                refuse("--slurm", fmt::format("{} has a job still queued or running (job {}, {} task(s)): wait for "
                                              "it or scancel it; see `atonlab simulate --status {}`.",
                                              o.out, s->jobs.back().id, queued.size(), o.out));
        if (const ProgramOutput c = run_program({"scontrol", "show", "config"}); c.status == 0)
            max_array = parse_max_array_size(c.output).value_or(default_max_array_size);
    }
    const std::size_t per_task =
        o.sessions_per_task > 0 ? o.sessions_per_task : default_sessions_per_task(o.sessions, max_array);
    const std::size_t tasks = task_shares(o.sessions, per_task).size();
    if (o.slurm && tasks > max_array)
        refuse("--sessions-per-task",
               fmt::format("--sessions-per-task {} makes {} array tasks, more than this cluster's MaxArraySize {} "
                           "allows: give at least {}.",
                           per_task, tasks, max_array, (o.sessions + max_array - 1) / max_array));
    return per_task;
}

void print_task_commands(const SimulateOptions& o, std::uint64_t seed, std::size_t per_task) {
    std::string words;
    for (const std::string& w : task_command(o, seed, fmt::format("{}", o.cpus_per_task)))
        words += (words.empty() ? "" : " ") + shell_quote(w);
    for (const TaskShare& share : task_shares(o.sessions, per_task))
        std::printf("%s --first %zu --count %zu --quiet\n", words.c_str(), share.first, share.count);
}

int submit_slurm_array(const SimulateOptions& o, std::uint64_t seed, std::size_t designs, std::size_t per_task) {
    const fs::path dir = o.out;
    SlurmJobs s;
    if (const std::optional<SlurmJobs> before = read_jobs(dir)) s.jobs = before->jobs;  // a new sweep; the old ids kept
    s.sessions = o.sessions;
    s.designs = designs;
    s.sessions_per_task = per_task;
    s.tasks = task_shares(o.sessions, per_task).size();
    fs::create_directories(dir / "slurm");
    files::write_file_atomically(script_path(dir), script_text(o, seed, s));
    const std::optional<std::string> id = sbatch(dir, "");
    if (!id) return 2;
    s.jobs.push_back(SlurmJobs::Job{*id, fmt::format("0-{}", s.tasks - 1), utc_now()});
    write_jobs(dir, s);
    std::printf(
        "simulate: submitted job %s: %zu array task(s) of %zu session(s) × %zu design(s) (%s); "
        "see them with: atonlab simulate --status %s\n",
        id->c_str(), s.tasks, per_task, designs, script_path(dir).c_str(), dir.c_str());
    return 0;
}

int print_slurm_status(const fs::path& dir) {
    const std::optional<SlurmJobs> s = read_jobs(dir);
    if (!s)
        throw InputError(SourceLocation::command_line("--status"),
                         fmt::format("{} has no Slurm job ({} is missing): submit one with `atonlab simulate … "
                                     "--out {} --slurm`.",
                                     dir.string(), jobs_path(dir).string(), dir.string()));
    const TaskStates t = task_states(dir, *s, "--status");
    std::printf("simulate: %s: %zu task(s) of %zu session(s) × %zu design(s); job(s) %s\n", dir.c_str(), s->tasks,
                s->sessions_per_task, s->designs, fmt::format("{}", fmt::join(job_ids(*s), ", ")).c_str());
    std::printf("  done     %zu%s\n  running  %zu%s\n  pending  %zu%s\n  failed   %zu%s\n  missing  %zu%s\n",
                t.done.size(), listed(t.done).c_str(), t.running.size(), listed(t.running).c_str(), t.pending.size(),
                listed(t.pending).c_str(), t.failed.size(), listed(t.failed).c_str(), t.missing.size(),
                listed(t.missing).c_str());
    for (const std::size_t f : t.failed)
        if (const auto a = t.accounted.find(f); a != t.accounted.end())
            std::printf("  task %zu: %s (sacct)\n", f, a->second.c_str());
    if (!t.failed.empty() || !t.missing.empty())
        std::printf("simulate: run the failed and missing tasks again with: atonlab simulate --resubmit %s\n",
                    dir.c_str());
    else if (t.running.empty() && t.pending.empty())
        std::printf("simulate: every task is done; merge with: atonlab analyze %s --out %s\n", dir.c_str(),
                    (dir / "report").c_str());
    return 0;
}

int resubmit_slurm_tasks(const fs::path& dir) {
    std::optional<SlurmJobs> s = read_jobs(dir);
    if (!s)
        throw InputError(
            SourceLocation::command_line("--resubmit"),
            fmt::format("{} has no Slurm job to resubmit ({} is missing).", dir.string(), jobs_path(dir).string()));
    if (!on_path("sbatch"))
        throw InputError(SourceLocation::command_line("--resubmit"),
                         "sbatch is not on PATH: --resubmit submits with Slurm's sbatch. Nothing was written.");
    const TaskStates t = task_states(dir, *s, "--resubmit");
    if (!t.running.empty() || !t.pending.empty())
        throw InputError(SourceLocation::command_line("--resubmit"),
                         fmt::format("{}'s job is still queued or running ({} task(s)): wait for it or scancel it, "
                                     "then resubmit.",
                                     dir.string(), t.running.size() + t.pending.size()));
    std::vector<std::size_t> again = t.failed;
    again.insert(again.end(), t.missing.begin(), t.missing.end());
    std::sort(again.begin(), again.end());
    if (again.empty()) {
        std::printf("simulate: every task of %s is done; nothing to resubmit\n", dir.c_str());
        return 0;
    }
    const std::string spec = array_spec(again);
    const std::optional<std::string> id = sbatch(dir, spec);
    if (!id) return 2;
    s->jobs.push_back(SlurmJobs::Job{*id, spec, utc_now()});
    write_jobs(dir, *s);
    std::printf("simulate: resubmitted %zu task(s) (%s) as job %s\n", again.size(), spec.c_str(), id->c_str());
    return 0;
}

}  // namespace atonlab::runner
