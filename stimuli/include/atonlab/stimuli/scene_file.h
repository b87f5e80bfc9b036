#pragma once
// The scene file (TOML; docs/architecture.md "Units and colour"; every key in docs/scene-file.md).
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli {

/// A command-line override "section.key=value" (value in TOML syntax: 250,
/// 1.5, "red", [0, 2, -100], true). Keys inside the [[light]] array are named
/// "light.NAME.key" (by the light's name) or "light[INDEX].key".
struct SceneOverride {
    std::string key;
    std::string value;
    /// Where the value was written when it comes from a file (a protocol's
    /// [display] key): errors about the value then name that file and line.
    /// Empty file: the command line, and errors name "--set KEY".
    SourceLocation origin;
    /// Parses "key=value"; throws InputError for a missing '=' or an empty key.
    static SceneOverride parse(std::string_view text);
};

/// Loads and validates a scene file, applying overrides in order (each one
/// type-checked like the file: the value must have the type the key takes).
/// Throws InputError naming the file, line and key (or "--set KEY") for: syntax
/// errors, unknown keys, missing required keys, wrong types, unknown colour or
/// SPD names, invalid rhythms, negative/NaN/inf values where not allowed.
Scene load_scene(const std::filesystem::path& file, const std::vector<SceneOverride>& overrides = {});

/// The same from text (file_label is used in error messages).
Scene parse_scene(std::string_view toml_text, std::string_view file_label,
                  const std::vector<SceneOverride>& overrides = {});

}  // namespace atonlab::stimuli
