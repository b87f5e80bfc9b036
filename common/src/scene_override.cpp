// A scene override parsed from `--set` text (scene_override.h).
#include "atonlab/common/scene_override.h"

#include <fmt/format.h>

#include "atonlab/common/input_text.h"

namespace atonlab {

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
    o.origin = SourceLocation::command_line(std::string(kSetOption), o.key);
    return o;
}

}  // namespace atonlab
