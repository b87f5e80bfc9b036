// The models' declared settings (glare_setting.h): reading them, their values,
// and the glare stage's kernel cache key built from them.
#include "atonlab/stimuli/glare_models/glare_setting.h"

#include <fmt/format.h>

#include <algorithm>

#include "atonlab/common/input_error.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/scene.h"
#include "glare_setting_reader.h"

namespace atonlab::stimuli {
namespace {

const GlareSetting* find_any(std::string_view key) {
    for (const GlareModelType* m : glare_models())
        for (const GlareSetting& s : m->settings())
            if (s.key == key) return &s;
    return nullptr;
}

// The value in g, else the declared default; InputError when neither.
const GlareSettingValue& value_of(const GlareSettings& g, std::string_view key) {
    if (auto it = g.values.find(key); it != g.values.end()) return it->second;
    const GlareSetting* s = find_any(key);
    if (s == nullptr || !s->default_value)
        throw InputError(SourceLocation{"", 0, 0, std::string(key)},
                         fmt::format("{} is not given and has no default.", key));
    return *s->default_value;
}

template <class T>
const T& typed(const GlareSettings& g, std::string_view key, std::string_view type) {
    const GlareSettingValue& v = value_of(g, key);
    if (const T* t = std::get_if<T>(&v)) return *t;
    throw InputError(SourceLocation{"", 0, 0, std::string(key)}, fmt::format("{} must be a {}.", key, type));
}

std::string value_text(const GlareSettingValue& v) {
    return std::visit(
        [](const auto& x) {
            using T = std::decay_t<decltype(x)>;
            if constexpr (std::is_same_v<T, std::string>)
                return fmt::format("\"{}\"", x);
            else
                return fmt::format("{}", x);
        },
        v);
}

}  // namespace

std::string_view glare_table_name(GlareTable t) {
    return t == GlareTable::eye ? "eye" : "glare";
}

double glare_number(const GlareSettings& g, std::string_view key) {
    return typed<double>(g, key, "number");
}

bool glare_flag(const GlareSettings& g, std::string_view key) {
    return typed<bool>(g, key, "boolean");
}

std::string glare_text(const GlareSettings& g, std::string_view key) {
    return typed<std::string>(g, key, "string");
}

std::string glare_setting_text(const GlareSettings& g, const GlareSetting& s) {
    if (s.typed_text) return s.typed_text(g);
    if (auto it = g.values.find(s.key); it != g.values.end()) return value_text(it->second);
    return s.default_value ? value_text(*s.default_value) : std::string();
}

const GlareSetting* find_glare_setting(GlareTable table, std::string_view key) {
    for (const GlareModelType* m : glare_models())
        for (const GlareSetting& s : m->settings())
            if (s.table == table && s.key == key) return &s;
    return nullptr;
}

std::string glare_setting_option(std::string_view key) {
    std::string option = "--" + std::string(key);
    std::replace(option.begin() + 2, option.end(), '_', '-');
    return option;
}

void read_declared_settings(const toml_reader::Section& s, GlareTable table, std::span<const GlareSetting> settings,
                            GlareSettings& g) {
    for (const GlareSetting& d : settings) {
        if (d.table != table || d.typed_text || !s.has(d.key)) continue;
        GlareSettingValue v;
        if (d.type == "bool")
            v = *s.boolean(d.key);
        else if (d.type == "string")
            v = *s.string(d.key);
        else
            v = *s.number(d.key);
        if (d.check)
            if (const std::string why = d.check(v); !why.empty()) s.fail(s.get(d.key), d.key, why);
        g.values.insert_or_assign(std::string(d.key), std::move(v));
    }
}

void apply_glare_settings(const std::map<std::string, TomlValue, std::less<>>& given, GlareSettings& g,
                          double pupil_mm) {
    toml::table glare_table, eye_table;
    for (const auto& [key, value] : given) {
        const GlareSetting* s = find_glare_setting(GlareTable::glare, key);
        if (s == nullptr) s = find_glare_setting(GlareTable::eye, key);
        const SourceLocation where{"", 0, 0, key};
        if (s == nullptr) {
            std::string keys;
            for (const GlareModelType* m : glare_models())
                for (const GlareSetting& d : m->settings())
                    keys += fmt::format("{}{}", keys.empty() ? "" : ", ", d.key);
            throw InputError(where, fmt::format("no glare model has a setting '{}'; the settings are {}.", key, keys));
        }
        toml::table& t = s->table == GlareTable::eye ? eye_table : glare_table;
        const toml::node& n = value.node();
        if (auto b = n.value_exact<bool>())
            t.insert(key, *b);
        else if (auto i = n.value_exact<std::int64_t>())
            t.insert(key, *i);
        else if (auto d = n.value_exact<double>())
            t.insert(key, *d);
        else if (auto str = n.value_exact<std::string>())
            t.insert(key, *str);
        else
            throw InputError(where, fmt::format("{} takes a {}, not an array or a table.", key, s->type));
    }
    const toml_reader::Document doc("");
    const toml_reader::Section glare(doc, glare_table, "glare", "the glare settings");
    const toml_reader::Section eye(doc, eye_table, "eye", "the eye settings");
    try {
        for (const GlareModelType* m : glare_models()) {
            m->read_glare_keys(doc, glare, g, pupil_mm);
            m->read_eye_keys(eye, g);
        }
    } catch (const InputError& e) {
        // The sections name "glare.KEY"; here a setting is its key alone (its option, its keyword).
        std::string key = e.where() ? e.where()->key : std::string();
        for (const std::string_view table : {"glare.", "eye."})
            if (key.starts_with(table)) key.erase(0, table.size());
        throw InputError(SourceLocation{"", 0, 0, key}, e.message());
    }
}

std::string glare_kernel_key(const Scene& scene, GlareModel model, std::string_view spd) {
    const GlareSettings& gs = scene.glare;
    // The settings every model's kernel shares (the glare stage's keys of [glare]).
    std::string key = fmt::format("{}|{}|{}|{}|{}|{}|", glare_model_name(model), gs.psf_size, gs.spectral_samples,
                                  glare_window_name(gs.window), gs.radius_deg.value_or(-1),
                                  scene.display.pixels_per_degree_at_centre());
    const GlareModelType& type = glare_model_type(model);
    for (const GlareSetting& s : type.settings())
        key += fmt::format("{}.{}={}|", glare_table_name(s.table), s.key, glare_setting_text(gs, s));
    return key + fmt::format("{}|{}", spd, type.kernel_scene_key(scene));
}

}  // namespace atonlab::stimuli
