#pragma once
// The scene file's reader, shared by its parts (scene_file.cpp: the whole
// file; scene_tables.cpp: [display], [camera], [environment], [eye], [glare]
// and [tonemap]; scene_profiles.cpp; scene_lights.cpp: [[light]] and [[disc]];
// scene_overrides.cpp: --set). Not installed.
#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <system_error>
#include <utility>

#include "atonlab/common/error_list.h"
#include "atonlab/common/input_error.h"
#include "atonlab/common/input_limits.h"
#include "atonlab/common/input_text.h"
#include "atonlab/common/toml_reader.h"
#include "atonlab/common/toml_text.h"
#include "atonlab/display/calibration.h"
#include "atonlab/display/colour.h"
#include "atonlab/stimuli/atmosphere.h"
#include "atonlab/stimuli/fft.h"
#include "atonlab/stimuli/glare_kernel.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/light_model.h"  // orientation_from_yaw_pitch_roll: the camera's convention
#include "atonlab/stimuli/profile.h"
#include "atonlab/stimuli/rhythm.h"
#include "atonlab/stimuli/scene.h"
#include "atonlab/stimuli/scene_file.h"

namespace atonlab::stimuli::scene_reader {
using namespace ::atonlab::display;  // NOLINT: colour, the display model, calibration files (display/)

inline constexpr std::string_view kSetOption = "--set";
// The source path of an override's value, "--set KEY" (SceneOverride's constructor).
inline constexpr std::string_view kSetPrefix = "--set ";

// ---------------------------------------------------------------------------
// The schema: the keys each table takes. Unknown keys are errors, so a typo
// ("intensity_cdd") is reported instead of silently taking a default.

using toml_reader::KeyList;

inline constexpr std::string_view kSections[] = {"display", "camera",   "environment", "eye", "glare",
                                                 "tonemap", "profiles", "light",       "disc"};
inline constexpr std::string_view kDisplayKeys[] = {
    "width_px",    "height_px", "width_m", "viewing_distance_m", "peak_cd_m2",  "black_cd_m2", "encoding", "transfer",
    "calibration", "bits",      "dither",  "dither_seed",        "out_of_gamut"};
inline constexpr std::string_view kCameraKeys[] = {"position_m", "yaw_deg", "pitch_deg", "roll_deg", "fov_deg"};
inline constexpr std::string_view kEnvironmentKeys[] = {"background",        "luminance_cd_m2", "visibility_nmi",
                                                        "extinction_per_km", "sea_reflectance", "spd"};
/// [eye]'s own keys; eye_keys() adds the glare models' (glare_model.h).
inline constexpr std::string_view kEyeOwnKeys[] = {"adaptation", "adaptation_cd_m2", "glare", "pupil_mm",
                                                   "adaptation_stride"};
inline constexpr std::string_view kTonemapKeys[] = {"operator",     "white_relative",
                                                    "reinhard_key", "reinhard_white_relative",
                                                    "kakimoto_g",   "kakimoto_k",
                                                    "white_cd_m2",  "display_adaptation_cd_m2",
                                                    "blueshift",    "blueshift_luminance",
                                                    "blueshift_xy", "hue_preservation",
                                                    "ldr_glare",    "mesopic"};
/// The [glare] keys every model shares (the glare stage's); glare_keys() adds each model's own.
inline constexpr std::string_view kSharedGlareKeys[] = {"psf_size",   "spectral_samples", "window",
                                                        "radius_deg", "area_layers",      "placement"};
/// The keys [eye] and [glare] take: their own, then each glare model's in the registry's order.
KeyList eye_keys();
KeyList glare_keys();
inline constexpr std::string_view kProfileKinds[] = {"vertical", "horizontal"};
inline constexpr std::string_view kVerticalKeys[] = {"elevation_deg", "relative"};
inline constexpr std::string_view kHorizontalKeys[] = {"sectors", "bearing_deg", "relative"};
inline constexpr std::string_view kSectorKeys[] = {"from_deg", "to_deg", "level", "edge_deg"};
inline constexpr std::string_view kLightKeys[] = {"name",
                                                  "position_m",
                                                  "intensity_cd",
                                                  "radius_m",
                                                  "colour",
                                                  "xy",
                                                  "spd",
                                                  "yaw_deg",
                                                  "pitch_deg",
                                                  "roll_deg",
                                                  "vertical_profile",
                                                  "horizontal_profile",
                                                  "sectors",
                                                  "rhythm",
                                                  "rhythm_phase_s",
                                                  "ramp_s",
                                                  "glare"};
inline constexpr std::string_view kDiscKeys[] = {"name",   "position_m", "diameter_deg", "luminance_cd_m2",
                                                 "colour", "xy",         "spd"};

/// Keys of which a table may hold at most one. An override that sets one of
/// them removes the others from its table, so "--set light.buoy.colour=red"
/// works on a light whose file gives xy.
inline const std::vector<std::vector<std::string_view>>& exclusive_groups() {
    static const std::vector<std::vector<std::string_view>> groups = {
        {"visibility_nmi", "extinction_per_km"},
        {"colour", "xy", "spd"},
        {"horizontal_profile", "sectors"},
    };
    return groups;
}

inline constexpr std::string_view kBuiltinVertical[] = {"uniform", "sabik-vp"};
inline constexpr std::string_view kBuiltinHorizontal[] = {"uniform"};
inline bool contains(KeyList list, std::string_view key) {
    return std::find(list.begin(), list.end(), key) != list.end();
}

template <typename Range>
std::string join(const Range& items, std::string_view quote = "'") {
    std::string s;
    for (const auto& item : items) {
        if (!s.empty()) s += ", ";
        s += fmt::format("{}{}{}", quote, item, quote);
    }
    return s;
}

using text::did_you_mean;
using text::type_phrase;
using toml_reader::number_text;

// ---------------------------------------------------------------------------
// Where a node came from: the scene file, or an override (common/toml_reader.h
// reads the values; this document says where an overridden one was written).

using toml_reader::Section;

class Document : public toml_reader::Document {
public:
    using toml_reader::Document::Document;

