#pragma once
// Where the lab's display-profile file is (docs/calibration.md, "The
// display-profile file"): `--profiles FILE`, else the environment variable
// ATONLAB_PROFILES, else the per-user default
// $XDG_DATA_HOME/atonlab/profiles.sqlite ($HOME/.local/share/... when
// XDG_DATA_HOME is unset or empty, as the XDG Base Directory specification says).
#include <filesystem>
#include <optional>
#include <string>

#include "atonlab/store/profiles.h"

namespace atonlab::runner {

/// The environment variable naming the display-profile file.
inline constexpr const char* kProfilesEnv = "ATONLAB_PROFILES";

struct ProfilesLocation {
    std::filesystem::path path;
    /// Where the path came from, for messages: "--profiles", "ATONLAB_PROFILES"
    /// or "the per-user default".
    std::string origin;
    /// Given by the user (option or environment): a missing file or directory
    /// is an error. The per-user default may be absent (no profiles yet), and
    /// its directory is created when a calibration is first stored there.
    bool explicit_path = false;
};

/// The display-profile file: `option` when not empty, else ATONLAB_PROFILES,
/// else the per-user default; std::nullopt only when none applies (no
/// XDG_DATA_HOME and no HOME).
std::optional<ProfilesLocation> profiles_location(const std::string& option);

/// The display-profile file as `atonlab run` reads it (read-only), or
/// std::nullopt when `none` (--no-profiles) or when the per-user default does
/// not exist. A path the user gave that does not exist is an InputError
/// naming its origin; a file that is not a display-profile file, or is
/// damaged, a StoreError.
std::optional<store::Profiles> open_profiles_for_run(const std::string& option, bool none);

}  // namespace atonlab::runner
