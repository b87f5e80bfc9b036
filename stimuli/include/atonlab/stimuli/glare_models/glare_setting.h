#pragma once
// A glare model's settings, as the model declares them (docs/architecture.md
// "How to add a glare model"): each key of [glare] or [eye] that only one
// model reads, with its default, its check and its documentation line. The
// scene reader, `--set`, `atonlab glare`'s options, the Python module and the
// glare stage's kernel cache key all read these declarations; nothing else
// lists a model's keys.
//
// Where a value lives: a model with a typed home for its settings (the
// wave-optics eye model, eye_model.h, which the pupil and hippus code share)
// reads them itself and gives each one's value as text (typed_text); every
// other model's values live in GlareSettings::values, set by the scene reader
// from the declaration (default_value's type is the key's type) and read back
// with glare_number / glare_flag / glare_text.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "atonlab/common/toml_value.h"

namespace atonlab::stimuli {

struct GlareSettings;

/// The scene file's table a setting is a key of.
enum class GlareTable : std::uint8_t { glare, eye };
std::string_view glare_table_name(GlareTable t);

/// A declared setting's value: a TOML boolean, number or string.
using GlareSettingValue = std::variant<bool, double, std::string>;

/// The values of the declared settings a file or an option gave (absent: the declared default).
using GlareSettingValues = std::map<std::string, GlareSettingValue, std::less<>>;

struct GlareSetting {
    std::string_view key{};                ///< as the scene file spells it
    GlareTable table = GlareTable::glare;  ///< [glare] or [eye]
    std::string_view type{};               ///< docs/scene-file.md's type column: "number", "bool", "string", "integer"
    std::string_view unit{};               ///< docs/scene-file.md's unit column: "°", "mm", "—"
    std::string_view default_text{};       ///< docs/scene-file.md's default column, as written there
    std::string_view doc{};                ///< one line: docs/scene-file.md's meaning column and help texts
    /// The TOML text of a valid value other than the default: an example for
    /// help texts, and the value the tests set it to, one setting at a time,
    /// to see the kernel's cache key change.
    std::string_view example{};
    /// A setting stored in GlareSettings::values: its default (nullopt: none,
    /// the model reads it as absent) and its check (nullptr: any value of its
    /// type), returning an error message, empty when the value is valid.
    std::optional<GlareSettingValue> default_value{};
    std::string (*check)(const GlareSettingValue&) = nullptr;
    /// A setting with a typed home: its value in g, as text (the kernel cache key).
    std::string (*typed_text)(const GlareSettings& g) = nullptr;
};

/// A stored setting's value in g, else its declared default (InputError naming
/// the key when neither: a model must declare a default for what it reads).
double glare_number(const GlareSettings& g, std::string_view key);
bool glare_flag(const GlareSettings& g, std::string_view key);
std::string glare_text(const GlareSettings& g, std::string_view key);

/// A setting's value in g as text: its typed_text, else its stored value or
/// default ("" when it has neither), with its type: the kernel cache key's part.
std::string glare_setting_text(const GlareSettings& g, const GlareSetting& s);

/// The declared setting `key` of [table] of any model; nullptr when no model declares it.
const GlareSetting* find_glare_setting(GlareTable table, std::string_view key);

/// Settings given outside a scene file (`atonlab glare`'s options, the
/// Python module's keywords), by key: each is read and checked by its model
/// as the scene reader reads [glare] and [eye] (pupil_mm: the pupil the eye
/// model's checks use). An InputError's location names the key; a key no
/// model declares, or a value that is not a boolean, number or string, is
/// refused.
void apply_glare_settings(const std::map<std::string, TomlValue, std::less<>>& given, GlareSettings& g,
                          double pupil_mm);

/// "--bloom-sigma-deg" for bloom_sigma_deg: the option `atonlab glare` reads it from.
std::string glare_setting_option(std::string_view key);

}  // namespace atonlab::stimuli
