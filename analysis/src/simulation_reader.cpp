// Reading a simulation folder (simulation.h): the manifest, the session files
// under sessions/NN/, and each file's per-condition estimates, on all cores.
// Each file is read whole (read_study: opened read-only and checked by
// SQLite's integrity_check, exactly as `atonlab analyze` reads a study file),
// analysed (analyze_study), reduced to a SessionSummary and dropped, so that
// memory grows with the number of files and not with their trials.
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <map>
#include <thread>

#include "atonlab/analysis/dataset.h"
#include "atonlab/analysis/profile_interval.h"
#include "atonlab/analysis/simulation.h"
#include "atonlab/analysis/study_analysis.h"
#include "atonlab/common/input_error.h"
#include "atonlab/store/error.h"
#include "atonlab/store/json.h"

namespace atonlab::analysis {

namespace fs = std::filesystem;

namespace {

bool ends_with(const std::string& s, std::string_view tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

/// A file found under sessions/: what it is.
struct Found {
    fs::path path;
    int design_index = -1;
    std::string skip;  ///< non-empty: why it is listed and left out without being opened
};

/// Every file under DIR/sessions/, sorted; a session's -wal and -shm belong to it.
std::vector<Found> list_session_files(const fs::path& dir, std::size_t n_designs, std::size_t& files_found) {
    std::vector<Found> out;
    const fs::path sessions = dir / "sessions";
    std::error_code ec;
    if (!fs::is_directory(sessions, ec)) return out;
    std::vector<fs::path> paths;
    for (fs::recursive_directory_iterator it(sessions, ec), end; !ec && it != end; it.increment(ec))
        if (it->is_regular_file(ec)) paths.push_back(it->path());
    std::sort(paths.begin(), paths.end());
    for (const fs::path& p : paths) {
        const std::string name = p.filename().string();
        // A session file's write-ahead log and shared memory are part of it.
        if (ends_with(name, "-wal") || ends_with(name, "-shm") || ends_with(name, "-journal")) continue;
        ++files_found;
        Found f;
        f.path = p;
        const fs::path rel = p.lexically_relative(sessions);
        const std::string folder = rel.has_parent_path() ? rel.parent_path().string() : std::string();
        if (folder.size() == 2 && std::isdigit(static_cast<unsigned char>(folder[0])) &&
            std::isdigit(static_cast<unsigned char>(folder[1])))
            f.design_index = std::stoi(folder);
        if (ends_with(name, ".db.partial"))
            f.skip = "unfinished: the session was still being written, or its writer was stopped (.partial)";
        else if (!ends_with(name, ".db") || name.rfind("session-", 0) != 0)
            f.skip = "not a session file (sessions/NN/session-NNNNNN.db)";
        else if (f.design_index < 0)
            f.skip = "not in a design's folder (sessions/NN/)";
        else if (static_cast<std::size_t>(f.design_index) >= n_designs)
            f.skip = fmt::format("design {} is not in simulation.json, which names {}", f.design_index, n_designs);
        out.push_back(std::move(f));
    }
    return out;
}

/// The session's estimate of one condition, and its interval by `options.intervals`.
SessionEstimate estimate_of(const ConditionInfo& c, const GroupResult& g, const SimulationOptions& options,
                            std::int64_t& bootstrap_fits) {
    SessionEstimate e;
    e.condition = c.condition;
    e.n_trials = g.n_trials;
    e.estimate = g.headline.value;
    e.method = g.headline.method;
    e.reliable = g.headline.reliable;
    e.reason = g.headline.reason;
    e.estimate_p = c.target_p;
    e.difference_label = c.difference_label();
    if (g.match_ratio && c.compares_glare() && c.test_intensity_cd) e.test_log10 = std::log10(*c.test_intensity_cd);
    if (g.bootstrap) bootstrap_fits += g.bootstrap->n_done;
    const bool from_fit = g.fit && g.fit->estimate && g.headline.value;
    if (options.intervals == IntervalMethod::Profile && from_fit) {
        const ProfileInterval p = profile_threshold_interval(g.counts, *g.fit, options.ci_level);
        e.ci = p.ci;
        e.ci_open = p.lower_open || p.upper_open;
        if (!p.ci && e.reason.empty()) e.reason = "no profile interval: " + p.reason;
        // The headline's reason for --bootstrap 0 names the bootstrap: not the question here.
        if (e.reason.find("no bootstrap was asked for") != std::string::npos) e.reason.clear();
    } else {
        e.ci = g.headline.ci;
    }
    return e;
}

/// The true values and the design of simulation_json; empty reason when read.
std::string read_truth(const std::string& json, SessionSummary& s, std::map<std::string, SessionEstimate>& truths,
                       int design_index) {
    nlohmann::json j;
    try {
        j = store::parse_json(json, "its simulation_json");
    } catch (const store::StoreError& e) {
        return e.what();
    }
    const auto index = store::number_at(j, "/design_index");
    if (!index || *index != design_index)
        return fmt::format("its simulation_json gives design_index {} but the file is in the folder of design {}",
                           index ? fmt::format("{}", *index) : std::string("(none)"), design_index);
    s.design_index = design_index;
    s.index = static_cast<std::int64_t>(store::number_at(j, "/index").value_or(-1));
    s.seed = static_cast<std::uint64_t>(store::number_at(j, "/seed").value_or(0));
    const nlohmann::json* truth = store::json_at(j, "/true");
    if (!truth || !truth->is_object()) return "its simulation_json has no object \"true\" (the true values)";
    for (const auto& [name, t] : truth->items()) {
        SessionEstimate e;
        e.condition = name;
        e.truth = store::number_at(t, "/value");
        e.truth_what = store::string_at(t, "/what").value_or("");
        e.truth_p = store::number_at(t, "/p").value_or(0.5);
        truths[name] = std::move(e);
    }
    return {};
}

}  // namespace

const char* to_string(IntervalMethod m) noexcept {
    return m == IntervalMethod::Bootstrap ? "bootstrap" : "profile";
}

SessionRead read_simulated_session(const fs::path& file, int design_index, const SimulationOptions& options) {
    SessionRead out;
    Dataset data;
    try {
        data = read_study(file);
    } catch (const std::exception& e) {
        out.reason = fmt::format("refused: {}", e.what());
        return out;
    }
    if (data.sessions.size() != 1) {
        out.reason = fmt::format("it holds {} sessions; a simulated session's file holds one", data.sessions.size());
        return out;
    }
    const SessionInfo& info = data.sessions.front();
    if (info.status != "completed") {
        out.reason = fmt::format("its session is {}, not completed", info.status);
        return out;
    }
    const std::optional<std::string>& simulation_json = info.simulation_json;
    if (!simulation_json) {
        out.reason = "its session is not a simulated one (no simulation_json): an ordinary study file";
        return out;
    }
    SessionSummary s;
    s.file = file.string();
    s.observer = info.observer;
    std::map<std::string, SessionEstimate> truths;
    if (std::string why = read_truth(*simulation_json, s, truths, design_index); !why.empty()) {
        out.reason = std::move(why);
        return out;
    }
    AnalysisOptions ao;
    ao.bootstrap = options.intervals == IntervalMethod::Bootstrap ? options.bootstrap : 0;
    ao.seed = options.seed;
    ao.family = options.family;
    ao.ci_level = options.ci_level;
    ao.last_reversals = options.last_reversals;
    ao.n_threads = 1;  // the files are the parallel work
    const StudyResults r = analyze_study(data, ao);
    for (const ConditionInfo& c : r.conditions) {
        const GroupResult* g = r.main_group(c.condition);
        if (!g) continue;
        SessionEstimate e = estimate_of(c, *g, options, out.bootstrap_fits);
        if (const auto it = truths.find(c.condition); it != truths.end()) {
            e.truth = it->second.truth;
            e.truth_what = it->second.truth_what;
            e.truth_p = it->second.truth_p;
        }
        if (s.level_unit.empty()) s.level_unit = c.level_unit();
        s.n_trials += e.n_trials;
        s.conditions.push_back(std::move(e));
    }
    out.summary = std::move(s);
    return out;
}

SimulationResults analyze_simulation(const fs::path& dir, const SimulationOptions& options) {
    if (!(options.ci_level > 0.0 && options.ci_level < 1.0))
        throw InputError(SourceLocation::command_line("--level"), "the interval level must lie in (0, 1)");
    if (options.intervals == IntervalMethod::Bootstrap && options.bootstrap < 1)
        throw InputError(SourceLocation::command_line("--bootstrap"),
                         "--intervals bootstrap needs at least 1 resample");
    SimulationResults r;
    r.options = options;
    r.options.progress = nullptr;
    r.folder = dir;
    r.manifest = read_simulation_manifest(dir);
    const std::vector<Found> found = list_session_files(dir, r.manifest.designs.size(), r.files_found);
    const auto started = std::chrono::steady_clock::now();

    std::vector<SessionRead> reads(found.size());
    std::atomic<std::size_t> next{0}, done{0};
    const auto work = [&] {
        for (std::size_t i = next++; i < found.size(); i = next++) {
            if (found[i].skip.empty()) reads[i] = read_simulated_session(found[i].path, found[i].design_index, options);
            ++done;
        }
    };
    const int n_threads = std::max(1, std::min<int>(options.n_threads, static_cast<int>(found.size())));
    std::vector<std::thread> workers;
    for (int t = 0; t < n_threads; ++t) workers.emplace_back(work);
    while (done.load() < found.size()) {
        if (options.progress) options.progress(done.load(), found.size());
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    for (std::thread& w : workers) w.join();
    if (options.progress) options.progress(found.size(), found.size());
    r.read_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

    for (std::size_t i = 0; i < found.size(); ++i) {
        if (!found[i].skip.empty()) {
            r.skipped.push_back({found[i].path.string(), found[i].skip});
        } else if (!reads[i].summary) {
            r.skipped.push_back({found[i].path.string(), reads[i].reason});
        } else {
            r.bootstrap_fits += reads[i].bootstrap_fits;
            r.sessions.push_back(std::move(*reads[i].summary));
        }
    }
    reads.clear();
    r.conditions = summarize_conditions(r.sessions, r.manifest, options.ci_level);
    r.power = power_analyses(r.sessions, r.manifest, options, r.warnings);
    for (const ConditionSummary& c : r.conditions)
        if (c.truth_differs)
            r.warnings.push_back(fmt::format(
                "design \"{}\", condition \"{}\": the sessions' true values differ (from {:.6g} to {:.6g}); bias "
                "and coverage are taken against each session's own truth, the mean is shown",
                c.design, c.condition, c.truth_min, c.truth_max));
    return r;
}

}  // namespace atonlab::analysis
