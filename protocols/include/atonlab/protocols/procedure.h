#pragma once
// The common shape of every adaptive procedure (docs/architecture.md "One trial, from protocol to store"): a pure
// state machine. Given the responses recorded so far it proposes the next
// stimulus; replaying the logged responses into a freshly constructed procedure
// (same parameters, same seed) reconstructs its state exactly, bit for bit. That
// is how a crashed session resumes.
//
// Rules every procedure follows so that replay is exact:
//  - all randomness comes from its own seeded Rng (rng.h), never from the
//    standard distributions, whose output differs between standard libraries;
//  - every random draw a proposal needs is made when the previous response is
//    recorded (or at construction), so next() is const and may be called any
//    number of times;
//  - the state depends only on (parameters, seed, responses), in that order.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace atonlab::protocols {

struct ProcedureType;  // what protocols and analysis know of a procedure kind (procedures.h)

/// A bad procedure parameter (or a response the procedure cannot take). Carries
/// the parameter's name as the protocol file spells it ("step_sizes",
/// "p_threshold"); the protocol-file parser catches it and adds file and line.
/// what() is "PARAMETER: MESSAGE".
class ProcedureError : public std::invalid_argument {
public:
    ProcedureError(std::string parameter, const std::string& message);

    const std::string& parameter() const noexcept { return parameter_; }
    const std::string& message() const noexcept { return message_; }

private:
    std::string parameter_;
    std::string message_;
};

/// One observer answer, as a procedure consumes it. Which answers a procedure
/// takes depends on the task:
///  - yes/no and "correct/incorrect" procedures (staircases, QUEST, constant
///    stimuli) take No / Yes. Yes is the answer that moves a staircase DOWN:
///    "correct", "seen", or whatever the protocol maps onto it;
///  - a two-alternative forced choice (ForcedChoice) takes Left / Right, the
///    side the observer chose (for a temporal 2IFC: Left = first interval);
///  - the method of adjustment takes the five adjustment actions.
/// The store logs each as its word (response_word), not as its number.
enum class Response : std::uint8_t {
    No = 0,
    Yes = 1,
    Left = 2,
    Right = 3,
    CoarseUp = 4,
    CoarseDown = 5,
    FineUp = 6,
    FineDown = 7,
    Confirm = 8,
};

/// "No", "Yes", "Left", ... (for messages and logs).
std::string_view to_string(Response r) noexcept;
/// The word a response is stored, scripted and analysed as: "no", "yes",
/// "left", "right", "coarse_up", "coarse_down", "fine_up", "fine_down",
/// "confirm" (the action words of docs/protocol-file.md). The store's
/// `response` column holds these words.
std::string_view response_word(Response r) noexcept;
/// The response a word names (the inverse of response_word); nullopt for any other word.
std::optional<Response> parse_response_word(std::string_view word) noexcept;
/// The words a trial the procedure never took is stored as: no answer within
/// the response timeout, or a stimulus that missed a refresh (shown again).
inline constexpr std::string_view kTimeoutWord = "timeout";
inline constexpr std::string_view kMissedWord = "missed";
/// A stored response word that the procedure took: not kTimeoutWord or kMissedWord.
constexpr bool is_counted_response_word(std::string_view word) noexcept {
    return word != kTimeoutWord && word != kMissedWord;
}
/// Yes for true, No for false.
constexpr Response binary(bool yes) noexcept {
    return yes ? Response::Yes : Response::No;
}

/// What a procedure asks to be shown next.
struct Proposal {
    double level = 0.0;                ///< in the procedure's own units (see each procedure)
    std::optional<bool> test_on_left;  ///< forced choice only: the test stimulus goes on the left (first interval)
    std::size_t stream = 0;            ///< Interleaver: index of the procedure that proposed it; 0 otherwise
    std::size_t trial = 0;             ///< 0-based trial of that procedure (several adjustment actions share one)
};

/// A procedure's current answer to the question it was built to ask.
struct Estimate {
    double value = std::numeric_limits<double>::quiet_NaN();  ///< threshold / PSE / matched level, procedure's units
    double sd = std::numeric_limits<double>::quiet_NaN();     ///< spread of that estimate where one is defined
    std::size_t n = 0;   ///< how many values it rests on (reversals, trials, matches)
    std::string method;  ///< how it was computed, e.g. "mean of last 6 reversals"
};

/// The interface. Concrete procedures are built from a parameter struct and a
/// seed; they validate the parameters in their constructor and throw
/// ProcedureError naming the first bad one.
class Procedure {
public:
    virtual ~Procedure() = default;

    /// Stable name of the procedure kind ("staircase", "quest", ...).
    virtual std::string_view kind() const noexcept = 0;
    /// True once the stop rule is met; next() is then empty and record() throws.
    virtual bool finished() const = 0;
    /// The next stimulus; std::nullopt once finished(). A pure function of
    /// (parameters, seed, history).
    virtual std::optional<Proposal> next() const = 0;
    /// The procedure's estimate from the responses so far.
    virtual Estimate estimate() const = 0;
    /// A deep copy, history included.
    virtual std::unique_ptr<Procedure> clone() const = 0;
    /// A one-line text that pins the whole state down exactly (doubles in hex
    /// floating point, large tables as a 64-bit hash): two procedures with the
    /// same state() propose the same future. Logged by the store with each trial.
    virtual std::string state() const = 0;
    /// True while a trial is half done (method of adjustment: actions taken but
    /// not yet confirmed). An Interleaver does not switch procedures then.
    virtual bool mid_trial() const { return false; }

    /// Records the answer to the current proposal. Throws std::logic_error when
    /// finished(), ProcedureError("response") for an answer this procedure
    /// cannot take (a mapping error in the protocol).
    void record(Response r);
    /// Every response recorded so far, in order: what the store logs and what
    /// replay() takes.
    const std::vector<Response>& history() const noexcept { return history_; }

protected:
    Procedure() = default;
    Procedure(const Procedure&) = default;
    Procedure& operator=(const Procedure&) = default;
    Procedure(Procedure&&) = default;
    Procedure& operator=(Procedure&&) = default;

    /// Validates r (throw before changing anything) and advances the state.
    virtual void do_record(Response r) = 0;

private:
    std::vector<Response> history_;
};

/// Feeds a logged history into a freshly constructed procedure. Throws
/// std::logic_error if `fresh` already has a history, ProcedureError("history")
/// if the log holds more responses than the procedure accepts before finishing,
/// and whatever record() throws for an answer it cannot take.
void replay(Procedure& fresh, std::span<const Response> history);

/// Builds a P from its constructor arguments (parameters, seed, ...) and replays
/// `history` into it: replay<Staircase>(history, params, seed).
template <class P, class... Args>
P replay(std::span<const Response> history, Args&&... constructor_args) {
    P p(std::forward<Args>(constructor_args)...);
    replay(static_cast<Procedure&>(p), history);
    return p;
}

}  // namespace atonlab::protocols
