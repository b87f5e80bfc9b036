#pragma once
// Continuing a session (--resume, --resume-last): the study file checked, the
// session found and checked against this run, and its logged responses
// replayed step by step against what this protocol and seed propose.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "atonlab/protocols/protocol.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/runner/session/run_options.h"
#include "atonlab/runner/session/session_observer.h"
#include "atonlab/store/store.h"

namespace atonlab::runner {


/// The study file opened read-only when it has content: checked by the store
/// (an atonlab study, undamaged, no newer than this build) before anything is
/// written. std::nullopt for a file that does not exist yet or is empty (a new
/// study; created when the session begins). A file of an older schema is
/// migrated first (a reader cannot migrate it), the one write made before the
/// session's other checks.
std::optional<store::Store> read_existing_study(const std::string& db, const store::StoreOptions& options);

/// The session this run continues, or a new one's seed.
struct SessionToRun {
    bool resumed = false;
    store::SessionId session{};              ///< resumed: the session continued
    std::uint64_t seed = 0;                  ///< the schedule's seed
    std::vector<store::TrialRecord> logged;  ///< resumed: its stored trials
};

/// The session --resume or --resume-last names in `existing` (checked: not
/// completed, the same protocol text, scene text, observer and seed), or a
/// new session with --seed or the protocol's. Throws InputError naming the
/// option (the protocol or scene file for a text that changed).
SessionToRun session_to_run(const RunOptions& o, std::optional<store::Store>& existing,
                            const protocols::Protocol& protocol, const std::string& protocol_sha,
                            const std::string& scene_sha, const std::string& code);

/// The model observer's seed: --observer-seed or one derived from the seed; a
/// resumed session keeps the one its first trial recorded.
std::uint64_t observer_seed_to_run(const RunOptions& o, const SessionToRun& run);

/// Where the logged responses leave the session.
struct Replayed {
    protocols::Schedule schedule;  ///< the procedures' state after the logged trials
    /// An adjustment match the log stops inside: its steps and their rows in the log.
    std::vector<std::pair<protocols::ScheduledTrial, std::size_t>> open_match;
    double clock_s = 0.0;               ///< the session clock at the last stored answer
    bool previous_ended_trial = true;   ///< the next trial gets the inter-trial fixation
};

/// Replays the logged responses: the schedule's state, checked step by step
/// against what was logged, and where the observer stands (a script skips the
/// lines used). A trial stored as "missed" (repeated: its stimulus missed a
/// refresh) or "timeout" was never shown to the procedure: it is checked, then
/// skipped, as the live session skipped it and showed the same proposal again.
/// Throws InputError naming the study file when the log does not fit.
Replayed replay_logged(const protocols::Protocol& protocol, const SessionToRun& run, const std::string& db,
                       SessionObserver& observer);

}  // namespace atonlab::runner
