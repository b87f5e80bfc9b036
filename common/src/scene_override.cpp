// A scene override parsed from `--set` text (scene_override.h).
#include "atonlab/common/scene_override.h"

#include <fmt/format.h>

#include "atonlab/common/input_text.h"

namespace atonlab {

SceneOverride::SceneOverride(std::string k, std::string v, SourceLocation where)
    : key(std::move(k)), value(std::move(v)), origin(std::move(where)) {
    // The nodes' source path names the override, so that the scene loader can
    // say where an element of it was written (stimuli/src/scene_reader.h).
    const std::string source = std::string(kSetOption) + " " + key;
    typed_ = TomlValue::parse(value, &not_toml_, source);
    if (typed_) return;
    typed_ = TomlValue::string(value, &unreadable_, source);
}

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
    std::string key(trim(text.substr(0, eq)));
    if (key.empty())
        throw InputError(SourceLocation::command_line(std::string(kSetOption)),
                         fmt::format("the key before '=' is empty in \"{}\".", text::echo(text)));
    SourceLocation origin = SourceLocation::command_line(std::string(kSetOption), key);
    return SceneOverride(std::move(key), std::string(trim(text.substr(eq + 1))), std::move(origin));
}

}  // namespace atonlab
