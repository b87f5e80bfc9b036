#pragma once
// What a study's stored scene says of its lights (docs/analysis.md, "The
// lights"): each [[light]]'s (and [[disc]]'s) colour, rhythm and spectrum as
// the scene file writes them, with a trial's overrides applied in order.
//
// analysis/ has no GL and no stimuli/ dependency, so the scene loader
// (stimuli::SceneTemplate) is not at hand. The runner has already checked the
// scene with these very overrides (it refuses a session otherwise), so this
// reads only the few keys a report names, with the common TOML parser, and
// applies the overrides as the loader does, with the loader's own addressing
// (common/scene_override.h element_address: "light.NAME.key" or
// "light[INDEX].key") and typed values (a value that is not TOML is a string,
// as for --set), later ones winning, and `colour`, `xy` and `spd` excluding
// each other.
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "atonlab/common/scene_override.h"

namespace atonlab::analysis {

/// One light as the report names it.
struct LightLook {
    /// An IALA name ("red"), "xy 0.31, 0.33", "spd NAME", "white" (the
    /// default), a chart letter's colour for one colour of an alternating
    /// light ("NAME/R": "red"), or "alternating W, R" for the whole light.
    std::string colour;
    /// The light character as written ("Fl(1) 4s"); "F" (fixed) by default;
    /// "steady" for a disc.
    std::string rhythm;
    /// The spectrum the light's glare is integrated over: the `spd` name the
    /// scene gives, else its IALA colour's representative spectrum ("iala-red"),
    /// "d65" for an `xy` colour; empty for a disc and an alternating light
    /// (each of its colours has its own; docs/glare.md "The light's spectrum").
    std::string spectrum;
    friend bool operator==(const LightLook&, const LightLook&) = default;
};

/// The stored scene text, parsed once.
class SceneLights {
public:
    /// Parses `scene_text` (TOML). std::nullopt, with `error` set, when it
    /// does not parse or its [[light]] array is not an array of tables.
    static std::optional<SceneLights> parse(std::string_view scene_text, std::string& error);

    /// Light (or disc) `name` with `overrides` (as stored in a trial's frame,
    /// read by SceneOverride::parse) applied in order. "NAME/LETTER" names one
    /// colour of an alternating light. std::nullopt: no light or disc has the name.
    std::optional<LightLook> look(std::string_view name, const std::vector<SceneOverride>& overrides) const;

private:
    struct Entry {
        std::string name;
        bool disc = false;
        std::string colour_key;    ///< "colour", "xy", "spd" or "" (none: white)
        std::string colour_value;  ///< the value as the report writes it
        std::string rhythm = "F";
    };
    std::vector<Entry> lights_, discs_;
};

}  // namespace atonlab::analysis
