#pragma once
// What the scene file's tests (test_scene_file*.cpp) share: a full scene and
// a minimal one, and the readers that name an error's file, line and key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <string>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/stimuli/scene_file.h"

namespace atonlab::stimuli::scene_file_test {

inline constexpr const char* kFile = "harbour.toml";

inline constexpr const char* kFullScene = R"(# a harbour entrance at night
[display]
width_px = 1920
height_px = 1080
width_m = 0.598
viewing_distance_m = 0.9

[camera]
position_m = [1.0, 4.0, -2.0]
yaw_deg = 45
pitch_deg = -2.5
roll_deg = 1
fov_deg = 30

[environment]
background = "uniform"
luminance_cd_m2 = 0.01
visibility_nmi = 10
sea_reflectance = 0.03

[eye]
adaptation = "fixed"
glare = "none"

[profiles.vertical.lantern]
elevation_deg = [-90, 0, 90]
relative = [0, 1, 0]

[profiles.horizontal.harbour]
sectors = [{ from_deg = 90, to_deg = 180 }, { from_deg = 180, to_deg = 270, level = 0.5, edge_deg = 2 }]

[[light]]
name = "buoy"
position_m = [0.0, 2.0, -1852.0]
intensity_cd = 250
colour = "red"
rhythm = "Fl(2) 10s"
ramp_s = 0.05
vertical_profile = "lantern"
horizontal_profile = "harbour"
yaw_deg = 90

[[light]]
position_m = [100, 5, -1000]
intensity_cd = 1000.0
xy = [0.3127, 0.3290]
vertical_profile = "sabik-vp"
radius_m = 0.25
rhythm_phase_s = 1.5

[[light]]
name = "pier"
position_m = [0, 3, -500]
intensity_cd = 50
spd = "led-green"
vertical_profile = "lantern"
)";

inline constexpr const char* kMinimal = R"([display]
width_px = 800
height_px = 600
width_m = 0.4
viewing_distance_m = 0.6
)";

/// 1-based line of the first occurrence of needle (so tests name lines by content).
inline int line_of(const std::string& text, const std::string& needle) {
    const auto pos = text.find(needle);
    EXPECT_NE(pos, std::string::npos) << needle;
    return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(pos), '\n'));
}

/// The InputError that parsing throws, or a failure.
inline InputError error_of(const std::string& text, const std::vector<SceneOverride>& overrides = {}) {
    try {
        parse_scene(text, kFile, overrides);
    } catch (const InputError& e) {
        return e;
    }
    ADD_FAILURE() << "no InputError for:\n" << text;
    return InputError("(none)");
}

/// Expects an error at FILE:LINE for KEY whose message contains `words`.
inline void expect_error_at(const std::string& text, int line, const std::string& key, const std::string& words) {
    const InputError e = error_of(text);
    const std::string what = e.what();
    EXPECT_NE(what.find(std::string(kFile) + ":" + std::to_string(line) + ":"), std::string::npos)
        << "expected line " << line << " in: " << what;
    EXPECT_NE(what.find("key '" + key + "'"), std::string::npos) << "expected key " << key << " in: " << what;
    EXPECT_NE(what.find(words), std::string::npos) << "expected '" << words << "' in: " << what;
    ASSERT_TRUE(e.where().has_value());
    EXPECT_EQ(e.where()->line, line);
    EXPECT_EQ(e.where()->key, key);
}

/// kMinimal plus a light section.
inline std::string with_light(const std::string& light) {
    return std::string(kMinimal) + "\n[[light]]\n" + light;
}

inline std::vector<SceneOverride> sets(std::initializer_list<const char*> texts) {
    std::vector<SceneOverride> out;
    for (const char* t : texts) out.push_back(SceneOverride::parse(t));
    return out;
}

/// The smallest scene with one light: an 800 × 600 px display and a 1 cd buoy 500 m ahead.
inline constexpr const char* kOneBuoyScene = R"([display]
width_px = 800
height_px = 600
width_m = 0.4
viewing_distance_m = 0.6
[[light]]
name = "buoy"
position_m = [0, 2, -500]
intensity_cd = 1
)";

}  // namespace atonlab::stimuli::scene_file_test
