// The scene file (scene_file.h; every key documented in docs/scene-file.md).
//
// Three steps: parse the TOML text (syntax errors keep the parser's line),
// apply the --set overrides to the parsed tree, then validate the tree against
// the schema while building the Scene. Every value's error names the file,
// line and dotted key; a value that came from --set names "--set KEY" instead
// (override values are parsed with the source path "--set KEY", and toml++
// keeps a node's source when it is moved into the scene's tree).
#include "atonlab/stimuli/scene_file.h"

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

#include "atonlab/stimuli/atmosphere.h"
#include "atonlab/common/error_list.h"
#include "atonlab/common/input_limits.h"
#include "atonlab/common/input_text.h"
#include "atonlab/common/toml_reader.h"
#include "atonlab/common/toml_text.h"
#include "atonlab/stimuli/calibration.h"
#include "atonlab/stimuli/colour.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/fft.h"
#include "atonlab/stimuli/glare_kernel.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/light_model.h"  // orientation_from_yaw_pitch_roll: the camera's convention
#include "atonlab/stimuli/profile.h"
#include "atonlab/stimuli/rhythm.h"

namespace atonlab::stimuli {
namespace {

constexpr std::string_view kSetOption = "--set";
constexpr std::string_view kSetPrefix = "--set ";  // source path of an override's value: "--set KEY"

// ---------------------------------------------------------------------------
// The schema: the keys each table takes. Unknown keys are errors, so a typo
// ("intensity_cdd") is reported instead of silently taking a default.

using toml_reader::KeyList;

constexpr std::string_view kSections[] = {"display", "camera", "environment", "eye", "glare", "tonemap", "profiles", "light",
                                           "disc"};
constexpr std::string_view kDisplayKeys[] = {"width_px",   "height_px",   "width_m",     "viewing_distance_m",
                                             "peak_cd_m2", "black_cd_m2", "transfer",    "calibration",
                                             "bits",       "dither",      "dither_seed"};
constexpr std::string_view kCameraKeys[] = {"position_m", "yaw_deg", "pitch_deg", "roll_deg", "fov_deg"};
constexpr std::string_view kEnvironmentKeys[] = {"background", "luminance_cd_m2", "visibility_nmi", "extinction_per_km",
                                                 "sea_reflectance"};
constexpr std::string_view kEyeKeys[] = {"adaptation", "adaptation_cd_m2", "glare", "pupil_mm", "adaptation_stride",
                                         "cie_age_years", "cie_pigmentation"};
constexpr std::string_view kTonemapKeys[] = {
    "operator", "white_relative", "reinhard_key", "reinhard_white_relative", "kakimoto_g", "kakimoto_k",
    "white_cd_m2", "display_adaptation_cd_m2", "blueshift", "blueshift_luminance", "blueshift_xy", "hue_preservation",
    "ldr_glare"};
constexpr std::string_view kGlareKeys[] = {
    "psf_size", "spectral_samples", "spectral_path", "spectral_anchors", "window", "radius_deg", "area_layers",
    "bloom_sigma_deg", "spencer_vision", "aperture_image", "aperture_width_mm", "aperture_with_pupil", "eye_preset",
    "seed", "halo_radius_deg", "plane_width_mm", "defocus_diopters", "supersampling", "clear_pupil", "hippus",
    "hippus_amplitude", "gratings", "grating_count", "grating_inner_radius_mm", "grating_width_um", "grating_opacity",
    "lens_particles", "lens_particle_count", "lens_particle_diameter_um", "vitreous_particles",
    "vitreous_particle_count", "vitreous_particle_diameter_um", "eyelashes", "eyelash_count", "eyelash_width_um",
    "eyelid", "eyelid_edge_mm"};
constexpr std::string_view kProfileKinds[] = {"vertical", "horizontal"};
constexpr std::string_view kVerticalKeys[] = {"elevation_deg", "relative"};
constexpr std::string_view kHorizontalKeys[] = {"sectors", "bearing_deg", "relative"};
constexpr std::string_view kSectorKeys[] = {"from_deg", "to_deg", "level", "edge_deg"};
constexpr std::string_view kLightKeys[] = {
    "name",    "position_m", "intensity_cd",   "radius_m", "colour",           "xy",
    "spd",     "yaw_deg",    "pitch_deg",      "roll_deg", "vertical_profile", "horizontal_profile",
    "sectors", "rhythm",     "rhythm_phase_s", "ramp_s",   "glare"};
constexpr std::string_view kDiscKeys[] = {"name",   "position_m", "diameter_deg", "luminance_cd_m2",
                                          "colour", "xy",         "spd"};

/// Keys of which a table may hold at most one. An override that sets one of
/// them removes the others from its table, so "--set light.buoy.colour=red"
/// works on a light whose file gives xy.
const std::vector<std::vector<std::string_view>>& exclusive_groups() {
    static const std::vector<std::vector<std::string_view>> groups = {
        {"visibility_nmi", "extinction_per_km"},
        {"colour", "xy", "spd"},
        {"horizontal_profile", "sectors"},
    };
    return groups;
}

constexpr std::string_view kBuiltinVertical[] = {"uniform", "sabik-vp"};
constexpr std::string_view kBuiltinHorizontal[] = {"uniform"};
bool contains(KeyList list, std::string_view key) {
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
        if (w.option == kSetOption && message.ends_with("got a string."))
            if (auto it = string_fallbacks_.find(w.key); it != string_fallbacks_.end())
                message = message.substr(0, message.size() - 1) + it->second + ".";
    }

public:

    /// Records an applied override: its key as typed and its schema key
    /// ("light.buoy.intensity_cd" -> "light[0].intensity_cd"), and where it
    /// was written when a file gave it (SceneOverride::origin).
    void note_override(const std::string& typed, const std::string& schema_key, const SourceLocation& origin) {
        override_keys_[typed] = schema_key;
        if (origin.file.empty())
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
        if (auto it = origins_.find(typed); it != origins_.end())
            return {it->second.file, it->second.line, it->second.column, key};
        return SourceLocation::command_line(std::string(kSetOption), key);
    }

