#pragma once
// Wide-angle veiling glare after the CIE (Vos & van den Berg): the CIE glare
// spread function (GSF) of CIE 135/1-1999, "Disability glare" (Vos & van den
// Berg 1999; the "CIE standard Glare Spread Function" of McCann & Vonikakis
// 2018, Front. Psychol. 8:2079), and its energy-conserving form on the whole
// sphere. It is the equation the `cie` glare model uses.
//
// The GSF gives the equivalent veiling luminance L_veil (cd/m²) that a point
// glare source at θ degrees from the line of sight produces per unit
// illuminance E_glare (lx) it puts into the plane of the eye; L/E has the unit
// sr⁻¹, so it is a density per steradian of the light's energy:
//
//   L_veil / E_glare = [1 − 0.08 (A/70)⁴] · [9.2·10⁶ / (1 + (θ/0.0046)²)^1.5 + 1.5·10⁵ / (1 + (θ/0.045)²)^1.5]
//                    + [1 + 1.6 (A/70)⁴] · { [400 / (1 + (θ/0.1)²) + 3·10⁻⁸ θ²]
//                                           + p · [1300 / (1 + (θ/0.1)²)^1.5 + 0.8 / (1 + (θ/0.1)²)^0.5] }
//                    + 2.5·10⁻³ p
//
// θ in degrees, A the age in years, p the ocular pigmentation factor (0 very
// dark eyes, 0.5 brown, 1.0 light blue-green, 1.2 very light blue). It is
// finite at θ = 0 (the 0.0046° and 0.045° terms are the eye's PSF core), which
// is why the `cie` model uses it: a convolution kernel must have a finite
// integral, and this one's is 1.047 at A = 25, p = 0.5.
//
// It is NOT one of CIE 146:2002's three equations, "CIE equations for
// disability glare" (TC 1-50; Vos 2003, Clin Exp Optom 86(6):363-370):
//   - the Age-adjusted Stiles-Holladay Disability Glare equation, 1° < θ < 30°;
//   - the Small Angle Disability Glare equation, 0.1° < θ < 30°;
//   - the General Disability Glare equation, 0.1° < θ < 100°, with age and
//     pigmentation (cie146_general_veil_per_lux below):
//       L_veil / E_glare = 10/θ³ + (5/θ² + 0.1 p/θ) · (1 + (A/62.5)⁴) + 0.0025 p.
// Their 10/θ³ term makes the energy inside any small angle infinite, so none of
// them can be a GSF below 0.1°. Within 0.1° … 100° the GSF and the General
// equation differ: GSF / General = 1.37 at 0.3°, 1.27 at 1°, 1.08 at 3°, 0.91
// at 10°, 0.87 at 20° for A = 25, p = 0.5 (unit.CieEquation.*).
//
// The GSF this module applies keeps the GSF's value exactly at every θ ≥ 0.1°
// and changes it only inside 0.1°: there it is the GSF's excess over its 0.1°
// value, scaled by the one factor (1 − κ) that makes the integral over the
// sphere exactly 1:
//
//   GSF(θ) = f(θ)                                   θ ≥ 0.1°
//   GSF(θ) = f(0.1°) + (1 − κ) · (f(θ) − f(0.1°))   θ < 0.1°
//
// which is continuous at 0.1°, ≥ f(0.1°) > 0 for κ ≤ 1, and conserves energy.
// Beyond 100° the equation is used as it stands (its θ² term), as far as 180°.
#include <vector>

namespace atonlab::stimuli {

/// The observer of the CIE equation.
struct CieObserver {
    double age_years = 25.0;    ///< A, years (25: the young observer CIE 146 and CIE 135/1 take as reference)
    double pigmentation = 0.5;  ///< p: 0 very dark, 0.5 brown, 1.0 light blue-green, 1.2 very light blue eyes
};

struct GlareSettings;
/// The `cie` model's observer of these settings ([eye] cie_age_years and
/// cie_pigmentation, declared in glare_models/cie.cpp).
CieObserver cie_observer(const GlareSettings& g);

/// The CIE glare spread function of Vos & van den Berg (CIE 135/1-1999), the
/// `cie` model's equation: L_veil / E_glare in sr⁻¹ ((cd/m²)/lx) at θ degrees
/// from a point source. Finite and defined for every θ ≥ 0 (the header comment).
double cie_gsf_veil_per_lux(double theta_deg, const CieObserver& observer);

/// The CIE 146:2002 General Disability Glare equation: L_veil / E_glare in sr⁻¹
/// ((cd/m²)/lx) at θ degrees from a point source, 10/θ³ + (5/θ² + 0.1 p/θ)(1 +
/// (A/62.5)⁴) + 0.0025 p. Valid (CIE 146) for 0.1° ≤ θ ≤ 100°; infinite at 0.
/// Not used by the `cie` model; the eye validation compares with it.
double cie146_general_veil_per_lux(double theta_deg, const CieObserver& observer);

/// Smallest angle at which the GSF keeps the equation's value (degrees).
constexpr double kCieInnerDeg = 0.1;

/// The energy-conserving GSF of an observer (see the header comment).
struct CieGlareSpread {
    CieObserver observer;
    double kappa = 0;        ///< the share of the equation's excess inside 0.1° that is removed
    double at_inner_sr = 0;  ///< f(0.1°), sr⁻¹

    /// GSF(θ) in sr⁻¹ (fraction of the light's energy per steradian), θ in degrees, 0 … 180.
    double density_sr(double theta_deg) const;
};

/// Builds the GSF of an observer. Throws InputError (key "cie_age_years" or
/// "cie_pigmentation") for an age outside 0 … 100 years, a pigmentation outside
/// 0 … 1.2, or an observer whose equation puts more than all the light outside
/// 0.1° (κ > 1: no positive GSF conserves energy).
CieGlareSpread cie_glare_spread(const CieObserver& observer);

/// Energy of the GSF within the ring θ0 ≤ θ ≤ θ1 of the sphere (degrees, 0 … 180):
/// ∫ GSF(θ) 2π sin θ dθ by Simpson's rule in ln θ, fine near 0 (relative error
/// below 1e-8 for the GSF).
double cie_energy_between(const CieGlareSpread& gsf, double theta0_deg, double theta1_deg);

/// The same for the raw glare spread function (cie_gsf_veil_per_lux, no change inside 0.1°).
double cie_gsf_energy_between(const CieObserver& observer, double theta0_deg, double theta1_deg);

}  // namespace atonlab::stimuli
