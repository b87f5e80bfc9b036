#pragma once
// What a session's protocol says about its trials: per condition the
// procedure, the guess rate and the target probability of the binary outcome
// (dataset.h Trial::outcome), and, for adaptive tracks, the staircase
// reversals and QUEST's posterior after every trial, found by replaying the
// logged answers through a fresh copy of the track's procedure (protocols/;
// docs/architecture.md: procedures are pure state machines).
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/analysis/dataset.h"
#include "atonlab/protocols/protocol.h"

namespace atonlab::analysis::detail {

struct ConditionDesign {
    const protocols::Condition* condition = nullptr;
    std::string procedure;  ///< "staircase", "quest", ...
    double guess_rate = 0.0;
    double target_p = 0.5;
    std::string note;  ///< e.g. a target probability that could not be derived
};

struct ProtocolDesign {
    std::optional<protocols::Protocol> protocol;
    std::string error;  ///< why the protocol text could not be read (then `protocol` is absent)
    std::map<std::string, ConditionDesign, std::less<>> conditions;
    std::vector<std::string> order;  ///< condition names in file order
};

/// Parses the stored protocol text (the scene file need not exist).
ProtocolDesign design_of(std::string_view protocol_text, std::string_view protocol_name);

/// Replays one track's trials (in trial order, all of one session and one
/// procedure_id) through a fresh copy of its procedure and fills
/// Trial::reversal (staircases) or the Trial::posterior_* fields (QUEST). Returns
/// an empty string, or why nothing was filled (the logged levels differ from
/// the procedure's proposals, an answer without an outcome, ...).
std::string replay_track(const ConditionDesign& design, std::size_t track, const std::vector<Trial*>& trials);

/// The track number of a procedure_id "CONDITION/rREP/tTRACK", if it has that shape.
std::optional<std::size_t> track_number(std::string_view procedure_id);

}  // namespace atonlab::analysis::detail