    std::map<std::string, std::string> override_keys_;
    std::map<std::string, SourceLocation> origins_;  // typed key -> where a file wrote it
    std::map<const toml::node*, std::string> made_for_override_;
    std::map<std::string, std::string> string_fallbacks_;
};

/// The sub-table `key` of `parent`, or nullptr when absent; an error when it is not a table.
const toml::table* sub_table(const Section& parent, std::string_view key, std::string_view as_written) {
    return parent.table(key, as_written);
}

/// A [x, y, z] array as a vector.
std::optional<glm::dvec3> vec3(const Section& s, std::string_view key) {
    auto v = s.numbers(key, 3);
    if (!v) return std::nullopt;
    return glm::dvec3((*v)[0], (*v)[1], (*v)[2]);
}

double wrap_degrees(double deg) {
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

/// Chart sector limits are bearings *from seaward*: the bearing on which an
/// observer sees the light. profile.h's Sector takes bearings from the light
/// towards the observer, which are the reciprocal: add 180°. Clockwise order
/// is kept, so "from 090 to 180" becomes "from 270 to 360".
Sector sector_from_seaward(double from_deg, double to_deg, double level, double edge_deg) {
    double span = to_deg - from_deg;
    if (span < 0) span += 360.0;  // the sector runs clockwise through north
    Sector s;
    s.level = level;
    s.edge_deg = edge_deg;
    if (span >= 360.0) {
        s.from_deg = 0.0;
        s.to_deg = 360.0;
        return s;
    }
    s.from_deg = wrap_degrees(from_deg + 180.0);
    s.to_deg = s.from_deg + span;  // from_sectors takes to > 360 as running on through 0°
    return s;
}

/// profile.h's checks throw InputError without a location; the file's checks
/// come first, so these only fire for what they missed.
HorizontalProfile horizontal_from_sectors(const Section& s, const std::vector<Sector>& sectors) {
    try {
        return HorizontalProfile::from_sectors(sectors);
    } catch (const InputError& e) {
        s.fail(s.get("sectors"), "sectors", e.message());
    }
}

std::vector<Sector> read_sectors(const Document& doc, const Section& owner, std::string_view key) {
    const toml::node* n = owner.get(key);
    if (!n->is_array() || n->as_array()->empty())
        owner.fail(n, key,
                   fmt::format("expected an array of sector tables like [{{ from_deg = 90, to_deg = 180 }}], got {}.",
                               n->is_array() ? "an empty array" : type_phrase(n->type())));
    std::vector<Sector> sectors;
    const toml::array& a = *n->as_array();
    for (std::size_t i = 0; i < a.size(); ++i) {
        const std::string element = fmt::format("{}[{}]", key, i);
        const toml::node* e = a.get(i);
        if (!e->is_table())
            owner.fail(e, element,
                       fmt::format("expected a sector table like {{ from_deg = 90, to_deg = 180 }}, got {}.",
                                   type_phrase(e->type())));
        Section s(doc, *e->as_table(), owner.key_path(element), fmt::format("sector {}", owner.key_path(element)));
        s.allow(kSectorKeys);
        const double from = s.required_number("from_deg", "bearing from seaward where the sector starts, degrees");
        const double to = s.required_number("to_deg", "bearing from seaward where the sector ends, clockwise, degrees");
        s.within("from_deg", from, 0.0, 360.0);
        s.within("to_deg", to, 0.0, 360.0);
        if (from == to)
            s.fail(s.get("to_deg"), "to_deg",
                   "to_deg equals from_deg: the sector is empty (use 0 and 360 for all round).");
        const double level = s.number_or("level", 1.0);
        s.at_least("level", level, 0.0);
        const double edge = s.number_or("edge_deg", 0.0);
        s.within("edge_deg", edge, 0.0, 90.0);
        sectors.push_back(sector_from_seaward(from, to, level, edge));
    }
    return sectors;
}

/// Two equal-length arrays: the first strictly increasing within [lo, hi), the second >= 0.
std::pair<std::vector<double>, std::vector<double>> read_table_pair(const Section& s, std::string_view angle_key,
                                                                    double lo, double hi, bool hi_inclusive,
                                                                    std::string_view what) {
    if (!s.has(angle_key)) s.missing(angle_key, what);
    if (!s.has("relative")) s.missing("relative", "relative intensities, one per angle, each >= 0");
    std::vector<double> angles = *s.numbers(angle_key, 0, 2);
    std::vector<double> relative = *s.numbers("relative", 0, 2);
    if (angles.size() != relative.size())
        s.fail(s.get("relative"), "relative",
               fmt::format("relative has {} values but {} has {}; they must have the same length.", relative.size(),
                           angle_key, angles.size()));
    const toml::array& angle_nodes = *s.get(angle_key)->as_array();
    const toml::array& relative_nodes = *s.get("relative")->as_array();
    for (std::size_t i = 0; i < angles.size(); ++i) {
        const std::string ak = fmt::format("{}[{}]", angle_key, i);
        if (angles[i] < lo || angles[i] > hi || (!hi_inclusive && angles[i] == hi))
            s.fail(angle_nodes.get(i), ak,
                   fmt::format("{} must be in [{}, {}{}, got {}.", ak, number_text(lo), number_text(hi),
                               hi_inclusive ? "]" : ")", number_text(angles[i])));
        if (i > 0 && !(angles[i] > angles[i - 1]))
            s.fail(angle_nodes.get(i), ak,
                   fmt::format("{} must be sorted in increasing order, but {} follows {}.", angle_key,
                               number_text(angles[i]), number_text(angles[i - 1])));
        const std::string rk = fmt::format("relative[{}]", i);
        if (relative[i] < 0)
            s.fail(relative_nodes.get(i), rk,
                   fmt::format("{} must be at least 0, got {}.", rk, number_text(relative[i])));
    }
    return {std::move(angles), std::move(relative)};
}

VerticalProfile read_vertical_profile(const Section& s) {
    s.allow(kVerticalKeys);
    auto [elevation, relative] = read_table_pair(s, "elevation_deg", -90.0, 90.0, true,
                                                 "elevations in degrees, -90 (down) to 90 (up), increasing");
    try {
        return VerticalProfile::from_elevation_table(elevation, relative);
    } catch (const InputError& e) {
        s.fail_table(e.message());
    }
}

HorizontalProfile read_horizontal_profile(const Document& doc, const Section& s) {
    s.allow(kHorizontalKeys);
    const bool has_sectors = s.has("sectors");
    const bool has_table = s.has("bearing_deg") || s.has("relative");
    if (has_sectors && has_table)
        s.fail(s.get("sectors"), "sectors", "give either sectors or bearing_deg and relative, not both.");
    if (has_sectors) {
        return horizontal_from_sectors(s, read_sectors(doc, s, "sectors"));
    }
    if (!has_table) s.fail_table(fmt::format("{} needs either sectors or bearing_deg and relative.", s.title()));
    auto [bearing, relative] =
        read_table_pair(s, "bearing_deg", 0.0, 360.0, false, "bearings from seaward in degrees, 0 to 360, increasing");
    // Bearings from seaward -> bearings from the light (+180°), re-sorted so the
    // periodic table still starts at its smallest bearing.
    std::vector<std::pair<double, double>> rows;
    for (std::size_t i = 0; i < bearing.size(); ++i) rows.emplace_back(wrap_degrees(bearing[i] + 180.0), relative[i]);
    std::sort(rows.begin(), rows.end());
    for (std::size_t i = 0; i < rows.size(); ++i) {
        bearing[i] = rows[i].first;
        relative[i] = rows[i].second;
    }
    try {
        return HorizontalProfile::from_bearing_table(bearing, relative);
    } catch (const InputError& e) {
        s.fail_table(e.message());
    }
}

VerticalProfile builtin_vertical(std::string_view name) {
    if (name == "sabik-vp") return sabik_vp_vertical_profile();
    return VerticalProfile::uniform();
}

struct Profiles {
    std::map<std::string, VerticalProfile, std::less<>> vertical;
    std::map<std::string, HorizontalProfile, std::less<>> horizontal;
};

Profiles read_profiles(const Document& doc, const Section& root) {
    Profiles out;
    const toml::table* t = sub_table(root, "profiles", "[profiles]");
    if (t == nullptr) return out;
    Section profiles(doc, *t, "profiles", "the [profiles] table");
    profiles.allow(kProfileKinds);
    for (std::string_view kind : kProfileKinds) {
        const toml::table* kt = sub_table(profiles, kind, fmt::format("[profiles.{}.NAME]", kind));
        if (kt == nullptr) continue;
        const bool vertical = kind == "vertical";
        for (auto&& [k, v] : *kt) {
            const std::string path = fmt::format("profiles.{}.{}", kind, k.str());
            if (contains(vertical ? KeyList(kBuiltinVertical) : KeyList(kBuiltinHorizontal), k.str()))
                throw InputError(
                    doc.where(k, path),
                    fmt::format("'{}' is the name of a builtin {} profile; choose another name.", text::echo(k.str()),
                                kind));
            if (!v.is_table())
                doc.fail(
                    &v, path,
                    fmt::format("expected a table [profiles.{}.{}], got {}.", kind, text::echo(k.str()),
                                type_phrase(v.type())));
            Section s(doc, *v.as_table(), path, fmt::format("[profiles.{}.{}]", kind, text::echo(k.str())));
            if (vertical)
                out.vertical.emplace(std::string(k.str()), read_vertical_profile(s));
            else
                out.horizontal.emplace(std::string(k.str()), read_horizontal_profile(doc, s));
        }
    }
    return out;
}

// ---------------------------------------------------------------------------
// Sections.

DisplayGeometry read_display(const Document& doc, const Section& root) {
    const toml::table* t = sub_table(root, "display", "[display]");
    if (t == nullptr)
        doc.fail(
            nullptr, "display",
            "the scene has no [display] table; it is required (width_px, height_px, width_m, viewing_distance_m).");
    Section s(doc, *t, "display", "the [display] table");
    s.allow(kDisplayKeys);
    DisplayGeometry d;
    // What every GL 4.5 context can allocate (common/input_limits.h).
    constexpr int max_px = limits::kMaxDisplaySidePx;
    auto w = s.integer("width_px", 1, max_px);
    if (!w) s.missing("width_px", "the display's width in pixels");
    auto h = s.integer("height_px", 1, max_px);
    if (!h) s.missing("height_px", "the display's height in pixels");
    d.width_px = *w;
    d.height_px = *h;
    if (static_cast<long long>(*w) * *h > limits::kMaxDisplayPixels)
        s.fail(s.get("height_px"), "height_px",
               fmt::format("a display of {}×{} px has {} pixels, more than the {} (8192×8192) the renderer's "
                           "full-frame targets are sized for.",
                           *w, *h, static_cast<long long>(*w) * *h, limits::kMaxDisplayPixels));
    d.width_m = s.required_number("width_m", "the picture's visible width in metres");
    s.greater_than("width_m", d.width_m, 0.0);
    d.viewing_distance_m = s.required_number("viewing_distance_m", "eye to screen distance in metres");
    s.greater_than("viewing_distance_m", d.viewing_distance_m, 0.0);
    return d;
}

Camera read_camera(const Document& doc, const Section& root) {
    Camera c;
    const toml::table* t = sub_table(root, "camera", "[camera]");
    if (t == nullptr) return c;
    Section s(doc, *t, "camera", "the [camera] table");
    s.allow(kCameraKeys);
    if (auto p = vec3(s, "position_m")) c.position_m = *p;
    c.yaw_deg = s.number_or("yaw_deg", 0.0);
    c.pitch_deg = s.number_or("pitch_deg", 0.0);
    c.roll_deg = s.number_or("roll_deg", 0.0);
    if (auto fov = s.number("fov_deg")) {
        if (!(*fov > 0.0 && *fov < 180.0))
            s.fail(s.get("fov_deg"), "fov_deg",
                   fmt::format("fov_deg must be greater than 0 and less than 180, got {}.", number_text(*fov)));
        c.fov_y_deg = *fov;
    }
    return c;
}

Environment read_environment(const Document& doc, const Section& root) {
    Environment e;
    const toml::table* t = sub_table(root, "environment", "[environment]");
    if (t == nullptr) return e;
    Section s(doc, *t, "environment", "the [environment] table");
    s.allow(kEnvironmentKeys);
    if (auto bg = s.string("background")) {
        if (*bg == "uniform")
            e.background = Background::uniform;
        else if (*bg == "sky-sea")
            e.background = Background::sky_sea;
        else
            s.fail(s.get("background"), "background",
                   fmt::format("unknown background \"{}\"; it must be \"uniform\" or \"sky-sea\".", text::echo(*bg)));
    }
    e.luminance_cd_m2 = s.number_or("luminance_cd_m2", e.luminance_cd_m2);
    s.at_least("luminance_cd_m2", e.luminance_cd_m2, 0.0);
    const auto visibility = s.number("visibility_nmi");
    const auto extinction = s.number("extinction_per_km");
    if (visibility && extinction)
        s.fail(s.get("extinction_per_km"), "extinction_per_km",
               "give either visibility_nmi or extinction_per_km, not both.");
    if (visibility) {
        s.greater_than("visibility_nmi", *visibility, 0.0);
        e.extinction_per_m = extinction_per_m_from_visibility_m(*visibility * metres_per_nautical_mile);
    }
    if (extinction) {
        s.at_least("extinction_per_km", *extinction, 0.0);
        e.extinction_per_m = *extinction / 1000.0;
    }
    e.sea_reflectance_f0 = s.number_or("sea_reflectance", e.sea_reflectance_f0);
    s.within("sea_reflectance", e.sea_reflectance_f0, 0.0, 1.0);
    return e;
}

/// The glare key of [eye] or of a [[light]]: one of the models' names.
std::optional<GlareModel> read_glare_model(const Section& s) {
    const auto g = s.string("glare");
    if (!g) return std::nullopt;
    auto model = glare_model_from_name(*g);
    if (!model)
        s.fail(s.get("glare"), "glare",
               fmt::format("unknown glare model \"{}\"; it must be \"none\", \"wave-optics\", \"gaussian-bloom\", "
                           "\"spencer\", \"aperture\" or \"cie\".",
                           text::echo(*g)));
    return model;
}

/// Returns Scene::adaptation_cd_m2; sets the glare model and pupil.
double read_eye(const Document& doc, const Section& root, const Environment& environment, GlareSettings& glare,
                AdaptationSettings& adapt) {
    const double fallback = environment.luminance_cd_m2 > 0.0 ? environment.luminance_cd_m2 : 0.001;
    const toml::table* t = sub_table(root, "eye", "[eye]");
    if (t == nullptr) return fallback;
    Section s(doc, *t, "eye", "the [eye] table");
    s.allow(kEyeKeys);
    if (auto a = s.string("adaptation")) {
        if (*a == "dynamic")
            adapt.mode = AdaptationMode::dynamic;
        else if (*a != "fixed")
            s.fail(s.get("adaptation"), "adaptation",
                   fmt::format("unknown adaptation \"{}\"; it must be \"fixed\" or \"dynamic\".", *a));
    }
    adapt.stride = s.integer("adaptation_stride", 1, 64).value_or(adapt.stride);
    const double adaptation = s.number_or("adaptation_cd_m2", fallback);
    s.greater_than("adaptation_cd_m2", adaptation, 0.0);
    if (auto model = read_glare_model(s)) glare.model = *model;
    if (auto p = s.number("pupil_mm")) {
        s.greater_than("pupil_mm", *p, 0.0);
        s.within("pupil_mm", *p, 0.5, 12.0);
        glare.pupil_mm = *p;
    }
    // CIE 146:2002 observer of the `cie` model (cie_glare.h).
    if (auto a = s.number("cie_age_years")) {
        s.within("cie_age_years", *a, 0.0, 100.0);
        glare.cie.age_years = *a;
    }
    if (auto p = s.number("cie_pigmentation")) {
        s.within("cie_pigmentation", *p, 0.0, 1.2);
        glare.cie.pigmentation = *p;
    }
    try {
        (void)cie_glare_spread(glare.cie);
    } catch (const InputError& err) {
        // Only a combination of the two can fail here: name the one the file gives (the age first).
        const std::string key = s.get("cie_age_years") ? "cie_age_years" : "cie_pigmentation";
        s.fail(s.get(key), key, err.message());
    }
    return adaptation;
}

/// The [glare] table: the glare stage's settings and the eye model (docs/scene-file.md).
/// pupil_mm: the pupil the scene's frames will use (fixed adaptation), or the
/// darkest eq 3.15 gives (dynamic), for the checks that depend on it.
void read_glare(const Document& doc, const Section& root, GlareSettings& g, double pupil_mm) {
    const toml::table* t = sub_table(root, "glare", "[glare]");
    if (t == nullptr) return;
    Section s(doc, *t, "glare", "the [glare] table");
    // The key the two-scale eye replaced (docs/glare.md): its distance was a
    // defocus of 1/d diopters, now said as such.
    if (s.has("fresnel_distance_mm"))
        s.fail(s.get("fresnel_distance_mm"), "fresnel_distance_mm",
               "fresnel_distance_mm is no longer read: the eye's defocus is now 'defocus_diopters' (0 = in focus, "
               "the default; a distance d in mm is 1000/d diopters), and eye_preset = \"k2012\" draws the thesis's "
               "single-scale eye with its Fresnel term (d = 5000 mm).");
    s.allow(kGlareKeys);
    EyeModel& e = g.eye;
    if (auto preset = s.string("eye_preset")) {
        const std::optional<EyeModel> named = eye_preset(*preset);
        if (!named)
            s.fail(s.get("eye_preset"), "eye_preset",
                   fmt::format("unknown eye preset \"{}\"; presets are {}.", *preset, join(eye_preset_names())));
        e = *named;
        // The thesis's look includes its spectral method: one FFT at λ0 and
        // eq 4.9 lookups (docs/glare.md). Summed exactly over wavelengths, its
        // defocus rings fill the dark centre it drew, so the preset draws with
        // the rescaled path unless spectral_path says otherwise.
        if (e.scale == EyeScale::k2012_single) g.spectral_path = SpectralPath::rescaled;
    }
    if (s.boolean("clear_pupil").value_or(false)) e = EyeModel::clear_pupil(e.pupil_diameter_mm);
    g.psf_size = s.integer("psf_size", 16, 2048).value_or(g.psf_size);
    if (!is_power_of_two(g.psf_size))
        s.fail(s.get("psf_size"), "psf_size",
               fmt::format("psf_size must be a power of two (the FFT needs one), got {}.", g.psf_size));
    g.spectral_samples = s.integer("spectral_samples", 1, 128).value_or(g.spectral_samples);
    if (auto p = s.string("spectral_path")) {
        const auto path = spectral_path_from_name(*p);
        if (!path)
            s.fail(s.get("spectral_path"), "spectral_path",
                   fmt::format("unknown spectral path \"{}\"; it must be \"anchored\", \"rescaled\" or \"exact\".",
                               *p));
        g.spectral_path = *path;
    }
    g.spectral_anchors = s.integer("spectral_anchors", 1, 128).value_or(g.spectral_anchors);
    if (auto w = s.string("window")) {
        try {
            g.window = glare_window_from_name(*w);
        } catch (const InputError& err) {
            s.fail(s.get("window"), "window", err.message());
        }
    }
    if (auto r = s.number("radius_deg")) {
        s.greater_than("radius_deg", *r, 0.0);
        s.within("radius_deg", *r, 0.0, 45.0);
        g.radius_deg = *r;
    }
    g.area_layers = s.integer("area_layers", 2, 256).value_or(g.area_layers);
    g.bloom_sigma_deg = s.number_or("bloom_sigma_deg", g.bloom_sigma_deg);
    s.greater_than("bloom_sigma_deg", g.bloom_sigma_deg, 0.0);
    if (auto v = s.string("spencer_vision")) {
        if (*v == "photopic") g.spencer_vision = SpencerVision::photopic;
        else if (*v == "mesopic") g.spencer_vision = SpencerVision::mesopic;
        else if (*v == "scotopic") g.spencer_vision = SpencerVision::scotopic;
        else if (*v != "auto")
            s.fail(s.get("spencer_vision"), "spencer_vision",
                   fmt::format("unknown vision \"{}\"; it must be \"photopic\", \"mesopic\", \"scotopic\" or \"auto\".",
                               *v));
    }
    if (auto img = s.string("aperture_image")) {
        // Relative to the scene file, like every path in it.
        std::filesystem::path p(*img);
        if (p.is_relative() && !doc.file().empty()) p = std::filesystem::path(doc.file()).parent_path() / p;
        if (!std::filesystem::is_regular_file(p))
            s.fail(s.get("aperture_image"), "aperture_image",
                   fmt::format("the aperture image {} does not exist or is not a file.", p.string()));
        g.aperture_image = p.string();
    }
    g.aperture_width_mm = s.number_or("aperture_width_mm", g.aperture_width_mm);
    s.greater_than("aperture_width_mm", g.aperture_width_mm, 0.0);
    g.aperture_with_pupil = s.boolean("aperture_with_pupil").value_or(g.aperture_with_pupil);

    if (auto seed = s.integer("seed", 0, std::numeric_limits<int>::max())) e.seed = static_cast<std::uint64_t>(*seed);
    if (auto h = s.number("halo_radius_deg")) {
        s.at_least("halo_radius_deg", *h, 0.0);
        e.halo_radius_deg = *h > 0 ? std::optional<double>(*h) : std::nullopt;  // 0: physical scale
    }
    e.plane_width_mm = s.number_or("plane_width_mm", e.plane_width_mm);
    e.defocus_diopters = s.number_or("defocus_diopters", e.defocus_diopters);
    e.supersampling = s.integer("supersampling", 1, 16).value_or(e.supersampling);
    e.hippus.enabled = s.boolean("hippus").value_or(e.hippus.enabled);
    e.hippus.amplitude = s.number_or("hippus_amplitude", e.hippus.amplitude);
    e.gratings.enabled = s.boolean("gratings").value_or(e.gratings.enabled);
    e.gratings.count = s.integer("grating_count", 0, 100000).value_or(e.gratings.count);
    e.gratings.inner_radius_mm = s.number_or("grating_inner_radius_mm", e.gratings.inner_radius_mm);
    e.gratings.width_um = s.number_or("grating_width_um", e.gratings.width_um);
    e.gratings.opacity = s.number_or("grating_opacity", e.gratings.opacity);
    e.lens_particles.enabled = s.boolean("lens_particles").value_or(e.lens_particles.enabled);
    e.lens_particles.count = s.integer("lens_particle_count", 0, 1000000).value_or(e.lens_particles.count);
    e.lens_particles.diameter_um = s.number_or("lens_particle_diameter_um", e.lens_particles.diameter_um);
    e.vitreous_particles.enabled = s.boolean("vitreous_particles").value_or(e.vitreous_particles.enabled);
    e.vitreous_particles.count = s.integer("vitreous_particle_count", 0, 1000000).value_or(e.vitreous_particles.count);
    e.vitreous_particles.diameter_um = s.number_or("vitreous_particle_diameter_um", e.vitreous_particles.diameter_um);
    e.eyelashes.enabled = s.boolean("eyelashes").value_or(e.eyelashes.enabled);
    e.eyelashes.count = s.integer("eyelash_count", 0, 10000).value_or(e.eyelashes.count);
    e.eyelashes.width_um = s.number_or("eyelash_width_um", e.eyelashes.width_um);
    e.eyelid.enabled = s.boolean("eyelid").value_or(e.eyelid.enabled);
    e.eyelid.edge_mm = s.number_or("eyelid_edge_mm", e.eyelid.edge_mm);
    // The eye model's own checks (the pupil itself is checked per frame, where
    // hippus has moved it): with the scene's pupil within half the plane, so
    // that a defocus the frames' grid cannot sample is refused here, at its line.
    try {
        EyeModel probe = e;
        probe.pupil_diameter_mm = std::min(pupil_mm, 0.5 * probe.plane_width_mm);
        probe.hippus.enabled = false;
        probe.validate(g.psf_size);
    } catch (const InputError& err) {
        const std::string key = err.where() ? err.where()->key : std::string();
        // Keys spelt the same in the file and the model are refused at their own line.
        if (!key.empty() && s.has(key)) s.fail(s.get(key), key, err.message());
        s.fail_table(fmt::format("the eye model is invalid ({}): {}", key, err.message()));
    }
}

/// The display model ([display] photometric keys) and [tonemap] (docs/scene-file.md).
void read_output(const Document& doc, const Section& root, OutputSettings& out) {
    if (const toml::table* t = sub_table(root, "display", "[display]")) {
        Section s(doc, *t, "display", "the [display] table");
        const double peak = s.number_or("peak_cd_m2", out.display.peak_cd_m2);
        s.greater_than("peak_cd_m2", peak, 0.0);
        const double black = s.number_or("black_cd_m2", out.display.black_cd_m2);
        s.at_least("black_cd_m2", black, 0.0);
        if (!(black < peak))
            s.fail(s.has("black_cd_m2") ? s.get("black_cd_m2") : s.get("peak_cd_m2"), "black_cd_m2",
                   fmt::format("the display's black ({} cd/m²) must be below its peak ({} cd/m²).", number_text(black),
                               number_text(peak)));
        const std::string transfer = s.string("transfer").value_or("srgb");
        if (transfer == "srgb")
            out.display = DisplayModel::srgb(peak, black);
        else if (transfer == "pq")
            out.display = DisplayModel::pq(peak, black);
        else
            s.fail(s.get("transfer"), "transfer",
                   fmt::format("unknown transfer \"{}\"; it must be \"srgb\" or \"pq\" (or give a calibration file).",
                               transfer));
        if (auto cal = s.string("calibration")) {
            std::filesystem::path p(*cal);
            if (p.is_relative() && !doc.file().empty()) p = std::filesystem::path(doc.file()).parent_path() / p;
            try {
                out.display = display_from_calibration(fit_calibration(read_calibration_file(p)), p.stem().string());
            } catch (const InputError& e) {
                s.fail(s.get("calibration"), "calibration", fmt::format("the calibration file is unusable: {}", e.what()));
            }
        }
        out.encode.bits = s.integer("bits", 1, 16).value_or(out.encode.bits);
        if (auto d = s.boolean("dither")) out.encode.dither = *d ? Dither::spatiotemporal : Dither::none;
        if (auto seed = s.integer("dither_seed", 0, std::numeric_limits<int>::max()))
            out.encode.seed = static_cast<std::uint32_t>(*seed);
    }
    ToneMapSettings& tm = out.tonemap;
    tm.display_peak_cd_m2 = out.display.peak_cd_m2;
    const toml::table* t = sub_table(root, "tonemap", "[tonemap]");
    if (t == nullptr) return;
    Section s(doc, *t, "tonemap", "the [tonemap] table");
    s.allow(kTonemapKeys);
    if (auto op = s.string("operator")) {
        auto v = tone_operator_from_name(*op);
        if (!v)
            s.fail(s.get("operator"), "operator",
                   fmt::format("unknown tone-mapping operator \"{}\"; it must be one of {}.", text::echo(*op),
                               join(tone_operator_names(), "\"")));
        tm.tone_operator = *v;
    }
    tm.white_relative = s.number_or("white_relative", tm.white_relative);
    tm.reinhard_key = s.number_or("reinhard_key", tm.reinhard_key);
    tm.reinhard_white_relative = s.number_or("reinhard_white_relative", tm.reinhard_white_relative);
    tm.kakimoto_g = s.number_or("kakimoto_g", tm.kakimoto_g);
    tm.kakimoto_k = s.number_or("kakimoto_k", tm.kakimoto_k);
    if (auto w = s.number("white_cd_m2")) tm.white_cd_m2 = *w;
    if (auto a = s.number("display_adaptation_cd_m2")) tm.display_adaptation_cd_m2 = *a;
    tm.blueshift = s.boolean("blueshift").value_or(tm.blueshift);
    if (auto b = s.string("blueshift_luminance")) {
        auto v = blueshift_luminance_from_name(*b);
        if (!v)
            s.fail(s.get("blueshift_luminance"), "blueshift_luminance",
                   fmt::format("unknown blueshift luminance \"{}\"; it must be \"pixel\" (the rod sensitivity of each "
                               "pixel's own luminance) or \"adaptation\" (of the adaptation luminance).",
                               *b));
        tm.blueshift_luminance = *v;
    }
    if (auto xy = s.numbers("blueshift_xy", 2)) tm.blueshift_xy = {(*xy)[0], (*xy)[1]};
    if (auto h = s.string("hue_preservation")) {
        auto v = hue_preservation_from_name(*h);
        if (!v)
            s.fail(s.get("hue_preservation"), "hue_preservation",
                   fmt::format("unknown hue preservation \"{}\"; it must be one of {}.", text::echo(*h),
                               join(hue_preservation_names(), "\"")));
        tm.hue_preservation = *v;
    }
    out.ldr_glare = s.boolean("ldr_glare").value_or(out.ldr_glare);
    try {
        validate_tonemap_settings(tm);
    } catch (const InputError& e) {
        // The validator names "tonemap.KEY"; point at that key's line.
        std::string key = e.where() ? e.where()->key : std::string();
        if (key.starts_with("tonemap.")) key.erase(0, 8);
        s.fail(s.has(key) ? s.get(key) : &s.table(), key.empty() ? "operator" : key, e.message());
    }
}

// ---------------------------------------------------------------------------
// Lights.

/// The colour key of a light: IALA name, xy or SPD name (at most one; default white).
glm::dvec3 read_colour(const Section& s) {
    if (auto name = s.string("colour")) {
        if (auto rgb = iala_colour_rgb(*name)) return *rgb;
        s.fail(s.get("colour"), "colour",
               fmt::format("unknown colour \"{}\"; IALA colours are {} (or give xy or spd).", text::echo(*name),
                           join(iala_colour_names(), "\"")));
    }
    if (auto xy = s.numbers("xy", 2)) {
        const double x = (*xy)[0];
        const double y = (*xy)[1];
        if (!(x >= 0.0 && y > 0.0 && x + y <= 1.0))
            s.fail(s.get("xy"), "xy",
                   fmt::format("xy = [{}, {}] is not a chromaticity: it needs x >= 0, y > 0 and x + y <= 1.",
                               number_text(x), number_text(y)));
        return normalised_rgb_from_xy(glm::dvec2(x, y), /*clip_to_gamut=*/true);
    }
    if (auto spd = s.string("spd")) {
        if (auto spectrum = named_spectrum(*spd)) return normalised_rgb_from_spectrum(*spectrum);
        s.fail(s.get("spd"), "spd",
               fmt::format("unknown spectrum \"{}\"; named spectra are {}.", text::echo(*spd),
                           join(spectrum_names(), "\"")));
    }
    return *iala_colour_rgb("white");
}

struct SceneBuilder {
    const Document& doc;
    Scene& scene;
    const Profiles& profiles;
    std::map<std::string, std::string> names;  // light name -> key of the light that took it

    int vertical_index(const Section& s, const std::string& name) {
        if (auto it = profiles.vertical.find(name); it != profiles.vertical.end())
            return intern(scene.profiles.vertical, it->second);
        if (contains(kBuiltinVertical, name)) return intern(scene.profiles.vertical, builtin_vertical(name));
        std::vector<std::string> known(std::begin(kBuiltinVertical), std::end(kBuiltinVertical));
        for (const auto& [n, p] : profiles.vertical) known.push_back(n);
        s.fail(s.get("vertical_profile"), "vertical_profile",
               fmt::format("unknown vertical profile \"{}\"; known profiles are {}.", text::echo(name),
                           join(known, "\"")));
    }

    int horizontal_index(const Section& s, const std::string& name) {
        if (auto it = profiles.horizontal.find(name); it != profiles.horizontal.end())
            return intern(scene.profiles.horizontal, it->second);
        if (name == "uniform") return intern(scene.profiles.horizontal, HorizontalProfile::uniform());
        std::vector<std::string> known(std::begin(kBuiltinHorizontal), std::end(kBuiltinHorizontal));
        for (const auto& [n, p] : profiles.horizontal) known.push_back(n);
        s.fail(s.get("horizontal_profile"), "horizontal_profile",
               fmt::format("unknown horizontal profile \"{}\"; known profiles are {}.", text::echo(name),
                           join(known, "\"")));
    }

    void claim_name(const Section& s, const std::string& name) {
        const toml::node* at = s.has("name") ? s.get("name") : &s.table();
        if (auto it = names.find(name); it != names.end())
            s.fail(at, "name",
                   fmt::format("the light name \"{}\" is already used by {}; names must be unique.", text::echo(name),
                               it->second));
        names.emplace(name, s.path());
    }

    void read_light(const toml::node& node, std::size_t index) {
        const std::string path = fmt::format("light[{}]", index);
        if (!node.is_table())
            doc.fail(&node, path,
                     fmt::format("each light must be a [[light]] table, got {}.", type_phrase(node.type())));
        Section s(doc, *node.as_table(), path, fmt::format("[[light]] number {} ({})", index + 1, path));
        s.allow(kLightKeys);

        Light light;
        light.name = s.string("name").value_or(fmt::format("light{}", index));
        if (light.name.empty()) s.fail(s.get("name"), "name", "a light's name must not be empty.");
        s.set_context(fmt::format("in light \"{}\", ", text::echo(light.name)));
        s.set_title(fmt::format("[[light]] \"{}\" ({})", text::echo(light.name), path));

        auto position = vec3(s, "position_m");
        if (!position) s.missing("position_m", "the light's position [x, y, z] in metres");
        light.position_m = *position;
        light.intensity_cd = s.required_number("intensity_cd", "the light's peak luminous intensity in cd");
        s.at_least("intensity_cd", light.intensity_cd, 0.0);
        light.radius_m = s.number_or("radius_m", light.radius_m);
        s.greater_than("radius_m", light.radius_m, 0.0);

        const std::vector<std::string_view> colour_keys = {"colour", "xy", "spd"};
        std::vector<std::string_view> given;
        for (auto k : colour_keys)
            if (s.has(k)) given.push_back(k);
        if (given.size() > 1)
            s.fail(s.get(given[1]), given[1],
                   fmt::format("give only one of colour, xy and spd; this light has {}.", join(given)));
        light.rgb_per_cd = read_colour(s);
        light.spd = s.string("spd").value_or("");
        light.glare = read_glare_model(s);

        light.orientation = orientation_from_yaw_pitch_roll(s.number_or("yaw_deg", 0.0), s.number_or("pitch_deg", 0.0),
                                                            s.number_or("roll_deg", 0.0));

        light.vertical_profile = vertical_index(s, s.string("vertical_profile").value_or("uniform"));
        if (s.has("sectors") && s.has("horizontal_profile"))
            s.fail(s.get("sectors"), "sectors", "give either horizontal_profile or sectors, not both.");
        if (s.has("sectors"))
            light.horizontal_profile =
                intern(scene.profiles.horizontal, horizontal_from_sectors(s, read_sectors(doc, s, "sectors")));
        else
            light.horizontal_profile = horizontal_index(s, s.string("horizontal_profile").value_or("uniform"));

        RhythmTiming timing;
        timing.ramp_s = s.number_or("ramp_s", timing.ramp_s);
        s.at_least("ramp_s", timing.ramp_s, 0.0);
        light.rhythm_phase_s = s.number_or("rhythm_phase_s", 0.0);
        const std::string rhythm_text = s.string("rhythm").value_or("F");
        Rhythm rhythm;
        try {
            rhythm = parse_rhythm(rhythm_text, timing);
        } catch (const InputError& e) {
            // The parser's sentence starts "rhythm 'TEXT': "; ours already names it.
            std::string why = e.message();
            for (const std::string& prefix :
                 {fmt::format("rhythm '{}': ", rhythm_text), fmt::format("rhythm \"{}\": ", rhythm_text)})
                if (why.starts_with(prefix)) why.erase(0, prefix.size());
            if (!why.empty() && why.back() != '.') why += '.';
            s.fail(s.has("rhythm") ? s.get("rhythm") : &s.table(), "rhythm",
                   fmt::format("invalid rhythm \"{}\": {}", text::echo(rhythm_text), why));
        }
        if (rhythm.channels.empty())
            s.fail(s.get("rhythm"), "rhythm",
                   fmt::format("the rhythm \"{}\" has no channel.", text::echo(rhythm_text)));
        light.rhythm_period_s = rhythm.period_s;

        // A character that names its colours (Al.WR) gives each channel the
        // colour of its chart letter; the light's own colour keys would conflict.
        const bool chart_colours = std::any_of(rhythm.channels.begin(), rhythm.channels.end(),
                                               [](const RhythmChannel& c) { return !c.colour.empty(); });
        if (chart_colours && !given.empty())
            s.fail(s.get(given[0]), given[0],
                   fmt::format("the rhythm \"{}\" gives the colours itself; remove {}.", text::echo(rhythm_text),
                               given[0]));

        const toml::node* name_node = s.has("name") ? s.get("name") : &s.table();
        if (rhythm.channels.size() == 1) {
            const RhythmChannel& channel = rhythm.channels.front();
            if (!channel.colour.empty()) light.rgb_per_cd = chart_letter_rgb(s, channel.colour, rhythm_text);
            light.rhythm = channel.knots;
            claim_name(s, light.name);
            scene.lights.push_back(std::move(light));
            return;
        }
        // Alternating: one light per channel, "NAME/W", "NAME/R", ...
        claim_name(s, light.name);
        for (const RhythmChannel& channel : rhythm.channels) {
            Light l = light;
            l.name = fmt::format("{}/{}", light.name, channel.colour);
            l.rgb_per_cd = chart_letter_rgb(s, channel.colour, rhythm_text);
            l.rhythm = channel.knots;
            if (auto it = names.find(l.name); it != names.end())
                s.fail(name_node, "name",
                       fmt::format("the alternating rhythm makes a light \"{}\", a name already used by {}.", l.name,
                                   it->second));
            names.emplace(l.name, s.path());
            scene.lights.push_back(std::move(l));
        }
    }

    /// One [[disc]]: a uniform patch of luminance (scene.h Disc). Its name is
    /// unique among lights and discs, so that a protocol's view names one thing.
    void read_disc(const toml::node& node, std::size_t index) {
        const std::string path = fmt::format("disc[{}]", index);
        if (!node.is_table())
            doc.fail(&node, path, fmt::format("each disc must be a [[disc]] table, got {}.", type_phrase(node.type())));
        Section s(doc, *node.as_table(), path, fmt::format("[[disc]] number {} ({})", index + 1, path));
        s.allow(kDiscKeys);
        Disc disc;
        disc.name = s.string("name").value_or(fmt::format("disc{}", index));
        if (disc.name.empty()) s.fail(s.get("name"), "name", "a disc's name must not be empty.");
        s.set_context(fmt::format("in disc \"{}\", ", text::echo(disc.name)));
        s.set_title(fmt::format("[[disc]] \"{}\" ({})", text::echo(disc.name), path));
        auto position = vec3(s, "position_m");
        if (!position) s.missing("position_m", "a point [x, y, z] in metres on the line of sight to the disc's centre");
        disc.position_m = *position;
        disc.diameter_deg = s.required_number("diameter_deg", "the disc's angular diameter in degrees");
        s.within("diameter_deg", disc.diameter_deg, 0.0, 90.0);
        disc.luminance_cd_m2 = s.required_number("luminance_cd_m2", "the disc's luminance in cd/m²");
        s.at_least("luminance_cd_m2", disc.luminance_cd_m2, 0.0);
        std::vector<std::string_view> given;
        for (std::string_view k : {"colour", "xy", "spd"})
            if (s.has(k)) given.push_back(k);
        if (given.size() > 1)
            s.fail(s.get(given[1]), given[1],
                   fmt::format("give only one of colour, xy and spd; this disc has {}.", join(given)));
        disc.rgb_per_cd_m2 = read_colour(s);
        const toml::node* at = s.has("name") ? s.get("name") : &s.table();
        if (auto it = names.find(disc.name); it != names.end())
            s.fail(at, "name",
                   fmt::format("the name \"{}\" is already used by {}; lights and discs need names of their own.",
                               text::echo(disc.name), it->second));
        names.emplace(disc.name, path);
        scene.discs.push_back(std::move(disc));
    }

    glm::dvec3 chart_letter_rgb(const Section& s, const std::string& letter, const std::string& rhythm_text) {
        if (auto name = iala_colour_from_chart_letter(letter))
            if (auto rgb = iala_colour_rgb(*name)) return *rgb;
        s.fail(s.get("rhythm"), "rhythm",
               fmt::format("the rhythm \"{}\" names the colour letter \"{}\", which is not an IALA colour.",
                           rhythm_text, letter));
    }
};

/// A derived limit: the glare billboard, the model's radius in degrees times
/// the display's pixels per degree, must fit the glare kernel (4097 px). The
/// sentence names every key the width comes from, with its line (or --set).
void check_billboard(const Document& doc, const Section& root, const Scene& scene) {
    // The widest billboard of the models in use: the eye's, and any a light asks for.
    GlareSettings widest = scene.glare;
    double radius_deg = 0.0;
    for (const GlareModel m : glare_models_used(scene)) {
        GlareSettings g = scene.glare;
        g.model = m;
        if (const double r = glare_billboard_radius_deg(g); r > radius_deg) {
            radius_deg = r;
            widest = g;
        }
    }
    if (!(radius_deg > 0.0)) return;  // no glare: no billboard
    const double ppd = scene.display.pixels_per_degree_at_centre();
    const double width_px = glare_kernel_width_px(ppd, radius_deg);
    if (width_px <= kMaxGlareKernelPx) return;
    const auto node_in = [&](std::string_view table, std::string_view key) -> const toml::node* {
        const toml::node* t = root.get(table);
        return t != nullptr && t->is_table() ? t->as_table()->get(key) : nullptr;
    };
    const auto at = [&](std::string_view table, std::string_view key) {
        const toml::node* n = node_in(table, key);
        if (n == nullptr) return std::string(" (not given)");
        const SourceLocation w = doc.where(n, fmt::format("{}.{}", table, key));
        if (w.from_command_line()) return std::string(" (--set)");
        if (w.file != doc.file()) return fmt::format(" ({}:{})", w.file, w.line);  // e.g. a protocol's [display]
        return w.line > 0 ? fmt::format(" (line {})", w.line) : std::string();
    };
    const toml::node* radius_node = node_in("glare", "radius_deg");
    const std::string radius_text =
        radius_node != nullptr
            ? fmt::format("glare.radius_deg = {}{}", number_text(radius_deg), at("glare", "radius_deg"))
            : fmt::format("{:.4g}°, the {} model's default radius{}", radius_deg,
                          glare_model_name(widest.model),
                          widest.model == GlareModel::wave_optics || widest.model == GlareModel::aperture
                              ? " for its psf_size"
                              : "");
    const std::string message = fmt::format(
        "the glare billboard is {} px wide, more than the {} px a glare kernel may be: its radius ({}) at "
        "{:.1f} px per degree, from display.width_px = {}{}, display.width_m = {}{} and "
        "display.viewing_distance_m = {}{}. Check the display's size and viewing distance, or give a smaller "
        "glare.radius_deg.",
        number_text(width_px), kMaxGlareKernelPx, radius_text, ppd, scene.display.width_px,
        at("display", "width_px"), number_text(scene.display.width_m), at("display", "width_m"),
        number_text(scene.display.viewing_distance_m), at("display", "viewing_distance_m"));
    // At the radius when the file gives it, else at the viewing distance (the
    // usual culprit: a distance in mm written as metres).
    if (radius_node != nullptr) doc.fail(radius_node, "glare.radius_deg", message);
    doc.fail(node_in("display", "viewing_distance_m"), "display.viewing_distance_m", message);
}

void read_discs(const Section& root, SceneBuilder& builder) {
    const toml::node* discs = root.get("disc");
    if (discs == nullptr) return;
    if (!discs->is_array())
        root.fail(discs, "disc",
                  fmt::format("expected an array of [[disc]] tables, got {}; write [[disc]], not [disc].",
                              type_phrase(discs->type())));
    const toml::array& a = *discs->as_array();
    for (std::size_t i = 0; i < a.size(); ++i) builder.read_disc(*a.get(i), i);
}

Scene build_scene(Document& doc, const toml::table& root_table) {
    // Every table (and every light) is read even after an error in another:
    // all the errors, in file order, in one run (text::ErrorList; docs/scene-file.md).
    text::ErrorList errors;
    const auto step = [&](auto&& f) { return errors.attempt(f); };
    // Every unknown key of a table is reported, not only the first (Section::allow).
    doc.collect_into(&errors);
    Section root(doc, root_table, "", "the scene");
    // Unknown top-level tables are reported with the list of sections.
    for (auto&& entry : root_table) {
        // Named references, not structured bindings: clang 14 (the fuzz
        // build) cannot capture a binding in a lambda.
        const toml::key& k = entry.first;
        const toml::node& v = entry.second;
        if (contains(kSections, k.str())) continue;
        step([&] {
            throw InputError(
                doc.where(k, std::string(k.str())),
                fmt::format("unknown {} '{}'.{} A scene has the tables {}.", v.is_table() ? "table" : "key",
                            text::echo(k.str()), did_you_mean(k.str(), kSections), join(kSections)));
        });
    }
    Scene scene;
    step([&] { scene.display = read_display(doc, root); });
    step([&] { scene.camera = read_camera(doc, root); });
    step([&] { scene.environment = read_environment(doc, root); });
    step(
        [&] { scene.adaptation_cd_m2 = read_eye(doc, root, scene.environment, scene.glare, scene.output.adaptation); });
    scene.output.adaptation.fixed_cd_m2 = scene.adaptation_cd_m2;
    // The pupil the glare stage will use (glare_stage.h glare_pupil_mm): given,
    // or eq 3.15 from the fixed adaptation, or the dark-adapted 7.9 mm when the
    // adaptation follows the frame.
    const double pupil_mm = scene.glare.pupil_mm ? *scene.glare.pupil_mm
                            : scene.output.adaptation.mode == AdaptationMode::dynamic
                                ? pupil_diameter_mm_from_adaptation(0.0)
                                : pupil_diameter_mm_from_adaptation(scene.adaptation_cd_m2);
    step([&] { read_glare(doc, root, scene.glare, pupil_mm); });
    const bool output_read = step([&] { read_output(doc, root, scene.output); });
    Profiles profiles;
    const bool profiles_read = step([&] { profiles = read_profiles(doc, root); });

    SceneBuilder builder{doc, scene, profiles, {}};
    if (const toml::node* lights = root.get("light"); lights != nullptr && profiles_read) {
        const bool is_array = step([&] {
            if (!lights->is_array())
                root.fail(lights, "light",
                          fmt::format("expected an array of [[light]] tables, got {}; write [[light]], not [light].",
                                      type_phrase(lights->type())));
        });
        if (is_array) {
            const toml::array& a = *lights->as_array();
            for (std::size_t i = 0; i < a.size(); ++i) step([&] { builder.read_light(*a.get(i), i); });
        }
    }
    step([&] { read_discs(root, builder); });
    // The billboard check needs the display, the output and each light's own
    // glare model as read.
    if (output_read && errors.empty()) step([&] { check_billboard(doc, root, scene); });
    doc.collect_into(nullptr);
    errors.throw_if_any();
    return scene;
}

// ---------------------------------------------------------------------------
// Overrides.

[[noreturn]] void override_error(const std::string& key, const std::string& message) {
    throw InputError(SourceLocation::command_line(std::string(kSetOption), key), message);
}

/// A TOML basic string holding `text`, for values that are not valid TOML.
std::string toml_quoted(std::string_view text) {
    std::string q = "\"";
    for (const char ch : text) {
        const auto c = static_cast<unsigned char>(ch);
        if (ch == '"' || ch == '\\') {
            q += '\\';
            q += ch;
        } else if (c < 0x20 || c == 0x7f) {
            q += fmt::format("\\u{:04X}", static_cast<unsigned>(c));
        } else {
            q += ch;
        }
    }
    return q + "\"";
}

/// The parsed value of an override, with source path "--set KEY". A value that
/// is not valid TOML is taken as a string (so `colour=red` needs no quotes);
/// `note` then says so, for the type error that usually follows a typo.
toml::table parse_override_value(const SceneOverride& o, std::string& note) {
    const std::string source = std::string(kSetPrefix) + o.key;
    try {
        return toml::parse("v = " + o.value, std::string_view(source));
    } catch (const toml::parse_error& e) {
        note = fmt::format(" (the value \"{}\" is not valid TOML: {}; it was read as a string)", text::echo(o.value),
                           std::string(e.description()));
    }
    try {
        return toml::parse("v = " + toml_quoted(o.value), std::string_view(source));
    } catch (const toml::parse_error& e) {
        override_error(o.key,
                       fmt::format("the value \"{}\" cannot be read: {}.", text::echo(o.value),
                                   std::string(e.description())));
    }
}

bool is_number(const toml::node& n) {
    return n.is_integer() || n.is_floating_point();
}

/// The table that holds the overridden key, created if absent (and remembered
/// so that errors about it name the override).
toml::table& table_for_override(Document& doc, toml::table& parent, std::string_view name, const std::string& typed,
                                const std::string& shown) {
    toml::node* n = parent.get(name);
    if (n == nullptr) {
        auto [it, inserted] = parent.insert(name, toml::table{});
        doc.note_made_for_override(&it->second, typed);
        return *it->second.as_table();
    }
    if (!n->is_table()) {
        const SourceLocation w = doc.where(n, shown);
        override_error(typed, fmt::format("cannot set {}: {} is {} in {}:{}, not a table.", typed, shown,
                                          type_phrase(n->type()), w.file, w.line));
    }
    return *n->as_table();
}

/// The [[light]] or [[disc]] table (`array`: "light", "disc") an override
/// addresses: "ARRAY[INDEX].key" or "ARRAY.NAME.key" (NAME may contain dots; the
/// key after the last dot never does).
std::pair<toml::table*, std::string> element_for_override(const Document& doc, toml::table& root,
                                                          const SceneOverride& o, std::string& key,
                                                          const std::string& array) {
    const std::string written = fmt::format("a {0} key is written {0}.NAME.KEY or {0}[INDEX].KEY.", array);
    toml::node* node = root.get(array);
    if (node == nullptr || !node->is_array() || node->as_array()->empty())
        override_error(o.key, fmt::format("the scene has no [[{}]] tables to override.", array));
    toml::array& elements = *node->as_array();
    const std::string& k = o.key;
    const auto last_dot = k.rfind('.');
    if (last_dot == std::string::npos || last_dot == k.size() - 1) override_error(o.key, written);
    key = k.substr(last_dot + 1);

    std::size_t index = 0;
    const std::size_t skip = array.size() + 1;  // "light[" or "light."
    if (k.starts_with(array + "[")) {
        const auto close = k.find(']');
        const std::string digits = k.substr(skip, close == std::string::npos ? 0 : close - skip);
        if (close == std::string::npos || close + 1 != last_dot || digits.empty() ||
            !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }) ||
            digits.size() > 6)
            override_error(o.key, written);
        index = static_cast<std::size_t>(std::stoul(digits));
        if (index >= elements.size())
            override_error(o.key, fmt::format("there is no {0}[{1}]: the scene has {2} {0}{3} ({0}[0] to {0}[{4}]).",
                                              array, index, elements.size(), elements.size() == 1 ? "" : "s",
                                              elements.size() - 1));
    } else {
        const std::string name = k.substr(skip, last_dot - skip);
        std::vector<std::string> known;
        bool found = false;
        for (std::size_t i = 0; i < elements.size(); ++i) {
            std::string element_name = fmt::format("{}{}", array, i);
            if (const toml::table* t = elements.get(i)->as_table())
                if (const toml::node* n = t->get("name"); n != nullptr && n->is_string())
                    element_name = n->as_string()->get();
            if (element_name == name && !found) {
                index = i;
                found = true;
            }
            known.push_back(element_name);
        }
        if (!found)
            override_error(o.key, fmt::format("no {} is named \"{}\"; the {}s are {}.", array, text::echo(name), array,
                                              join(known, "\"")));
    }
    toml::node* element = elements.get(index);
    if (!element->is_table()) {
        const SourceLocation w = doc.where(element, fmt::format("{}[{}]", array, index));
        override_error(o.key, fmt::format("{}[{}] in {}:{} is not a table.", array, index, w.file, w.line));
    }
    return {element->as_table(), fmt::format("{}[{}]", array, index)};
}