    /// Location of a node with its dotted schema key ("light[2].intensity_cd").
    SourceLocation where(const toml::node* node, const std::string& key) const override {
        if (node != nullptr) {
            const auto& path = node->source().path;
            if (path && path->starts_with(kSetPrefix)) return override_location(path->substr(kSetPrefix.size()), key);
            if (auto it = made_for_override_.find(node); it != made_for_override_.end())
                return override_location(it->second, key);
            if (node->source().begin.line > 0)
                return {file(), static_cast<int>(node->source().begin.line),
                        static_cast<int>(node->source().begin.column), key};
        }
        return {file(), 0, 0, key};
    }
    SourceLocation where(const toml::key& k, const std::string& key) const override {
        const auto& path = k.source().path;
        if (path && path->starts_with(kSetPrefix)) return override_location(path->substr(kSetPrefix.size()), key);
        return toml_reader::Document::where(k, key);
    }

protected:
    void relocate(SourceLocation& w, std::string& message) const override {
        // A type error in an override that was not valid TOML says so.
        if (w.from_command_line() && message.ends_with("got a string."))
            if (auto it = string_fallbacks_.find(w.key); it != string_fallbacks_.end())
                message = message.substr(0, message.size() - 1) + it->second + ".";
    }

public:
    /// Records an applied override: its key as typed and its schema key
    /// ("light.buoy.intensity_cd" -> "light[0].intensity_cd"), and where it
    /// was written when a file or an argument other than --set gave it
    /// (SceneOverride::origin: the Python module's `overrides`).
    void note_override(const std::string& typed, const std::string& schema_key, const SourceLocation& origin) {
        override_keys_[typed] = schema_key;
        if (origin.file.empty() && (origin.option.empty() || origin.option == kSetOption))
            origins_.erase(typed);
        else
            origins_[typed] = origin;
    }
    /// A table created to hold an override's value (it has no source of its own).
    void note_made_for_override(const toml::node* table, const std::string& typed) {
        made_for_override_[table] = typed;
    }
    /// An override whose value was not valid TOML and was read as a string.
    void note_string_fallback(const std::string& typed, const std::string& note) {
        if (note.empty())
            string_fallbacks_.erase(typed);
        else
            string_fallbacks_[typed] = note;
    }

private:
    // Errors in an overridden value name the override as typed; an error in an
    // element of it keeps the element's suffix ("light.buoy.sectors[1].from_deg").
    SourceLocation override_location(const std::string& typed, const std::string& schema_key) const {
        std::string key = typed;
        if (auto it = override_keys_.find(typed); it != override_keys_.end() && schema_key.starts_with(it->second))
            key += schema_key.substr(it->second.size());
        if (auto it = origins_.find(typed); it != origins_.end()) {
            if (it->second.file.empty()) return SourceLocation::command_line(it->second.option, key);
            return {it->second.file, it->second.line, it->second.column, key};
        }
        return SourceLocation::command_line(std::string(kSetOption), key);
    }

