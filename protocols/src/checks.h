#pragma once
// Parameter and response checks shared by the procedures: each throws
// ProcedureError naming the parameter as the protocol file spells it.
#include <fmt/format.h>

#include <cmath>
#include <string_view>

#include "atonlab/protocols/procedure.h"

namespace atonlab::protocols::detail {

inline void require(bool ok, std::string_view parameter, std::string_view message) {
    if (!ok) throw ProcedureError(std::string(parameter), std::string(message));
}

inline void require_finite(double v, std::string_view parameter) {
    require(std::isfinite(v), parameter, fmt::format("must be a finite number, not {}", v));
}

inline void require_positive(double v, std::string_view parameter) {
    require(std::isfinite(v) && v > 0.0, parameter, fmt::format("must be a finite number > 0, not {}", v));
}

/// Yes -> true, No -> false; anything else is a mapping error in the protocol.
inline bool require_binary(Response r, std::string_view kind) {
    if (r == Response::Yes) return true;
    if (r == Response::No) return false;
    throw ProcedureError("response", fmt::format("a {} takes Yes or No, not {}", kind, to_string(r)));
}

}  // namespace atonlab::protocols::detail