void apply_override(Document& doc, toml::table& root, const SceneOverride& o) {
    const std::string& k = o.key;
    toml::table* target = nullptr;
    std::string key;         // the key inside *target
    std::string schema_key;  // canonical dotted path, e.g. "light[0].intensity_cd"

    const auto unknown = [&](std::string_view section, KeyList allowed, std::string_view leaf) {
        override_error(k, fmt::format("unknown key '{}' in [{}].{} Allowed keys: {}.", text::echo(leaf),
                                      text::echo(section),
                                      did_you_mean(leaf, allowed), join(allowed)));
    };

    if (k == "light" || k.starts_with("light.") || k.starts_with("light[")) {
        auto [table, path] = element_for_override(doc, root, o, key, "light");
        if (!contains(kLightKeys, key)) unknown("[light]", kLightKeys, key);
        target = table;
        schema_key = path + "." + key;
    } else if (k == "disc" || k.starts_with("disc.") || k.starts_with("disc[")) {
        auto [table, path] = element_for_override(doc, root, o, key, "disc");
        if (!contains(kDiscKeys, key)) unknown("[disc]", kDiscKeys, key);
        target = table;
        schema_key = path + "." + key;
    } else if (k.starts_with("profiles.")) {
        // profiles.KIND.NAME.KEY (NAME may contain dots)
        const std::string rest = k.substr(9);
        const auto kind_end = rest.find('.');
        const auto last_dot = rest.rfind('.');
        if (kind_end == std::string::npos || last_dot == kind_end)
            override_error(k, "a profile key is written profiles.vertical.NAME.KEY or profiles.horizontal.NAME.KEY.");
        const std::string kind = rest.substr(0, kind_end);
        const std::string name = rest.substr(kind_end + 1, last_dot - kind_end - 1);
        key = rest.substr(last_dot + 1);
        if (!contains(kProfileKinds, kind))
            override_error(k, fmt::format("unknown profile kind '{}'; it must be 'vertical' or 'horizontal'.", kind));
        const KeyList allowed = kind == "vertical" ? KeyList(kVerticalKeys) : KeyList(kHorizontalKeys);
        if (!contains(allowed, key)) unknown(fmt::format("profiles.{}.{}", kind, name), allowed, key);
        toml::table& profiles = table_for_override(doc, root, "profiles", k, "profiles");
        toml::table& kinds = table_for_override(doc, profiles, kind, k, "profiles." + kind);
        target = &table_for_override(doc, kinds, name, k, fmt::format("profiles.{}.{}", kind, name));
        schema_key = fmt::format("profiles.{}.{}.{}", kind, name, key);
    } else {
        const auto dot = k.find('.');
        const std::string section = k.substr(0, dot);
        if (!contains(kSections, section))
            override_error(k, fmt::format("unknown key '{}'; a scene has the tables {}.", text::echo(k),
                                          join(kSections)));
        if (dot == std::string::npos || dot + 1 == k.size())
            override_error(k, fmt::format("--set takes a key inside [{}], e.g. {}.{}.", section, section,
                                          section == "display" ? "width_px" : "yaw_deg"));
        key = k.substr(dot + 1);
        const KeyList allowed = section == "display"       ? KeyList(kDisplayKeys)
                                : section == "camera"      ? KeyList(kCameraKeys)
                                : section == "environment" ? KeyList(kEnvironmentKeys)
                                : section == "glare"       ? KeyList(kGlareKeys)
                                : section == "tonemap"     ? KeyList(kTonemapKeys)
                                                           : KeyList(kEyeKeys);
        if (!contains(allowed, key)) unknown(section, allowed, key);
        target = &table_for_override(doc, root, section, k, section);
        schema_key = k;
    }

    std::string note;
    toml::table parsed = parse_override_value(o, note);
    toml::node* value = parsed.get("v");

    // The new value must have the type of the one it replaces (integers and
    // floats are interchangeable); values the file leaves at their default are
    // type-checked by the schema afterwards.
    if (const toml::node* old = target->get(key)) {
        const bool same = old->type() == value->type() || (is_number(*old) && is_number(*value));
        if (!same) {
            const SourceLocation w = doc.where(old, schema_key);
            const std::string from =
                w.from_command_line() ? std::string("an earlier --set") : fmt::format("{}:{}", w.file, w.line);
            override_error(k, fmt::format("expected {} like the value it replaces ({}), got {}{}.",
                                          is_number(*old) ? std::string_view("a number") : type_phrase(old->type()),
                                          from, type_phrase(value->type()), note));
        }
    }
    for (const auto& group : exclusive_groups()) {
        if (std::find(group.begin(), group.end(), key) == group.end()) continue;
        for (std::string_view other : group)
            if (other != key) target->erase(other);
    }
    doc.note_override(k, schema_key, o.origin);
    doc.note_string_fallback(k, note);
    value->visit([&](auto& concrete) { target->insert_or_assign(key, std::move(concrete)); });
}

}  // namespace

