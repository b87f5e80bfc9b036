#pragma once
// Emission profiles of a light, in light space (K2012 §4.1.1-4.1.2, §5.1).
// Tables are sampled uniformly and linearly interpolated; the GLSL in
// shaders/light_model.glsl does exactly the same arithmetic, so the tests can
// compare CPU and GPU to 1e-5.
#include <span>
#include <string>
#include <vector>

namespace atonlab::stimuli {

/// Vertical profile, K2012 eq 4.1-4.2: n >= 2 values at p_j = j / (n-1) where
/// p = (cos θ + 1) / 2 and θ is the polar angle from the light's up axis
/// (p = 1 straight up, p = 0.5 horizontal, p = 0 straight down). Clamped at the ends.
struct VerticalProfile {
    std::vector<float> table;

    /// All ones (an unshielded light).
    static VerticalProfile uniform(int n = 2);
    /// From (elevation_deg, relative) pairs, elevation = 90° - θ in [-90, 90],
    /// sorted by elevation, linearly interpolated in elevation and resampled to n
    /// entries in p; flat beyond the first and last pair.
    static VerticalProfile from_elevation_table(std::span<const double> elevation_deg,
                                                std::span<const double> relative, int n = 256);

    /// CPU reference of the lookup: p in [0, 1].
    double at_p(double p) const;
    double at_cos_theta(double cos_theta) const { return at_p(0.5 * cos_theta + 0.5); }
};

/// A horizontal sector: lit from from_deg clockwise to to_deg (bearings from
/// the light towards the observer, in light space: 0 = light-local north (-z),
/// 90 = east (+x)), full relative level inside, falling linearly to zero over
/// edge_deg outside each edge so neighbouring sectors overlap gradually (K2012 §2.2).
struct Sector {
    double from_deg = 0;
    double to_deg = 360;
    double level = 1;
    double edge_deg = 0;
};

/// Horizontal profile, K2012 eq 4.3-4.4: n values at bearing i * 360 / n,
/// periodic, linearly interpolated.
struct HorizontalProfile {
    std::vector<float> table;

    static HorizontalProfile uniform(int n = 1);
    /// Sectors (several allowed, a sector may wrap through 0°); where they
    /// overlap the maximum is taken. Sampled at n points (default 0.1°).
    static HorizontalProfile from_sectors(std::span<const Sector> sectors, int n = 3600);
    /// From (bearing_deg, relative) pairs over 0..360, periodic, linearly interpolated.
    static HorizontalProfile from_bearing_table(std::span<const double> bearing_deg,
                                                std::span<const double> relative, int n = 3600);

    /// CPU reference of the lookup: bearing in degrees, any real (wrapped).
    double at_bearing_deg(double bearing_deg) const;
};

/// Builtin vertical profile of the Sabik VP LED buoy lantern that K2012 §2.3 uses
/// as its reference: "50% peak intensity at 10° and 10% peak intensity at 20°"
/// (the thesis says "horizontal", meaning the spread away from the horizontal
/// plane: the lantern is all-round). Fit: a generalised Gaussian in elevation
/// e (degrees), B(e) = exp(-ln2 * (|e| / 10)^k), k = log2(log2 10) = 1.7320...,
/// which passes exactly through 1 at 0°, 0.5 at ±10° and 0.1 at ±20° (an
/// ordinary Gaussian through 0.5 at 10° gives 0.0625 at 20°). Symmetric, no
/// data beyond 20°: it is an extrapolation there (0.0096 at 30°).
double sabik_vp_relative_intensity(double elevation_deg);
/// sabik_vp_relative_intensity tabulated at n points uniform in p (eq 4.1).
/// With n = 256 the linear lookup is within 1e-3 of the fit everywhere (the
/// worst error is at the peak), within 1e-4 at ±10° and ±20°.
VerticalProfile sabik_vp_vertical_profile(int n = 256);

/// Light-space bearing (degrees in [0, 360)) of a light-space direction towards
/// the eye: atan2(x, -z), clockwise from -z. K2012 eq 4.4 uses atan2(x, z) + π;
/// ours is the same parameterisation rotated by 180° so sector limits read as
/// bearings on a chart.
/// The zero vector (x = z = 0: straight up or down) gives 0.
double bearing_deg_of_direction(double x, double z);

}  // namespace atonlab::stimuli
