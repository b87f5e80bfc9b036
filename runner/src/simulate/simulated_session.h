#pragma once
// One simulated session without a render (docs/simulate.md): the protocol's
// schedule answered by a simulated observer from the decision table, written
// into its own study file in one transaction. The file is written under a
// ".partial" name and renamed into place once it is closed, so a file under
// its final name is always a whole session and a killed run leaves only
// ".partial" files behind, which the next run deletes and redoes.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "atonlab/protocols/protocol.h"
#include "atonlab/protocols/simulated_observer.h"
#include "simulate/decision_table.h"

namespace atonlab::runner {

/// What a condition's stimulus record says of its frames in one arrangement,
/// worked out once from the scene (no render): each frame's moment and each view's glare model.
struct FrameFacts {
    std::vector<double> frame_times_s;
    std::vector<std::string> view_glares;
};

/// What every session of one design shares, read-only across worker threads.
struct SimulationDesign {
    std::size_t index = 0;
    std::string label;  ///< "max_trials=20", a protocol's file name, or "" for a simulation of one design
    std::vector<std::string> overrides;  ///< the protocol keys this design sets (KEY=VALUE)
    protocols::Protocol protocol;
    std::string protocol_path;  ///< the file the design comes from
    std::string protocol_text;  ///< with the design's overrides applied: what each session stores
    std::string protocol_name;
    std::string scene_text;
    std::string scene_name;
    protocols::SimulatedObserverParams observer;
    /// table_key() of this design: known before the table is loaded or built.
    std::string table_key;
    DecisionTable table;
    /// The model's true value per condition (level units, without the
    /// observer's bias), or why there is none.
    std::map<std::string, double> model_true;
    std::map<std::string, std::string> no_true;
    std::map<std::pair<std::string, int>, FrameFacts> frame_facts;  ///< (condition, arrangement)
};

/// The observer seed of a session with schedule seed `seed`, as `atonlab run` derives it (resume.h).
std::uint64_t simulated_observer_seed(std::uint64_t seed);

/// The sessions.simulation_json of session `index` (docs/simulate.md): the
/// design, the seed, the observer's parameters, each condition's true value
/// (the model's plus the observer's bias) and how the decisions were made
/// ("table" or "rendered").
std::string simulation_json(const SimulationDesign& design, std::size_t index, std::uint64_t seed,
                            const std::string& decisions);

/// The observer code of session `index` of design `design_index`, unique in a simulation.
std::string simulated_observer_code(std::size_t design_index, std::size_t index);

/// Runs session `index` (schedule seed `seed`) from the design's table and
/// writes it to partial_path(file), its commits unsynced (StoreOptions::durable
/// false): a SessionCommitter makes it durable and renames it to `file`.
/// Returns the trials stored. Throws store::StoreError when the file cannot be written.
std::size_t simulate_session(const SimulationDesign& design, std::size_t index, std::uint64_t seed,
                             const std::filesystem::path& file);

/// Makes written sessions durable and renames each from its ".partial" name
/// to its own, in batches: one syncfs(2) for many files instead of an fsync
/// per commit (a second's sessions, or 256). Thread-safe.
class SessionCommitter {
public:
    explicit SessionCommitter(const std::filesystem::path& dir);
    ~SessionCommitter();
    SessionCommitter(const SessionCommitter&) = delete;
    SessionCommitter& operator=(const SessionCommitter&) = delete;
    /// `file`'s partial is written and closed; commits the batch when it is due.
    void add(const std::filesystem::path& file);
    /// Commits every session added.
    void flush();

private:
    void commit_locked();
    int dir_fd_ = -1;
    std::mutex mutex_;
    std::vector<std::filesystem::path> pending_;
    std::chrono::steady_clock::time_point oldest_;
};

/// file + ".partial", and the SQLite files beside it.
std::filesystem::path partial_path(const std::filesystem::path& file);
void remove_partial(const std::filesystem::path& file);

}  // namespace atonlab::runner
