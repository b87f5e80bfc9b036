#pragma once
// JSON text for what the runner stores (fit_json, results_json): numbers in
// the shortest form that reads back as the same double, non-finite as null,
// strings escaped (RFC 8259 §7). Reading goes through store::JsonReader.
#include <string>
#include <string_view>

namespace atonlab::runner {

/// The shortest decimal that reads back as the same double; "null" for NaN and ±inf.
std::string json_number(double v);
/// A JSON string literal, quotes included.
std::string json_string(std::string_view text);

}  // namespace atonlab::runner
