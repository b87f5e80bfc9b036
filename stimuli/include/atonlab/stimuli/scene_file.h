#pragma once
// The scene file (TOML; docs/architecture.md "Units and colour"; every key in docs/scene-file.md).
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/common/scene_override.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli {

/// An override "section.key=value" (value in TOML syntax: 250, 1.5, "red",
/// [0, 2, -100], true) and where it was written (common/scene_override.h).
/// Keys inside the [[light]] array are named "light.NAME.key" (by the light's
/// name) or "light[INDEX].key"; [[disc]] likewise.
using SceneOverride = ::atonlab::SceneOverride;

/// A scene file read and parsed once, from which scenes are made with
/// different overrides: a protocol's conditions change a few keys of one
/// template per frame. Copies share the parsed file; instantiate() may be
/// called from several threads (one at a time makes its scene).
class SceneTemplate {
public:
    /// Parses `toml_text` (file_label names it in errors). Throws InputError
    /// for a TOML syntax error; the schema is checked by instantiate().
    static SceneTemplate parse(std::string_view toml_text, std::string_view file_label);
    /// Reads and parses a scene file (up to text::kMaxInputFileBytes).
    static SceneTemplate load(const std::filesystem::path& file);

    /// The scene with `overrides` applied in order, validated as load_scene does.
    Scene instantiate(const std::vector<SceneOverride>& overrides = {}) const;
    const std::string& file_label() const noexcept;

private:
    struct Parsed;
    explicit SceneTemplate(std::shared_ptr<const Parsed> parsed) : parsed_(std::move(parsed)) {}
    std::shared_ptr<const Parsed> parsed_;
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
