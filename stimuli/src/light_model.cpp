#include "atonlab/stimuli/light_model.h"

#include <cmath>
#include <numbers>

#include <glm/gtc/quaternion.hpp>

#include "atonlab/stimuli/atmosphere.h"
#include "atonlab/display/colour.h"

namespace atonlab::stimuli {

glm::dquat orientation_from_yaw_pitch_roll(double yaw_deg, double pitch_deg, double roll_deg) {
    const double k = std::numbers::pi / 180.0;
    // Yaw clockwise seen from above = negative rotation about +y (right-handed).
    const glm::dquat yaw = glm::angleAxis(-yaw_deg * k, glm::dvec3(0, 1, 0));
    const glm::dquat pitch = glm::angleAxis(pitch_deg * k, glm::dvec3(1, 0, 0));
    // Roll about the forward axis (−z): by the right-hand rule a positive angle
    // turns +y clockwise as seen looking forward, i.e. towards +x.
    const glm::dquat roll = glm::angleAxis(roll_deg * k, glm::dvec3(0, 0, -1));
    return yaw * pitch * roll;
}

LightAtEye evaluate_light(const Light& light, const ProfileTables& profiles, glm::dvec3 eye, double time_s,
                          double extinction_per_m) {
    LightAtEye s;
    const glm::dvec3 to_eye = eye - light.position_m;
    s.distance_m = glm::length(to_eye);
    if (!(s.distance_m > 0.0)) return s;
    // K2012 listing 5.1: the profiles are looked up in light space.
    const glm::dvec3 e = glm::conjugate(light.orientation) * (to_eye / s.distance_m);
    s.cos_theta = e.y;
    s.bearing_deg = bearing_deg_of_direction(e.x, e.z);
    s.vertical = profiles.vertical.at(static_cast<std::size_t>(light.vertical_profile)).at_cos_theta(s.cos_theta);
    s.horizontal =
        profiles.horizontal.at(static_cast<std::size_t>(light.horizontal_profile)).at_bearing_deg(s.bearing_deg);
    s.rhythm = rhythm_level(light.rhythm, light.rhythm_period_s, time_s + light.rhythm_phase_s);
    s.transmittance = bouguer_transmittance(extinction_per_m, s.distance_m);  // K2012 eq 4.14
    const double factor = light.intensity_cd * s.vertical * s.horizontal * s.rhythm * s.transmittance /
                          (s.distance_m * s.distance_m);
    s.illuminance_rgb_lux = light.rgb_per_cd * factor;
    return s;
}

double illuminance_lux(const LightAtEye& s) { return display::luminance_of_linear_rgb(s.illuminance_rgb_lux); }

glm::dquat Camera::orientation() const { return orientation_from_yaw_pitch_roll(yaw_deg, pitch_deg, roll_deg); }


}  // namespace atonlab::stimuli
