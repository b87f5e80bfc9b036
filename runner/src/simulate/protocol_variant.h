#pragma once
// A protocol with keys set from the command line (`atonlab simulate --set`
// and `--vary`, docs/simulate.md): the file's TOML tree with each KEY set to
// its VALUE (typed by TomlValue, the one place text becomes a value), written
// out again as the design's protocol text, which each of its sessions stores.
#include <string>
#include <string_view>
#include <vector>

namespace atonlab::runner {

/// One protocol key set to one value: "defaults.procedure.max_trials=40".
/// A bare key ("max_trials=40") is the [defaults.procedure] key.
struct ProtocolSet {
    std::string key;    ///< the dotted path, bare keys expanded
    std::string value;  ///< the TOML text of the value
    std::string text() const { return key + "=" + value; }
};

/// "KEY=VALUE" read; throws InputError naming `option` when there is no '=',
/// the key is empty or the value is not one TOML value.
ProtocolSet parse_protocol_set(std::string_view text, std::string_view option);

/// "KEY=v1,v2,…" (`--vary`): one ProtocolSet per value, commas inside
/// brackets, braces and quotes kept. Throws InputError naming --vary.
std::vector<ProtocolSet> parse_vary(std::string_view text);

/// The protocol text with every set applied in order (tables created where
/// absent). The original text unchanged when `sets` is empty. Throws
/// InputError naming `option` when a key runs into a value that is not a
/// table, or the text is not TOML (the protocol reader says where).
std::string protocol_with(const std::string& text, std::string_view file_label, const std::vector<ProtocolSet>& sets,
                          std::string_view option);

}  // namespace atonlab::runner
