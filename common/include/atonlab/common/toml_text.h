#pragma once
// Sentences about TOML input, shared by the scene file (stimuli) and the
// protocol file (protocols) so both say things the same way.
#include <toml++/toml.h>

#include <span>
#include <string>
#include <string_view>

namespace atonlab::text {

/// Levenshtein distance between two keys.
std::size_t edit_distance(std::string_view a, std::string_view b);

/// " Did you mean 'x'?" for the allowed key that `key` is a unit-less prefix of
/// ("yaw" → "yaw_deg") or the nearest within two edits; "" when none is close.
std::string did_you_mean(std::string_view key, std::span<const std::string_view> allowed);

/// "a string", "an integer", ... for a TOML node type, as sentences use it.
std::string_view type_phrase(toml::node_type type);

}  // namespace atonlab::text
