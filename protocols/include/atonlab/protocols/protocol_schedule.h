#pragma once
// The trial schedule of a session: the protocol's blocks in file order, each
// run `repetitions` times; in each run, every track of every condition of the
// block is interleaved by one Interleaver (random or sequential, the block's
// `interleave`). The whole sequence is a pure function of (protocol, seed,
// responses): replaying the logged responses into a fresh Schedule reproduces
// every trial, which is how the runner resumes a session.
//
// Seeds (rng.h derive_seed): run r (counting every run of every block in
// order) gets run_seed = derive_seed(seed, r); its interleaver
// derive_seed(run_seed, 0); condition c of the block derive_seed(run_seed, c + 1),
// and its track t derive_seed(condition_seed, t), exactly as make_procedure().
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "atonlab/protocols/protocol.h"

namespace atonlab::protocols {

/// One run of a block.
struct BlockRun {
    std::size_t block = 0;  ///< index into Protocol::blocks
    int repetition = 0;     ///< 0-based
    std::uint64_t seed = 0;
};

/// What to show now.
struct ScheduledTrial {
    std::size_t step = 0;       ///< responses recorded so far in the session (this one's index in history())
    std::size_t run = 0;        ///< index into Schedule::block_runs()
    std::size_t block = 0;      ///< index into Protocol::blocks
    int repetition = 0;         ///< of the block
    std::size_t condition = 0;  ///< index into the block's conditions
    std::size_t track = 0;      ///< the condition's track
    std::string condition_id;   ///< the condition's name
    std::string procedure_id;   ///< "CONDITION/rREPETITION/tTRACK": unique in the session
    Task task = Task::TwoAfc;
    Proposal proposal;        ///< the track's proposal (proposal.trial: the track's trial)
    Stimulus stimulus;        ///< frames and views to show
    bool starts_run = false;  ///< the first trial of a block run: adapt (and show the block's instructions) first
};

/// A track's outcome.
struct TrackResult {
    std::size_t run = 0;
    std::size_t block = 0;
    int repetition = 0;
    std::size_t condition = 0;
    std::size_t track = 0;
    std::string condition_id;
    std::string procedure_id;
    bool finished = false;
    std::size_t responses = 0;  ///< responses the track took
    Estimate estimate;          ///< the procedure's (a forced choice gives its inner procedure's)
};

class Schedule {
public:
    /// Seeded with protocol.seed.
    explicit Schedule(Protocol protocol);
    Schedule(Protocol protocol, std::uint64_t seed);

    const Protocol& protocol() const noexcept { return protocol_; }
    std::uint64_t seed() const noexcept { return seed_; }
    const std::vector<BlockRun>& block_runs() const noexcept { return runs_; }
    /// The most trials the whole schedule can take (every track of every
    /// block run at its ProcedureSpec::max_trials_per_track); nullopt when a
    /// procedure has no upper bound.
    std::optional<std::size_t> max_trials() const;

    bool finished() const noexcept { return run_ >= runs_.size(); }
    /// The trial to show now; nullopt once finished(). Pure.
    std::optional<ScheduledTrial> next() const;
    /// The answer to next(): Left / Right for 2AFC (the side or interval
    /// chosen), Yes / No for yes-no, an adjustment action for adjust. Throws
    /// std::logic_error when finished, ProcedureError("response") for an answer
    /// the task does not take (nothing changes then).
    void record(Response r);
    const std::vector<Response>& history() const noexcept { return history_; }
    /// One line that pins the state down (the run and its interleaver's state).
    std::string state() const;
    /// Every track of every run begun so far.
    std::vector<TrackResult> results() const;

    /// A fresh schedule with `responses` recorded (ProcedureError("history")
    /// if the schedule finishes before they are used up).
    static Schedule replay(Protocol protocol, std::uint64_t seed, std::span<const Response> responses);

private:
    struct Run {
        Interleaver interleaver;
        std::vector<std::pair<std::size_t, std::size_t>> tracks;  ///< stream -> (condition, track)
    };
    Run build_run(std::size_t r) const;

    Protocol protocol_;
    std::uint64_t seed_;
    std::vector<BlockRun> runs_;
    std::size_t run_ = 0;
    std::vector<Run> done_;    ///< finished runs
    std::optional<Run> live_;  ///< the run in progress
    std::vector<Response> history_;
};

}  // namespace atonlab::protocols
