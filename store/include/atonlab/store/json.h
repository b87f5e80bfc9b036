#pragma once
// The JSON text atonlab keeps (a calibration's fit_json, a check's
// results_json, a session's displayability_json, a trial's stimulus_json) and
// writes (the analysis's summary.json), through one library, nlohmann::json.
// Callers build and walk nlohmann::json themselves; what lives here is what
// every one of them must do the same way: refuse invalid text with a
// StoreError naming it, write non-finite numbers as null and read null back as
// "no number", and never throw on a byte that is not UTF-8.
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <string_view>

namespace atonlab::store {

/// Parses `text`. Throws StoreError (invalid_argument) when it is not valid JSON
/// (RFC 8259); `what` names the text in that message ("fit_json of calibration 3
/// is not valid JSON (at byte 5: ...)").
nlohmann::json parse_json(std::string_view text, std::string_view what = "the JSON text");

/// The JSON text of `j`: compact with `indent` < 0, else one member per line.
/// Keys keep the order they were added in (ordered_json); numbers are a
/// decimal that reads back as the same double (Grisu2: nearly always the
/// shortest); NaN and ±inf are written as null (JSON has no such numbers); a
/// byte that is not UTF-8 is written as U+FFFD instead of throwing (an
/// instrument's transcript may hold one).
std::string dump_json(const nlohmann::ordered_json& j, int indent = -1);

// Reading a value that may be absent. `at` is a JSON pointer (RFC 6901):
// "/display/channels/1/gamma"; "" is the whole document.

/// The value at `at`, or nullptr when there is none.
const nlohmann::json* json_at(const nlohmann::json& j, std::string_view at);
/// The number at `at` (an integer or a real), or nullopt when absent, null (a
/// non-finite number as written) or something else.
std::optional<double> number_at(const nlohmann::json& j, std::string_view at);
/// The string at `at`, or nullopt when absent or not a string.
std::optional<std::string> string_at(const nlohmann::json& j, std::string_view at);
/// true / false at `at`, or nullopt when absent or not a boolean.
std::optional<bool> boolean_at(const nlohmann::json& j, std::string_view at);
/// The array at `at`; an empty array when absent or not an array (so a caller
/// can loop over it without checking first).
const nlohmann::json& array_at(const nlohmann::json& j, std::string_view at);

}  // namespace atonlab::store
