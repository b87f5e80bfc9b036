// The session's trial schedule (protocol_schedule.h).
#include "atonlab/protocols/protocol_schedule.h"

#include <fmt/format.h>

#include <stdexcept>

namespace atonlab::protocols {

Schedule::Schedule(Protocol protocol) : Schedule(protocol, protocol.seed) {}

Schedule::Schedule(Protocol protocol, std::uint64_t seed) : protocol_(std::move(protocol)), seed_(seed) {
    std::uint64_t r = 0;
    for (std::size_t b = 0; b < protocol_.blocks.size(); ++b)
        for (int rep = 0; rep < protocol_.blocks[b].repetitions; ++rep)
            runs_.push_back({b, rep, derive_seed(seed_, r++)});
    if (!runs_.empty()) live_.emplace(build_run(0));
}

Schedule::Run Schedule::build_run(std::size_t r) const {
    const BlockRun& run = runs_[r];
    const Block& block = protocol_.blocks[run.block];
    std::vector<std::unique_ptr<Procedure>> procedures;
    std::vector<std::pair<std::size_t, std::size_t>> tracks;
    for (std::size_t c = 0; c < block.conditions.size(); ++c) {
        const Condition& condition = block.conditions[c];
        const std::uint64_t condition_seed = derive_seed(run.seed, c + 1);
        for (std::size_t t = 0; t < condition.procedure.tracks(); ++t) {
            procedures.push_back(make_track(condition, t, derive_seed(condition_seed, t)));
            tracks.emplace_back(c, t);
        }
    }
    return Run{Interleaver(std::move(procedures), block.interleave, derive_seed(run.seed, 0)), std::move(tracks)};
}

std::optional<ScheduledTrial> Schedule::next() const {
    if (finished()) return std::nullopt;
    const std::optional<Proposal> proposal = live_->interleaver.next();
    if (!proposal) return std::nullopt;  // not reached: a finished run is replaced at once
    const BlockRun& run = runs_[run_];
    const auto [c, t] = live_->tracks.at(proposal->stream);
    const Condition& condition = protocol_.blocks[run.block].conditions[c];
    ScheduledTrial trial;
    trial.step = history_.size();
    trial.run = run_;
    trial.block = run.block;
    trial.repetition = run.repetition;
    trial.condition = c;
    trial.track = t;
    trial.condition_id = condition.name;
    trial.procedure_id = fmt::format("{}/r{}/t{}", condition.name, run.repetition, t);
    trial.task = condition.task;
    trial.proposal = *proposal;
    trial.stimulus = make_stimulus(protocol_, condition, *proposal);
    trial.starts_run = live_->interleaver.history().empty();
    return trial;
}

void Schedule::record(Response r) {
    if (finished()) throw std::logic_error("Schedule::record() after the schedule finished");
    live_->interleaver.record(r);  // throws, unchanged, for an answer the track cannot take
    history_.push_back(r);
    if (!live_->interleaver.finished()) return;
    done_.push_back(std::move(*live_));
    live_.reset();
    if (++run_ < runs_.size()) live_.emplace(build_run(run_));
}

std::string Schedule::state() const {
    if (finished()) return fmt::format("schedule finished runs={} steps={}", runs_.size(), history_.size());
    return fmt::format("schedule run={} steps={} {}", run_, history_.size(), live_->interleaver.state());
}

std::optional<std::size_t> Schedule::max_trials() const {
    std::size_t total = 0;
    for (const BlockRun& run : runs_) {
        for (const Condition& c : protocol_.blocks[run.block].conditions) {
            const std::optional<std::size_t> per_track = c.procedure.max_trials_per_track();
            if (!per_track) return std::nullopt;
            total += *per_track * c.procedure.tracks();
        }
    }
    return total;
}

std::vector<TrackResult> Schedule::results() const {
    std::vector<TrackResult> out;
    auto add = [&](const Run& run, std::size_t r) {
        const BlockRun& br = runs_[r];
        for (std::size_t i = 0; i < run.tracks.size(); ++i) {
            const auto [c, t] = run.tracks[i];
            const Condition& condition = protocol_.blocks[br.block].conditions[c];
            const Procedure& p = run.interleaver.procedure(i);
            TrackResult tr;
            tr.run = r;
            tr.block = br.block;
            tr.repetition = br.repetition;
            tr.condition = c;
            tr.track = t;
            tr.condition_id = condition.name;
            tr.procedure_id = fmt::format("{}/r{}/t{}", condition.name, br.repetition, t);
            tr.finished = p.finished();
            tr.responses = p.history().size();
            tr.estimate = p.estimate();
            out.push_back(std::move(tr));
        }
    };
    for (std::size_t r = 0; r < done_.size(); ++r) add(done_[r], r);
    if (live_) add(*live_, run_);
    return out;
}

Schedule Schedule::replay(Protocol protocol, std::uint64_t seed, std::span<const Response> responses) {
    Schedule s(std::move(protocol), seed);
    for (std::size_t i = 0; i < responses.size(); ++i) {
        if (s.finished())
            throw ProcedureError("history", fmt::format("the schedule finished after {} responses but the log holds {}",
                                                        i, responses.size()));
        s.record(responses[i]);
    }
    return s;
}

}  // namespace atonlab::protocols