    std::map<std::string, std::string> override_keys_;
    std::map<std::string, SourceLocation> origins_;  // typed key -> where a file (or an argument) wrote it
    std::map<const toml::node*, std::string> made_for_override_;
    std::map<std::string, std::string> string_fallbacks_;
};

/// The sub-table `key` of `parent`, or nullptr when absent; an error when it is not a table.
inline const toml::table* sub_table(const Section& parent, std::string_view key, std::string_view as_written) {
    return parent.table(key, as_written);
}

/// A [x, y, z] array as a vector.
inline std::optional<glm::dvec3> vec3(const Section& s, std::string_view key) {
    auto v = s.numbers(key, 3);
    if (!v) return std::nullopt;
    return glm::dvec3((*v)[0], (*v)[1], (*v)[2]);
}

inline double wrap_degrees(double deg) {
    double r = std::fmod(deg, 360.0);
    if (r < 0) r += 360.0;
    return r;
}

// ---------------------------------------------------------------------------
// Profiles: parsed from [profiles.*], deduplicated into Scene::profiles by
// table content (index 0 of each list is the uniform profile).

template <typename Profile>
int intern(std::vector<Profile>& list, Profile profile) {
    for (std::size_t i = 0; i < list.size(); ++i)
        if (list[i].table == profile.table) return static_cast<int>(i);
    list.push_back(std::move(profile));
    return static_cast<int>(list.size() - 1);
}

struct Profiles {
    std::map<std::string, VerticalProfile, std::less<>> vertical;
    std::map<std::string, HorizontalProfile, std::less<>> horizontal;
};

Profiles read_profiles(const Document& doc, const Section& root);
VerticalProfile builtin_vertical(std::string_view name);
HorizontalProfile horizontal_from_sectors(const Section& s, const std::vector<Sector>& sectors);
std::vector<Sector> read_sectors(const Document& doc, const Section& owner, std::string_view key);

// ---------------------------------------------------------------------------
// The tables (scene_tables.cpp).

DisplayGeometry read_display(const Document& doc, const Section& root);
Camera read_camera(const Document& doc, const Section& root);
Environment read_environment(const Document& doc, const Section& root);
/// [eye]: returns the fixed adaptation luminance, cd/m².
double read_eye(const Document& doc, const Section& root, const Environment& environment, GlareSettings& glare,
                AdaptationSettings& adapt);
/// A light's or the scene's own glare model name, if given.
std::optional<GlareModel> read_glare_model(const Section& s);
void read_glare(const Document& doc, const Section& root, GlareSettings& g, double pupil_mm);
void read_output(const Document& doc, const Section& root, OutputSettings& out);

// ---------------------------------------------------------------------------
// Lights and discs (scene_lights.cpp).

/// Every [[light]] (when the profiles were read) and [[disc]]; each light's
/// error is kept in `errors` and the reading goes on.
void read_lights_and_discs(const Document& doc, const Section& root, Scene& scene, const Profiles& profiles,
                           bool profiles_read, text::ErrorList& errors);
/// The glare billboard fits the display (GL-free, naming the keys).
void check_billboard(const Document& doc, const Section& root, const Scene& scene);

// ---------------------------------------------------------------------------
// Overrides (scene_overrides.cpp).

/// The changes overrides make to a template's tree, undone (newest first) when
/// it goes out of scope, so that the tree is the file's again: a template is
/// parsed once and every scene is made from the same tree. A replaced or
/// erased node is moved aside, never copied, because toml++ keeps a node's
/// source line when it is moved and drops it when it is copied, and every
/// later error must name the file's line.
class TreeEdits {
public:
    TreeEdits() = default;
    TreeEdits(const TreeEdits&) = delete;
    TreeEdits& operator=(const TreeEdits&) = delete;
    ~TreeEdits() { undo(); }

    /// table[key] = value, the value moved out of `value`.
    void assign(toml::table& table, std::string_view key, toml::node& value);
    /// Removes table[key] when present.
    void erase(toml::table& table, std::string_view key);
    /// An empty table made at parent[key], which must be absent.
    toml::table& insert_table(toml::table& parent, std::string_view key);
    /// Restores every change, newest first.
    void undo() noexcept;

private:
    /// Moves table[key] aside (when present) and records the change.
    void save(toml::table& table, std::string_view key);
    struct Edit {
        toml::table* table = nullptr;
        toml::key key;      ///< as the table held it (with its source), or as made
        toml::table saved;  ///< "v": the node it held; empty when the key was absent
    };
    std::vector<Edit> edits_;
};

/// Applies one override to the parsed tree (each change recorded in `edits`),
/// type-checked against the value it replaces.
void apply_override(Document& doc, toml::table& root, const SceneOverride& o, TreeEdits& edits);

}  // namespace atonlab::stimuli::scene_reader
