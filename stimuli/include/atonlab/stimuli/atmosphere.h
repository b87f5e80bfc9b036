#pragma once
// The atmosphere between light and eye: Allard's law (K2012 eq 2.1, IALA
// E200-2) and Bouguer's law of extinction (K2012 eq 4.14).

namespace atonlab::stimuli {

inline constexpr double metres_per_nautical_mile = 1852.0;

/// Illuminance thresholds E_t at the eye (lux) of IALA E200-2.
inline constexpr double allard_threshold_night_lux = 2e-7;
inline constexpr double allard_threshold_day_lux = 1e-3;

/// Allard's law, K2012 eq 2.1 / IALA E200-2: the luminous intensity (cd) needed
/// for a light to be seen at range_nmi given the threshold E_t (lux) and the
/// meteorological visibility V (nmi). background_factor multiplies E_t for
/// background lighting (1 none, 10 minor, 100 substantial: IALA E200-2).
/// I = 3.43e6 * E_t * f * d^2 * 0.05^(-d/V), d and V in nmi.
double allard_intensity_cd(double range_nmi, double threshold_lux, double visibility_nmi,
                           double background_factor = 1.0);

/// Inverse of allard_intensity_cd: the range in nmi at which intensity_cd
/// reaches the threshold (monotonic; solved by bracketing + Newton in double,
/// relative error ~1e-15, finite for every finite positive intensity).
/// Returns 0 for intensity_cd <= 0 (or NaN) and +inf for +inf.
double allard_range_nmi(double intensity_cd, double threshold_lux, double visibility_nmi,
                        double background_factor = 1.0);

/// Nominal range (night, V = 10 nmi, E_t = 2e-7 lux) rounded to the NEAREST whole
/// nmi, which is how IALA E200-2 tabulates it: n nmi covers I(n - 0.5) .. I(n + 0.5),
/// e.g. 108..203 cd -> 6 nmi (I(5.5) = 107.8, I(6.5) = 203.2), 204..364 cd -> 7 nmi.
/// 0 for intensity_cd <= 0.
int nominal_range_nmi(double intensity_cd);

/// Allard's law the other way round (K2012 eq 2.1; IALA Dictionary 2-1-265):
/// the illuminance (lux) at the eye from intensity_cd at range_nmi,
/// E = I * T^d / (3.43e6 * d^2) with T = 0.05^(1/V) per nmi; 3.43e6 is IALA's
/// rounding of 1852^2 m^2 per nmi^2, so allard_illuminance_lux(allard_intensity_cd(d,
/// E_t, V), d, V) == E_t. +inf at d = 0 for a light that is on.
double allard_illuminance_lux(double intensity_cd, double range_nmi, double visibility_nmi);

/// The atmospheric transmissivity per nautical mile for meteorological visibility
/// V (nmi): T = 0.05^(1/V) (IALA E200-2; 0.7411 at V = 10 nmi, the IES's "0.74 per
/// nautical mile" of the nominal range). And its inverse, V = ln 0.05 / ln T for
/// 0 < T < 1 (T = 0.8, the COLREGs Annex I §8 value, is V = 13.4 nmi).
double allard_transmissivity_per_nmi(double visibility_nmi);
double visibility_nmi_from_transmissivity(double transmissivity_per_nmi);

/// The intensities (cd) that IALA E200-2's table gives a nominal range of n nmi:
/// [I(n - 0.5), I(n + 0.5)) at night, V = 10 nmi (first = 0 for n = 0); see
/// nominal_range_nmi. n >= 0.
struct IntensityBand {
    double lower_cd = 0;
    double upper_cd = 0;
};
IntensityBand nominal_range_band_cd(int range_nmi);

/// Extinction coefficient (1/m) for meteorological visibility V (metres) with
/// the 5% contrast threshold that Allard's law uses: sigma = -ln(0.05) / V.
double extinction_per_m_from_visibility_m(double visibility_m);

/// Bouguer's law, K2012 eq 4.14: transmittance T = exp(-sigma * d). sigma in 1/m, d in m.
double bouguer_transmittance(double extinction_per_m, double distance_m);

}  // namespace atonlab::stimuli
