#include "profile_location.h"

#include <fmt/format.h>

#include <cstdlib>

#include "atonlab/stimuli/error.h"

namespace atonlab::runner {

std::optional<ProfilesLocation> profiles_location(const std::string& option) {
    if (!option.empty()) return ProfilesLocation{option, "--profiles", true};
    if (const char* env = std::getenv(kProfilesEnv); env && *env) return ProfilesLocation{env, kProfilesEnv, true};
    // XDG Base Directory Specification 0.8: $XDG_DATA_HOME, default $HOME/.local/share;
    // a relative XDG_DATA_HOME is invalid and ignored.
    std::filesystem::path data;
    if (const char* xdg = std::getenv("XDG_DATA_HOME"); xdg && *xdg && std::filesystem::path(xdg).is_absolute())
        data = xdg;
    else if (const char* home = std::getenv("HOME"); home && *home)
        data = std::filesystem::path(home) / ".local" / "share";
    else
        return std::nullopt;
    return ProfilesLocation{data / "atonlab" / "profiles.sqlite", "the per-user default", false};
}

std::optional<store::Profiles> open_profiles_for_run(const std::string& option, bool none) {
    if (none) return std::nullopt;
    const std::optional<ProfilesLocation> where = profiles_location(option);
    if (!where) return std::nullopt;
    std::error_code ec;
    if (!std::filesystem::exists(where->path, ec)) {
        if (!where->explicit_path) return std::nullopt;
        throw InputError(SourceLocation::command_line(where->origin),
                         fmt::format("the display-profile file {} does not exist (measure a display into it with "
                                     "`atonlab calibrate measure --profiles {}`, or run with --no-profiles).",
                                     where->path.string(), where->path.string()));
    }
    return store::Profiles::open_read_only(where->path);
}

}  // namespace atonlab::runner
