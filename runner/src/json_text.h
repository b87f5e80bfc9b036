#pragma once
// JSON text built by hand, left only for run_session.cpp's trial records until
// they are built with nlohmann::json like every other JSON atonlab writes
// (atonlab/store/json.h); then this file goes. Numbers in the shortest form
// that reads back as the same double, non-finite as null, strings escaped
// (RFC 8259 §7).
#include <string>
#include <string_view>

namespace atonlab::runner {

/// The shortest decimal that reads back as the same double; "null" for NaN and ±inf.
std::string json_number(double v);
/// A JSON string literal, quotes included.
std::string json_string(std::string_view text);

}  // namespace atonlab::runner
