#pragma once
// One scene override: a dotted scene key, a value in TOML syntax, and where it
// was written. The one form in which a value reaches the scene loader, whether
// `--set` gave it (render, view), a protocol's line (a condition's `set`, its
// [display] table) or the protocol library made it (a procedure level, a
// side-by-side position). Errors about the value name its origin
// (docs/scene-file.md "Overrides with --set").
#include <string>
#include <string_view>

#include "atonlab/common/input_error.h"

namespace atonlab {

struct SceneOverride {
    std::string key;    ///< dotted scene key: "eye.glare", "light.buoy.intensity_cd", "light[0].rhythm"
    std::string value;  ///< TOML value text: "\"none\"", "120", "[0.0, 3.0, -500.0]"
    /// Where the value was written: a file, line and column (a protocol's
    /// line; the key there, e.g. "block[0].condition[1].set[0]"), or the
    /// command-line option "--set". Errors about the value name it.
    SourceLocation origin = SourceLocation::command_line(std::string(kSetOption));

    /// The `--set` option's name.
    static constexpr std::string_view kSetOption = "--set";

    /// "key=value", as `--set` takes it and the study file stores it.
    std::string text() const { return key + "=" + value; }
    /// Parses `--set` text "key=value" (spaces around both trimmed; the value
    /// is everything after the first '='). Throws InputError for a missing '='
    /// or an empty key. The origin is "--set KEY".
    static SceneOverride parse(std::string_view text);
    /// The same key, value and origin.
    friend bool operator==(const SceneOverride& a, const SceneOverride& b) {
        const SourceLocation& x = a.origin;
        const SourceLocation& y = b.origin;
        return a.key == b.key && a.value == b.value && x.file == y.file && x.line == y.line &&
               x.column == y.column && x.key == y.key && x.option == y.option && x.key_is_column == y.key_is_column;
    }
};

}  // namespace atonlab
