// The Procedure base: history keeping and replay (procedure.h).
#include "atonlab/protocols/procedure.h"

#include <fmt/format.h>

#include <stdexcept>

namespace atonlab::protocols {

ProcedureError::ProcedureError(std::string parameter, const std::string& message)
    : std::invalid_argument(fmt::format("{}: {}", parameter, message)),
      parameter_(std::move(parameter)),
      message_(message) {}

std::string_view to_string(Response r) noexcept {
    switch (r) {
        case Response::No:
            return "No";
        case Response::Yes:
            return "Yes";
        case Response::Left:
            return "Left";
        case Response::Right:
            return "Right";
        case Response::CoarseUp:
            return "CoarseUp";
        case Response::CoarseDown:
            return "CoarseDown";
        case Response::FineUp:
            return "FineUp";
        case Response::FineDown:
            return "FineDown";
        case Response::Confirm:
            return "Confirm";
    }
    return "?";
}

std::string_view response_word(Response r) noexcept {
    switch (r) {
        case Response::No:
            return "no";
        case Response::Yes:
            return "yes";
        case Response::Left:
            return "left";
        case Response::Right:
            return "right";
        case Response::CoarseUp:
            return "coarse_up";
        case Response::CoarseDown:
            return "coarse_down";
        case Response::FineUp:
            return "fine_up";
        case Response::FineDown:
            return "fine_down";
        case Response::Confirm:
            return "confirm";
    }
    return "?";
}

std::optional<Response> parse_response_word(std::string_view word) noexcept {
    for (const Response r : {Response::No, Response::Yes, Response::Left, Response::Right, Response::CoarseUp,
                             Response::CoarseDown, Response::FineUp, Response::FineDown, Response::Confirm})
        if (response_word(r) == word) return r;
    return std::nullopt;
}

void Procedure::record(Response r) {
    if (finished()) throw std::logic_error(fmt::format("{}: record() after the procedure finished", kind()));
    do_record(r);  // throws before changing anything for an answer it cannot take
    history_.push_back(r);
}

void replay(Procedure& fresh, std::span<const Response> history) {
    if (!fresh.history().empty())
        throw std::logic_error(
            fmt::format("replay: the {} already has {} responses", fresh.kind(), fresh.history().size()));
    for (std::size_t i = 0; i < history.size(); ++i) {
        if (fresh.finished())
            throw ProcedureError("history", fmt::format("the {} finished after {} responses but the log holds {}",
                                                        fresh.kind(), i, history.size()));
        fresh.record(history[i]);
    }
}

}  // namespace atonlab::protocols
