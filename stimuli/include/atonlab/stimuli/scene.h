#pragma once
// A scene: what the renderer draws in one frame (DESIGN.md "File formats").
// World frame: metres, right-handed, x east, y up, -z north. Bearings and yaw
// are clockwise from north, as on a chart.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "atonlab/stimuli/profile.h"
#include "atonlab/stimuli/rhythm.h"

namespace atonlab::stimuli {

/// The observer's display. With square pixels and a veridical camera the
/// pinhole's focal length in pixels is viewing_distance * width_px / width_m.
struct DisplayGeometry {
    int width_px = 1920;
    int height_px = 1080;
    double width_m = 0.598;             ///< visible width of the picture, metres
    double viewing_distance_m = 0.9;    ///< eye to screen, metres

    double height_m() const { return width_m * height_px / width_px; }
    double focal_px() const { return viewing_distance_m * width_px / width_m; }
    double fov_x_rad() const;           ///< visual angle the display subtends horizontally
    double fov_y_rad() const;           ///< ... vertically
    double pixels_per_degree_at_centre() const;  ///< focal_px * π/180 (small-angle, at the centre)
};

struct Camera {
    glm::dvec3 position_m{0.0, 3.0, 0.0};
    double yaw_deg = 0.0;    ///< heading, clockwise from north (-z)
    double pitch_deg = 0.0;  ///< up positive
    double roll_deg = 0.0;   ///< clockwise positive, looking forward
    std::optional<double> fov_y_deg;  ///< vertical field of view; default: the display's visual angle

    /// World-from-camera rotation: camera looks down its -z, +y up, +x right.
    glm::dquat orientation() const;
};

enum class Background : std::uint8_t { uniform, sky_sea };

struct Environment {
    Background background = Background::sky_sea;
    double luminance_cd_m2 = 0.001;          ///< sky (or uniform field) luminance
    double sea_reflectance_f0 = 0.02;        ///< Schlick R_F(0°) of the sea (K2012 eq 3.17, §3.6.1)
    double extinction_per_m = 0.0;           ///< Bouguer σ (K2012 eq 4.14); 0 = clear
};

/// A light's emission pattern shared by lights (K2012 §5.1: profiles are
/// shared through ids).
struct ProfileTables {
    std::vector<VerticalProfile> vertical{VerticalProfile::uniform()};
    std::vector<HorizontalProfile> horizontal{HorizontalProfile::uniform()};
};

/// One ATON light (K2012 §4.1): an isotropic sphere of radius radius_m shielded
/// by its profiles, modulated by its rhythm. One colour: a sectored lighthouse is
/// several lights sharing a position and a horizontal profile table.
struct Light {
    std::string name;
    glm::dvec3 position_m{0.0};
    glm::dquat orientation{1.0, 0.0, 0.0, 0.0};  ///< world-from-light
    double radius_m = 0.1;
    double intensity_cd = 100.0;                 ///< peak luminous intensity
    glm::dvec3 rgb_per_cd{1.0};                  ///< linear Rec.709, normalised to Y = 1 (K2012 table 4.1)
    int vertical_profile = 0;                    ///< index into ProfileTables::vertical
    int horizontal_profile = 0;                  ///< index into ProfileTables::horizontal
    std::vector<RhythmKnot> rhythm{{0.0, 1.0}};  ///< B(t) knots of this light's colour channel
    double rhythm_period_s = 0.0;                ///< 0 = fixed
    double rhythm_phase_s = 0.0;                 ///< added to the time before the rhythm lookup
};

struct Scene {
    DisplayGeometry display;
    Camera camera;
    Environment environment;
    ProfileTables profiles;
    std::vector<Light> lights;
    double adaptation_cd_m2 = 0.001;  ///< recorded in image headers; drives later stages
};

}  // namespace atonlab::stimuli
