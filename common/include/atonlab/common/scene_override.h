#pragma once
// One scene override: a dotted scene key, its value, and where it was written.
// The one form in which a value reaches the scene loader, whether `--set` gave
// it (render, view), a protocol's line (a condition's `set`, its [display]
// table) or the protocol library made it (a procedure level, a side-by-side
// position). Errors about the value name its origin (docs/scene-file.md
// "Overrides with --set").
//
// The value is parsed once, when the override is made (toml_value.h): the
// scene loader applies the typed value; the text stays for the stored form
// (`text()`, the study file's bytes) and for messages.
#include <optional>
#include <string>
#include <string_view>

#include "atonlab/common/input_error.h"
#include "atonlab/common/toml_value.h"

namespace atonlab {

/// One "key=value" as a person wrote it: a `--set`, a protocol's `set` line,
/// a stored override, `check --set`, `simulate --observer` and `--protocol-set`.
/// The one reader of that form: split at the first '=', blanks around the key
/// and the value trimmed, the value parsed once (toml_value.h).
struct KeyValue {
    std::string key;
    std::string text;  ///< the value as written (trimmed)
    /// The TOML value, or the text as a string when it is not one (not_toml
    /// then says why); nullopt when it cannot be read even as a string
    /// (unreadable says why).
    std::optional<TomlValue> value;
    std::string not_toml;
    std::string unreadable;
};
/// nullopt when `text` has no '='. `source`: the values' nodes' source path.
std::optional<KeyValue> read_key_value(std::string_view text, std::string_view source = {});

struct SceneOverride {
    std::string key;    ///< dotted scene key: "eye.glare", "light.buoy.intensity_cd", "light[0].rhythm"
    /// The value's TOML text as written: "\"none\"", "120", "[0.0, 3.0, -500.0]".
    /// Set by the constructor and not changed after it: typed() was parsed from it.
    std::string value;
    /// Where the value was written: a file, line and column (a protocol's
    /// line; the key there, e.g. "block[0].condition[1].set[0]"), or the
    /// command-line option "--set". Errors about the value name it.
    SourceLocation origin = SourceLocation::command_line(std::string(kSetOption));

    /// The `--set` option's name.
    static constexpr std::string_view kSetOption = "--set";

    SceneOverride() = default;
    /// Parses `value`. Text that is not one TOML value is taken as a string
    /// (so `--set light.buoy.colour=red` needs no quotes); not_toml() says why.
    SceneOverride(std::string key, std::string value,
                  SourceLocation origin = SourceLocation::command_line(std::string(kSetOption)));

    /// The value: the TOML value, or the text as a string when it is not one
    /// (not_toml() is then set). nullptr when it cannot be read even as a
    /// string (unreadable() says why), or for a default-made override. Its
    /// nodes' source path is "--set KEY".
    const TomlValue* typed() const noexcept { return typed_ ? &*typed_ : nullptr; }
    /// Why the text is not one TOML value (toml++'s description); "" when it is.
    const std::string& not_toml() const noexcept { return not_toml_; }
    /// Why the text cannot be read even as a string; "" when it can.
    const std::string& unreadable() const noexcept { return unreadable_; }

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

private:
    std::optional<TomlValue> typed_;
    std::string not_toml_;
    std::string unreadable_;
};

/// What an override of a [[light]] or [[disc]] table addresses: "ARRAY.NAME.KEY"
/// or "ARRAY[INDEX].KEY" (NAME may hold dots; KEY, after the last dot, never
/// does). The one reading of this addressing: the scene loader applies
/// overrides with it and the analysis names a trial's lights with it.
struct ElementAddress {
    std::optional<std::size_t> index;  ///< ARRAY[INDEX]; nullopt: by name
    std::string name;                  ///< ARRAY.NAME; empty when by index
    std::string key;                   ///< the key inside the element
};
/// The address `key` gives in `array` ("light", "disc"). nullopt when it is
/// not one: `key` does not start with "ARRAY." or "ARRAY[", has no key after
/// its last dot, or an index that is not 1 to 6 digits closed by "]." .
std::optional<ElementAddress> element_address(std::string_view key, std::string_view array);

}  // namespace atonlab
