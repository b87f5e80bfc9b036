#pragma once
// Scotopic and mesopic photometry: the CIE 1951 scotopic luminous efficiency V'(lambda), the S/P ratio of
// a spectrum, and the mesopic luminance of CIE 191:2010's recommended system (MES2). No GL: the reference
// the tone mappers' mesopic checks compare against (docs/tone-mapping.md, "Mesopic photometry").
//
// Units: photopic luminance in cd/m² (K_m = 683 lm/W on V(lambda)); scotopic luminance in scotopic cd/m²
// (K'_m = 1700 lm/W on V'(lambda)); mesopic luminance in mesopic cd/m² (CIE TN 004:2016's "cd/m²" under
// V_mes). The S/P ratio is dimensionless.
#include "atonlab/display/colour.h"

namespace atonlab::display {

/// Maximum luminous efficacy for photopic vision, K_m, in lm/W: ISO 23539:2005/CIE S 010/E:2004 (683.002
/// lm/W from the SI definition of the candela, rounded as CIE uses it).
inline constexpr double kPhotopicEfficacyLmPerW = 683.0;
/// Maximum luminous efficacy for scotopic vision, K'_m, in lm/W: CIE S 010/E:2004 (1700.06 lm/W, rounded).
/// CIE 191:2010 writes V'(555 nm) = 683/1699, i.e. K'_m = 683/0.402 = 1699 lm/W; the two differ by 0.06 %.
inline constexpr double kScotopicEfficacyLmPerW = 1700.0;

/// CIE 1951 scotopic spectral luminous efficiency V'(lambda) at wavelength_nm: 1 at 507 nm, linearly
/// interpolated from the 1 nm CIE table (cie_tables.cpp cites it); 0 outside 380..780 nm and for NaN.
double cie1951_scotopic_efficiency(double wavelength_nm);

/// S/P ratio of a spectrum: (K'_m ∫S V' dλ) / (K_m ∫S V dλ), dimensionless, with V = ȳ of the CIE 1931
/// observer and the spectrum's own step as dλ (as spectrum_to_xyz). It is the scotopic luminance, in
/// scotopic cd/m², of light of that spectrum at 1 photopic cd/m². Throws InputError when the spectrum has
/// no photopic luminance (nothing between 360 and 830 nm), where the ratio is undefined.
double scotopic_to_photopic_ratio(const Spectrum& spd);

/// Scotopic luminance in scotopic cd/m² of light of spectrum spd whose photopic luminance is
/// photopic_cd_m2 (cd/m²): photopic_cd_m2 · S/P. Linear in photopic_cd_m2. Throws as
/// scotopic_to_photopic_ratio.
double scotopic_luminance_cd_m2(const Spectrum& spd, double photopic_cd_m2);

/// The mesopic state of CIE 191:2010's MES2 system for one adaptation field.
struct MesopicLuminance {
    double luminance_cd_m2 = 0.0;  ///< mesopic luminance L_mes, mesopic cd/m²
    double adaptation_m = 1.0;     ///< adaptation coefficient m in [0, 1]: 1 photopic, 0 scotopic
};

/// MES2's m = a + b log10(L_mes): a and b as CIE 191:2010 prints them (the tone mapper's GLSL twin
/// repeats them: stimuli/shaders/tonemap.glsl).
inline constexpr double kMesopicAdaptationA = 0.7670;
inline constexpr double kMesopicAdaptationB = 0.3334;
/// V'(lambda_0) at lambda_0 = 555 nm as CIE 191:2010 writes it: 683/1699 (= 0.402, the table's V'(555)).
inline constexpr double kMesopicScotopicAt555 = 683.0 / 1699.0;

/// Lower and upper photopic luminance of the mesopic range of CIE 191:2010 (and CIE TN 007:2017), cd/m².
inline constexpr double kMesopicLowerPhotopicCdM2 = 0.005;
inline constexpr double kMesopicUpperPhotopicCdM2 = 5.0;

/// Mesopic luminance (mesopic cd/m²) and adaptation coefficient m of a field of photopic luminance
/// photopic_cd_m2 (cd/m², >= 0) and S/P ratio s_p_ratio (> 0), by CIE 191:2010's MES2 system (as CIE TN 007:2017
/// restates it):
///   L_mes = (m L_p + (1 − m) L_s V'(λ0)) / (m + (1 − m) V'(λ0)),  L_s = (S/P) L_p,  V'(λ0) = 683/1699,
///   m = a + b log10(L_mes), 0 <= m <= 1, a = 0.7670, b = 0.3334,
/// solved by the standard's fixed-point iteration from m = 0.5. Outside the mesopic range of photopic
/// luminance: at or above 5 cd/m², m = 1 and L_mes = L_p (photopic); at or below 0.005 cd/m², m = 0 and
/// L_mes = L_s (scotopic). Throws InputError for a negative or non-finite luminance or a non-positive or
/// non-finite S/P ratio.
MesopicLuminance mesopic_luminance_cd_m2(double photopic_cd_m2, double s_p_ratio);

}  // namespace atonlab::display
