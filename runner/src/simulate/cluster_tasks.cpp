// How a simulation is cut into tasks for a cluster (cluster_tasks.h).
#include "simulate/cluster_tasks.h"

#include <fmt/format.h>

#include <algorithm>
#include <regex>
#include <sstream>

namespace atonlab::runner {

std::vector<TaskShare> task_shares(std::size_t sessions, std::size_t per_task) {
    std::vector<TaskShare> out;
    if (per_task == 0) return out;
    for (std::size_t first = 0; first < sessions; first += per_task)
        out.push_back(TaskShare{first, std::min(per_task, sessions - first)});
    return out;
}

std::size_t default_sessions_per_task(std::size_t sessions, std::size_t max_array_size) {
    const std::size_t most_tasks = std::max<std::size_t>(1, std::min<std::size_t>(1000, max_array_size));
    const std::size_t fitting = (sessions + most_tasks - 1) / most_tasks;
    return std::max<std::size_t>({1, std::min<std::size_t>(100, sessions), fitting});
}

std::string slurm_time_problem(const std::string& limit) {
    // sbatch(1) --time: "minutes", "minutes:seconds", "hours:minutes:seconds",
    // "days-hours", "days-hours:minutes" and "days-hours:minutes:seconds".
    static const std::regex forms(R"(\d+|\d+:\d{1,2}|\d+:\d{1,2}:\d{1,2}|\d+-\d{1,2}|\d+-\d{1,2}:\d{1,2}|)"
                                  R"(\d+-\d{1,2}:\d{1,2}:\d{1,2})");
    std::string upper = limit;
    std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) { return std::toupper(c); });
    if (upper == "UNLIMITED" || upper == "INFINITE") return {};
    if (!std::regex_match(limit, forms))
        return fmt::format(
            "'{}' is not a Slurm time limit: give MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM or D-HH:MM:SS "
            "(e.g. 90, 1:30:00, 2-12)",
            limit);
    // Seconds and minutes after a colon are below 60 (sbatch reads 1:75:00 as something else than meant).
    static const std::regex after_colon(R"(:(\d+))");
    for (auto it = std::sregex_iterator(limit.begin(), limit.end(), after_colon); it != std::sregex_iterator(); ++it)
        if (std::stoul((*it)[1].str()) >= 60)
            return fmt::format("'{}' is not a Slurm time limit: minutes and seconds after a ':' are below 60", limit);
    if (limit.find('-') != std::string::npos && std::stoul(limit.substr(limit.find('-') + 1, 2)) >= 24)
        return fmt::format("'{}' is not a Slurm time limit: the hours after 'D-' are below 24", limit);
    if (limit.find_first_not_of("0:-") == std::string::npos)
        return fmt::format("'{}' is not a Slurm time limit: it is zero", limit);
    return {};
}

std::optional<std::size_t> parse_max_array_size(const std::string& text) {
    static const std::regex line(R"(^MaxArraySize\s*=\s*(\d+)\s*$)", std::regex::multiline);
    std::smatch m;
    if (!std::regex_search(text, m, line)) return std::nullopt;
    return static_cast<std::size_t>(std::stoull(m[1].str()));
}

std::string array_spec(const std::vector<std::size_t>& tasks) {
    std::string out;
    for (std::size_t i = 0; i < tasks.size();) {
        std::size_t j = i;
        while (j + 1 < tasks.size() && tasks[j + 1] == tasks[j] + 1) ++j;
        if (!out.empty()) out += ',';
        out += j == i ? fmt::format("{}", tasks[i]) : fmt::format("{}-{}", tasks[i], tasks[j]);
        i = j + 1;
    }
    return out;
}

std::map<std::size_t, std::string> live_tasks(const std::string& text, const std::vector<std::string>& job_ids) {
    std::map<std::size_t, std::string> out;
    std::istringstream lines(text);
    std::string job, task, state;
    while (lines >> job >> task >> state)
        if (std::find(job_ids.begin(), job_ids.end(), job) != job_ids.end() &&
            task.find_first_not_of("0123456789") == std::string::npos && !task.empty())
            out[std::stoul(task)] = state;
    return out;
}

std::map<std::size_t, std::string> accounted_tasks(const std::string& text, const std::vector<std::string>& job_ids) {
    std::map<std::size_t, std::string> out;
    static const std::regex line(R"(^(\d+)_(\d+)\|(\S+))");
    for (const std::string& id : job_ids) {  // in submission order: a later job's state wins
        std::istringstream lines(text);
        std::string l;
        std::smatch m;
        while (std::getline(lines, l))
            if (std::regex_search(l, m, line) && m[1].str() == id) out[std::stoul(m[2].str())] = m[3].str();
    }
    return out;
}

std::string shell_quote(const std::string& word) {
    if (!word.empty() && word.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789"
                                                "_-+=./:,@%") == std::string::npos)
        return word;
    std::string out = "'";
    for (char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

}  // namespace atonlab::runner
