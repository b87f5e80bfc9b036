#pragma once
// The protocol file (TOML; every key in docs/protocol-file.md). Strict like the
// scene file: unknown keys, wrong types, impossible values and procedures
// without a stop rule are InputErrors naming the file, the line and the key,
// in one sentence ("glare.toml:42: key 'block[0].condition[1].procedure.step_sizes':
// in condition \"dark-empirical\", step_sizes must be a finite number > 0, not -0.1.").
#include <filesystem>
#include <string_view>

#include "atonlab/protocols/protocol.h"

namespace atonlab::protocols {

/// Reads and validates a protocol file; the scene path is resolved against the
/// file's folder and must name an existing file. Throws InputError.
Protocol load_protocol(const std::filesystem::path& file);

/// The same from text; file_name is used in messages and to resolve the scene
/// path (its folder), which is not checked for existence. Throws InputError.
Protocol parse_protocol(std::string_view toml_text, std::string_view file_name);

/// The protocol file's `text` with the text of each conditions file its blocks
/// name (conditions_file, relative to `protocol_file`) appended as comment lines
/// ("#@conditions_file NAME", then "#@|LINE" per line of the CSV): what a study
/// stores, so that parse_protocol() of the stored text finds the rows when the
/// CSV itself is not at hand. `text` unchanged when it names none (or one
/// cannot be read: load_protocol reports that).
std::string with_conditions_files(std::string_view text, const std::filesystem::path& protocol_file);

}  // namespace atonlab::protocols
