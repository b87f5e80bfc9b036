// The lights of a stored scene text, with a trial's overrides (scene_lights.h).
#include "atonlab/analysis/scene_lights.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <tuple>

#include "atonlab/common/toml_value.h"
#include "atonlab/display/colour.h"

namespace atonlab::analysis {

namespace {

/// A value as a report writes it: a string's contents, numbers shortest round-trip.
std::string value_text(const toml::node& n) {
    if (const auto s = n.value<std::string>(); s && n.is_string()) return *s;
    if (n.is_integer() || n.is_floating_point()) return fmt::format("{}", *n.value<double>());
    if (const toml::array* a = n.as_array()) {
        std::string out;
        for (const toml::node& e : *a) out += (out.empty() ? "" : ", ") + value_text(e);
        return out;
    }
    if (const auto b = n.value<bool>(); b && n.is_boolean()) return *b ? "true" : "false";
    return {};
}

/// An override's value as a report writes it: its typed value (a value that
/// is not TOML is a string, as the scene loader takes it; docs/scene-file.md
/// "Overrides with --set"), else the text as written.
std::string override_value(const SceneOverride& o) {
    return o.typed() ? value_text(o.typed()->node()) : o.value;
}

constexpr std::string_view kColourKeys[] = {"colour", "xy", "spd"};

}  // namespace

std::optional<SceneLights> SceneLights::parse(std::string_view scene_text, std::string& error) {
    toml::table root;
    try {
        root = toml::parse(scene_text);
    } catch (const toml::parse_error& e) {
        error = fmt::format("the stored scene text does not parse (line {}: {})", e.source().begin.line,
                            std::string(e.description()));
        return std::nullopt;
    }
    SceneLights out;
    for (const std::string_view array : {std::string_view("light"), std::string_view("disc")}) {
        const toml::node* n = root.get(array);
        if (n == nullptr) continue;
        const toml::array* a = n->as_array();
        if (a == nullptr) {
            error = fmt::format("the stored scene's {} is not an array of tables", array);
            return std::nullopt;
        }
        for (std::size_t i = 0; i < a->size(); ++i) {
            const toml::table* t = a->get(i)->as_table();
            if (t == nullptr) {
                error = fmt::format("the stored scene's {}[{}] is not a table", array, i);
                return std::nullopt;
            }
            Entry e;
            e.disc = array == "disc";
            e.name = t->get("name") && t->get("name")->is_string() ? *t->get("name")->value<std::string>()
                                                                   : fmt::format("{}{}", array, i);
            for (const std::string_view k : kColourKeys)
                if (const toml::node* v = t->get(k); v && e.colour_key.empty()) {
                    e.colour_key = std::string(k);
                    e.colour_value = value_text(*v);
                }
            if (const toml::node* r = t->get("rhythm"); r && !e.disc) e.rhythm = value_text(*r);
            (e.disc ? out.discs_ : out.lights_).push_back(std::move(e));
        }
    }
    return out;
}

std::optional<LightLook> SceneLights::look(std::string_view name, const std::vector<SceneOverride>& overrides) const {
    // The light or disc itself, or the base of "NAME/LETTER" (an alternating light's colour).
    std::string letter;
    const auto find = [&](std::string_view n) -> std::pair<const std::vector<Entry>*, std::size_t> {
        for (const std::vector<Entry>* list : {&lights_, &discs_})
            for (std::size_t i = 0; i < list->size(); ++i)
                if ((*list)[i].name == n) return {list, i};
        return {nullptr, 0};
    };
    auto [list, index] = find(name);
    if (list == nullptr) {
        const auto slash = name.rfind('/');
        if (slash == std::string_view::npos) return std::nullopt;
        std::tie(list, index) = find(name.substr(0, slash));
        if (list == nullptr || list != &lights_) return std::nullopt;
        letter = std::string(name.substr(slash + 1));
    }
    const std::string array = list == &lights_ ? "light" : "disc";
    Entry e = (*list)[index];
    // The overrides that address this element (ARRAY.NAME.KEY or ARRAY[INDEX].KEY), applied in order.
    for (const SceneOverride& o : overrides) {
        const std::optional<ElementAddress> a = element_address(o.key, array);
        if (!a || (a->index ? *a->index != index : a->name != (*list)[index].name)) continue;
        const std::string& leaf = a->key;
        if (std::find(std::begin(kColourKeys), std::end(kColourKeys), leaf) != std::end(kColourKeys)) {
            e.colour_key = leaf;  // the others of the group are removed (scene_reader.h exclusive_groups)
            e.colour_value = override_value(o);
        } else if (leaf == "rhythm" && !e.disc) {
            e.rhythm = override_value(o);
        }
    }
    LightLook out;
    out.rhythm = e.disc ? "steady" : e.rhythm;
    const bool alternating = !e.disc && e.rhythm.starts_with("Al");
    if (!letter.empty()) {
        out.colour = display::iala_colour_from_chart_letter(letter).value_or(letter);
    } else if (e.colour_key == "colour") {
        out.colour = e.colour_value;
    } else if (e.colour_key == "xy") {
        out.colour = "xy " + e.colour_value;
    } else if (e.colour_key == "spd") {
        out.colour = "spd " + e.colour_value;
        out.spectrum = e.colour_value;
    } else {
        out.colour = alternating ? "alternating (" + e.rhythm + ")" : "white";
    }
    // A light without `spd` has its glare integrated over its colour's representative spectrum,
    // or D65 for an `xy` colour (docs/glare.md "The light's spectrum"); a disc has no glare.
    if (out.spectrum.empty() && !e.disc && !(alternating && letter.empty())) {
        out.spectrum = e.colour_key == "xy" ? "d65" : display::iala_colour_spectrum_name(out.colour).value_or("");
    }
    return out;
}

}  // namespace atonlab::analysis