SceneOverride SceneOverride::parse(std::string_view text) {
    const auto trim = [](std::string_view s) {
        while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
        while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
        return s;
    };
    const auto eq = text.find('=');
    if (eq == std::string_view::npos)
        throw InputError(SourceLocation::command_line(std::string(kSetOption), std::string(trim(text))),
                         fmt::format("expected KEY=VALUE, e.g. camera.yaw_deg=45, got \"{}\".", text::echo(text)));
    SceneOverride o;
    o.key = std::string(trim(text.substr(0, eq)));
    o.value = std::string(trim(text.substr(eq + 1)));
    if (o.key.empty())
        throw InputError(SourceLocation::command_line(std::string(kSetOption)),
                         fmt::format("the key before '=' is empty in \"{}\".", text::echo(text)));
    return o;
}

Scene parse_scene(std::string_view toml_text, std::string_view file_label,
                  const std::vector<SceneOverride>& overrides) {
    Document doc{std::string(file_label)};
    toml::table root;
    try {
        root = toml::parse(toml_text, file_label);
    } catch (const toml::parse_error& e) {
        throw InputError(SourceLocation{std::string(file_label), static_cast<int>(e.source().begin.line),
                                        static_cast<int>(e.source().begin.column), ""},
                         fmt::format("TOML syntax error: {}.", std::string(e.description())));
    }
    for (const SceneOverride& o : overrides) apply_override(doc, root, o);
    return build_scene(doc, root);
}

Scene load_scene(const std::filesystem::path& file, const std::vector<SceneOverride>& overrides) {
    // Read only up to a limit: /dev/zero or a video file given by mistake is
    // refused, not read until the memory runs out.
    const text::FileText read = text::read_text_file(file);
    if (!read.ok())
        throw InputError(SourceLocation{file.string(), 0, 0, ""},
                         fmt::format("cannot read the scene file: {}.", read.error));
    return parse_scene(read.text, file.string(), overrides);
}

}  // namespace atonlab::stimuli
