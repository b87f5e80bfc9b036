// One simulated session without a render (simulated_session.h).
#include "simulate/simulated_session.h"

#include <fmt/format.h>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <nlohmann/json.hpp>
#include <system_error>

#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/protocols/rng.h"
#include "atonlab/store/store.h"
#include "session/trial_record.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace st = atonlab::store;
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

/// How long the trial's stimulus was on, s: one frame, or two intervals and the blank between.
double presented_s(const p::Protocol& protocol, const p::Condition& c) {
    const p::Timing& t = protocol.timing;
    return c.presentation == p::Presentation::TwoInterval ? 2.0 * t.stimulus_s + t.inter_stimulus_s : t.stimulus_s;
}

}  // namespace

std::uint64_t simulated_observer_seed(std::uint64_t seed) {
    return p::derive_seed(seed, 0x6f62736572766572ULL);  // "observer", as resume.cpp's observer_seed_to_run
}

std::string simulated_observer_code(std::size_t design_index, std::size_t index) {
    return fmt::format("sim-d{:02}-{:06}", design_index, index);
}

std::string simulation_json(const SimulationDesign& d, std::size_t index, std::uint64_t seed,
                            const std::string& decisions) {
    Json j;
    j["design"] = d.label;
    j["design_index"] = d.index;
    j["index"] = index;
    j["seed"] = seed;
    Json observer;
    for (const auto& [key, value] : p::observer_values(d.observer)) observer[key] = value;
    j["observer"] = std::move(observer);
    Json truth = Json::object();
    for (const p::Block& b : d.protocol.blocks)
        for (const p::Condition& c : b.conditions) {
            Json one;
            const auto it = d.model_true.find(c.name);
            const bool two_afc = c.task == p::Task::TwoAfc;
            const std::optional<double> p_yes = c.procedure.target_p_yes();
            if (it != d.model_true.end()) {
                one["value"] = it->second + d.observer.departures.bias_log10;
                one["model_value"] = it->second;
            } else {
                one["value"] = nullptr;
                one["why_none"] = d.no_true.count(c.name) ? d.no_true.at(c.name) : std::string("not computed");
            }
            const double p_level = p_yes ? (two_afc && !c.yes_means_level() ? 1.0 - *p_yes : *p_yes) : 0.5;
            one["what"] = c.task == p::Task::YesNo ? "threshold" : (p_level == 0.5 ? "pse" : "matching level");
            one["p"] = p_level;
            truth[c.name] = std::move(one);
        }
    j["true"] = std::move(truth);
    j["decisions"] = decisions;
    if (decisions == "table") {
        j["table"] = d.table.key;
        j["table_bound"] = d.table.stated_bound;  // what the table holds the decision variable to
    }
    return j.dump();
}

fs::path partial_path(const fs::path& file) {
    return fs::path(file.string() + ".partial");
}

void remove_partial(const fs::path& file) {
    std::error_code ec;
    const fs::path partial = partial_path(file);
    for (const char* suffix : {"", "-wal", "-shm", "-journal"}) fs::remove(partial.string() + suffix, ec);
}

std::size_t simulate_session(const SimulationDesign& d, std::size_t index, std::uint64_t seed, const fs::path& file) {
    remove_partial(file);
    const p::Protocol& protocol = d.protocol;
    p::Schedule schedule(protocol, seed);
    const std::uint64_t observer_seed = simulated_observer_seed(seed);
    p::ObserverDrift drift(d.observer.departures, observer_seed);
    std::vector<st::TrialRecord> records;
    double clock_s = 0.0;  // a virtual session clock at the protocol's timing (docs/simulate.md)
    while (!schedule.finished()) {
        const p::ScheduledTrial t = *schedule.next();
        const p::Condition& c = protocol.blocks[t.block].conditions[t.condition];
        if (t.starts_run) clock_s += protocol.blocks[t.block].adaptation_s;
        const int arrangement = c.task == p::Task::TwoAfc ? arrangement_of(t.proposal.test_on_left) : 0;
        const DecisionCurve& curve = d.table.curve(c.name, arrangement);
        const double perceived = t.proposal.level - drift.at(t.step);
        const double delta = curve.at(perceived);
        const p::Answer answer =
            p::simulated_answer(d.observer, t.task, delta, p::derive_seed(observer_seed, t.step),
                                p::derive_seed(observer_seed, p::observer_cell(c.name, arrangement, t.proposal.level)));
        schedule.record(answer.response);
        const FrameFacts& facts = d.frame_facts.at({c.name, arrangement});
        const double shown_s = presented_s(protocol, c);
        st::TrialRecord tr;
        tr.trial_index = static_cast<std::int64_t>(records.size());
        tr.block = static_cast<int>(t.block);
        tr.condition_id = t.condition_id;
        tr.procedure_id = t.procedure_id;
        tr.level = t.proposal.level;
        tr.test_on_left = t.proposal.test_on_left;
        tr.stimulus_json = stimulus_json(protocol, c, t, facts.frame_times_s, std::nullopt, facts.view_glares, {});
        tr.response = std::string(p::response_word(answer.response));
        tr.response_time_s = shown_s + answer.response_time_s;
        tr.onset_time_s = clock_s;
        tr.procedure_state_json =
            state_json(schedule, "simulated", observer_seed, answer.response_time_s, answer.response, "", t.step);
        records.push_back(std::move(tr));
        clock_s += shown_s + answer.response_time_s + protocol.timing.inter_trial_s;
    }
    const fs::path partial = partial_path(file);
    {
        st::StoreOptions options;
        options.durable = false;  // recomputable from its seed: SessionCommitter syncs it once, with others
        st::Store store = st::Store::create_or_open(partial, options);
        st::SessionStart start;
        start.observer_code = simulated_observer_code(d.index, index);
        start.protocol_text = d.protocol_text;
        start.protocol_name = d.protocol_name;
        start.scene_text = d.scene_text;
        start.scene_name = d.scene_name;
        start.seed = seed;
        start.displayability_json = d.table.displayability_json;
        start.simulation_json = simulation_json(d, index, seed, "table");
        const st::SessionId session = store.begin_session(start);
        store.record_trials(session, records);
        store.finish_session(session, st::SessionStatus::completed);
        store.switch_to_rollback_journal();  // its readers leave no -wal and -shm beside it
    }  // closed: SQLite checkpoints the WAL into the file and removes it
    return records.size();
}

SessionCommitter::SessionCommitter(const fs::path& dir) : dir_fd_(::open(dir.c_str(), O_RDONLY | O_DIRECTORY)) {
    if (dir_fd_ < 0)
        throw std::system_error(errno, std::generic_category(), fmt::format("cannot open {}", dir.string()));
}

SessionCommitter::~SessionCommitter() {
    ::close(dir_fd_);
}

void SessionCommitter::add(const fs::path& file) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (pending_.empty()) oldest_ = std::chrono::steady_clock::now();
    pending_.push_back(file);
    if (pending_.size() >= 256 || std::chrono::steady_clock::now() - oldest_ > std::chrono::seconds(1)) commit_locked();
}

void SessionCommitter::flush() {
    const std::lock_guard<std::mutex> lock(mutex_);
    commit_locked();
}

void SessionCommitter::commit_locked() {
    if (pending_.empty()) return;
    // Every written page of the file system on disk, then the names: a file
    // under its final name is a whole session even after a power cut.
    if (::syncfs(dir_fd_) != 0)
        throw std::system_error(errno, std::generic_category(), "syncfs of the simulation's folder");
    for (const fs::path& file : pending_) fs::rename(partial_path(file), file);
    pending_.clear();
}

}  // namespace atonlab::runner
