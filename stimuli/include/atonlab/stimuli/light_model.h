#pragma once
// The ATON light model evaluated at the eye (K2012 §4.1, §4.3.1, §5.1): the CPU
// reference of shaders/light_model.glsl. Both compute, per colour channel,
//   E = I · rgb · P_v(θ) · P_h(φ) · B(t) · T(d) / d²     (lux; Y channel = illuminance)
// with the profiles looked up in light space (listing 5.1), Bouguer's fog
// (eq 4.14) and the rhythm B(t).
#include <glm/glm.hpp>

#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli {

struct LightAtEye {
    glm::dvec3 illuminance_rgb_lux{0.0};  ///< per channel; luminance-weighted sum = illuminance in lux
    double distance_m = 0;                ///< light centre to eye
    double cos_theta = 0;                 ///< cosine of the polar angle from the light's up axis to the eye
    double bearing_deg = 0;               ///< light-space bearing of the eye (profile.h convention)
    double vertical = 0, horizontal = 0;  ///< profile factors
    double rhythm = 0;                    ///< B(t)
    double transmittance = 0;             ///< T(d)
};

/// Evaluates one light for an eye at eye_position_m at time time_s (seconds).
/// A light whose centre coincides with the eye (d = 0) returns zero illuminance
/// (the inverse-square law is singular there; the renderer culls d <= radius).
LightAtEye evaluate_light(const Light& light, const ProfileTables& profiles, glm::dvec3 eye_position_m,
                          double time_s, double extinction_per_m);

/// Illuminance (lux) at the eye: the luminance-weighted sum of the channels
/// (Y = 0.2126 R + 0.7152 G + 0.0722 B).
double illuminance_lux(const LightAtEye& s);

/// World-from-local rotation for yaw (clockwise from north about +y), pitch
/// (up positive, about the local +x) and roll (about the local forward axis,
/// positive tilts the up vector to the right). Used by cameras and lights.
glm::dquat orientation_from_yaw_pitch_roll(double yaw_deg, double pitch_deg, double roll_deg);

}  // namespace atonlab::stimuli
