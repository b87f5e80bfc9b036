// A scene override parsed from `--set` text (scene_override.h).
#include "atonlab/common/scene_override.h"

#include <fmt/format.h>

#include <algorithm>
#include <string>

#include "atonlab/common/input_text.h"

namespace atonlab {

namespace {

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

/// The value of `text`: TOML, else a string (not_toml says why), else none (unreadable says why).
std::optional<TomlValue> typed_value(std::string_view text, std::string_view source, std::string& not_toml,
                                     std::string& unreadable) {
    if (auto v = TomlValue::parse(text, &not_toml, source)) {
        not_toml.clear();
        return v;
    }
    return TomlValue::string(text, &unreadable, source);
}

}  // namespace

std::optional<KeyValue> read_key_value(std::string_view text, std::string_view source) {
    const auto eq = text.find('=');
    if (eq == std::string_view::npos) return std::nullopt;
    KeyValue kv;
    kv.key = std::string(trim(text.substr(0, eq)));
    kv.text = std::string(trim(text.substr(eq + 1)));
    kv.value = typed_value(kv.text, source, kv.not_toml, kv.unreadable);
    return kv;
}

SceneOverride::SceneOverride(std::string k, std::string v, SourceLocation where)
    : key(std::move(k)), value(std::move(v)), origin(std::move(where)) {
    // The nodes' source path names the override, so that the scene loader can
    // say where an element of it was written (stimuli/src/scene_reader.h).
    typed_ = typed_value(value, std::string(kSetOption) + " " + key, not_toml_, unreadable_);
}

SceneOverride SceneOverride::parse(std::string_view text) {
    const std::optional<KeyValue> kv = read_key_value(text);
    if (!kv)
        throw InputError(SourceLocation::command_line(std::string(kSetOption), std::string(trim(text))),
                         fmt::format("expected KEY=VALUE, e.g. camera.yaw_deg=45, got \"{}\".", text::echo(text)));
    if (kv->key.empty())
        throw InputError(SourceLocation::command_line(std::string(kSetOption)),
                         fmt::format("the key before '=' is empty in \"{}\".", text::echo(text)));
    SourceLocation origin = SourceLocation::command_line(std::string(kSetOption), kv->key);
    return SceneOverride(kv->key, kv->text, std::move(origin));
}

std::optional<ElementAddress> element_address(std::string_view k, std::string_view array) {
    const std::string by_index = std::string(array) + "[", by_name = std::string(array) + ".";
    if (!k.starts_with(by_index) && !k.starts_with(by_name)) return std::nullopt;
    const auto last_dot = k.rfind('.');
    if (last_dot == std::string_view::npos || last_dot == k.size() - 1) return std::nullopt;
    ElementAddress a;
    a.key = std::string(k.substr(last_dot + 1));
    const std::size_t skip = array.size() + 1;  // "light[" or "light."
    if (k.starts_with(by_index)) {
        const auto close = k.find(']');
        const std::string_view digits = k.substr(skip, close == std::string_view::npos ? 0 : close - skip);
        if (close == std::string_view::npos || close + 1 != last_dot || digits.empty() || digits.size() > 6 ||
            !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
            return std::nullopt;
        a.index = static_cast<std::size_t>(std::stoul(std::string(digits)));
    } else {
        if (last_dot < skip) return std::nullopt;  // "light." with no name: the dot is the array's
        a.name = std::string(k.substr(skip, last_dot - skip));
    }
    return a;
}

}  // namespace atonlab
