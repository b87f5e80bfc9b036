#pragma once
// The procedure registry: every procedure kind a protocol file may name, and
// what the rest of atonlab knows of each (docs/architecture.md "How to add a
// procedure"). Each kind declares its own facts in its type file
// (protocols/src/procedure_types/NAME.cpp: its keys, how its table is read, its
// target probability and level range, what analysis replays and summarises);
// the protocol reader, the runner and analysis ask the kind through
// ProcedureType instead of comparing names. A kind's name is spelled once,
// as its class's kName ("staircase").
//
// Adding a procedure: its header and state machine (NAME.h, NAME.cpp), its
// type file, and one entry in each of the three lists below (same order).
// ForcedChoice and Interleaver are not kinds: they wrap a kind's tracks (2AFC,
// interleaved tracks).
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "atonlab/protocols/adjustment.h"
#include "atonlab/protocols/constant_stimuli.h"
#include "atonlab/protocols/forced_choice.h"
#include "atonlab/protocols/interleaver.h"
#include "atonlab/protocols/procedure.h"
#include "atonlab/protocols/quest.h"
#include "atonlab/protocols/rng.h"
#include "atonlab/protocols/staircase.h"
#include "atonlab/protocols/weighted_staircase.h"

namespace atonlab::protocols {

// --- The registered kinds (the three lists in one order) ---------------------------

enum class ProcedureKind : std::uint8_t { Staircase, WeightedStaircase, Quest, Adjustment, ConstantStimuli };

/// A procedure and its parameters, 1:1 the procedures' parameter structs.
using ProcedureParams =
    std::variant<StaircaseParams, WeightedStaircaseParams, QuestParams, AdjustmentParams, ConstantStimuliParams>;

/// Each kind's facts, in ProcedureKind's order.
inline constexpr const ProcedureType& (*kProcedureTypes[])() = {
    &Staircase::type, &WeightedStaircase::type, &Quest::type, &Adjustment::type, &ConstantStimuli::type};

static_assert(std::size(kProcedureTypes) == std::variant_size_v<ProcedureParams>,
              "one ProcedureParams alternative per registered procedure");

// --- What a kind declares ---------------------------------------------------------

namespace detail {
class ProcedureReader;  // a condition's merged procedure table (protocols/src/protocol_schema.h)
}

/// What analysis reads back from a track replayed through the procedure, and
/// what the tracks figure marks on it (docs/analysis.md).
enum class TrackEstimate : std::uint8_t {
    None,       ///< no estimate per track: the psychometric fit (or the matches) of all trials is the estimate
    Reversals,  ///< the mean of each track's last reversals; the figure circles the reversals (Levitt 1971)
    Posterior,  ///< the posterior's mean, sd and 95% credible interval after every trial (Watson & Pelli 1983)
};

/// A replayed track's state after an answer, as analysis stores it per trial.
struct TrackState {
    std::vector<std::size_t> reversal_trials;  ///< Reversals: the 0-based trials whose answer made a reversal
    std::optional<double> mean, sd;            ///< Posterior: mean and sd, the procedure's units
    std::optional<double> lower, upper;        ///< Posterior: its 2.5% and 97.5% quantiles
};

/// Everything the protocol reader, the runner and analysis know of a kind.
/// Every function takes the kind's own alternative of ProcedureParams.
struct ProcedureType {
    ProcedureKind kind;
    std::string_view name;                   ///< as protocol files, the store and analysis spell it
    std::span<const std::string_view> keys;  ///< its procedure table's keys, "kind" included

    // --- the protocol file
    /// Reads the merged procedure table; a list-valued start (one interleaved
    /// track per entry) goes to track_starts. Throws InputError at the key,
    /// ProcedureError for a bad value.
    ProcedureParams (*read)(const detail::ProcedureReader& table, std::vector<double>& track_starts);
    bool adjusts;                  ///< takes the adjustment actions: task "adjust" needs it, and it needs "adjust"
    std::string_view needs_log10;  ///< why it needs level_scale = "log10"; empty: any scale
    /// One track: start (when given) replaces its first level; validates and
    /// throws ProcedureError naming the first bad parameter.
    std::unique_ptr<Procedure> (*make)(const ProcedureParams& params, std::optional<double> start, std::uint64_t seed);

    // --- ProcedureSpec's questions (protocol.h says what each means)
    std::optional<double> (*target_p_yes)(const ProcedureParams& params);
    std::vector<double> (*level_bounds)(const ProcedureParams& params);
    std::pair<double, double> (*search_range)(const ProcedureParams& params, std::span<const double> track_starts);
    std::optional<std::size_t> (*max_trials_per_track)(const ProcedureParams& params);
    /// How messages name the lowest and highest level it presents ("min_level", "max_level").
    std::array<std::string_view, 2> bound_names;

    // --- analysis
    TrackEstimate track_estimate;
    /// The P(Yes) at no stimulus it states itself (QUEST's gamma); nullopt: the task's.
    std::optional<double> (*guess_rate)(const ProcedureParams& params);
    /// The kind with its parameters in words, for notes ("a 2-up/2-down staircase with up_step_ratio 1").
    std::string (*describe)(const ProcedureParams& params);
    /// Its state after the answers replayed into `p` (a procedure this type made).
    TrackState (*track_state)(const Procedure& p);

    /// Whether analysis follows its tracks (reversals or a posterior).
    bool adaptive() const noexcept { return track_estimate != TrackEstimate::None; }
};

/// The registered kinds, in ProcedureKind's order.
std::span<const ProcedureType* const> procedure_types();
const ProcedureType& procedure_type(ProcedureKind kind) noexcept;
/// The kind called `name`; nullptr for any other word.
const ProcedureType* find_procedure_type(std::string_view name) noexcept;
/// The registered names, each quoted, joined by `separator` and the last by
/// `last` ("\"staircase\", ... or \"constant-stimuli\"").
std::string quoted_procedure_names(std::string_view separator, std::string_view last);

}  // namespace atonlab::protocols
