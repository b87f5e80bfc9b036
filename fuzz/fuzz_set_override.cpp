// libFuzzer target: `--set KEY=VALUE` (SceneOverride::parse and the override
// applied to a scene, stimuli/src/scene_file.cpp). The input is split at
// newlines into up to four overrides, applied in order to a fixed scene with a
// light of each kind of profile, so keys that address lights by name or index,
// profiles and sectors all have something to override. An InputError is the
// expected refusal; anything else is a finding (docs/fuzzing.md).
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/scene_file.h"

namespace {

constexpr std::string_view kScene = R"(
[display]
width_px = 320
height_px = 180
width_m = 0.1
viewing_distance_m = 0.9

[camera]
position_m = [0.0, 3.0, 0.0]
yaw_deg = 10.0

[environment]
background = "sky-sea"
luminance_cd_m2 = 0.01
visibility_nmi = 10.0

[eye]
adaptation_cd_m2 = 0.01
glare = "spencer"

[glare]
psf_size = 64

[tonemap]
operator = "empirical"

[profiles.vertical.lantern]
elevation_deg = [-10.0, 0.0, 10.0]
relative = [0.2, 1.0, 0.2]

[profiles.horizontal.half]
bearing_deg = [0.0, 180.0]
relative = [1.0, 0.5]

[[light]]
name = "buoy"
position_m = [0.0, 2.0, -1852.0]
intensity_cd = 250.0
colour = "green"
rhythm = "Fl(2) 10s"
vertical_profile = "lantern"

[[light]]
name = "sector.light"
position_m = [100.0, 10.0, -3000.0]
intensity_cd = 1000.0
xy = [0.31, 0.33]
sectors = [{ from_deg = 0, to_deg = 90, level = 1.0 }, { from_deg = 90, to_deg = 180, level = 0.5 }]

[[light]]
name = "range"
position_m = [-50.0, 5.0, -900.0]
intensity_cd = 80.0
spd = "led-blue"
horizontal_profile = "half"
rhythm = "Oc 4s"

[[light]]
name = "lighthouse"
position_m = [300.0, 40.0, -8000.0]
intensity_cd = 50000.0
rhythm = "Al.WR 4s"
)";

}  // namespace

// The scene itself must load, or every input would only test a refusal.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
    (void)atonlab::stimuli::parse_scene(kScene, "fuzz-scene.toml", {});  // throws (and aborts) if it does not
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        std::vector<atonlab::stimuli::SceneOverride> overrides;
        while (overrides.size() < 4) {
            const auto newline = text.find('\n');
            overrides.push_back(atonlab::stimuli::SceneOverride::parse(text.substr(0, newline)));
            if (newline == std::string_view::npos) break;
            text.remove_prefix(newline + 1);
        }
        (void)atonlab::stimuli::parse_scene(kScene, "fuzz-scene.toml", overrides);
    } catch (const atonlab::InputError&) {
        // A refusal with a sentence.
    }
    return 0;
}
