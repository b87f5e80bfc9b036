#pragma once
// Colour science (K2012 §3.2-3.3, §4.1). All RGB here is *linear* Rec.709/sRGB
// primaries with a D65 white, on an absolute scale where Y = 0.2126 R + 0.7152 G
// + 0.0722 B. No transfer function unless a name says "srgb_encode/decode".
#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

namespace atonlab::display {

using Mat3 = glm::dmat3;  ///< column-major (glm): m[col][row]
using Vec3 = glm::dvec3;

// ---------------------------------------------------------------------------
// Tabulated CIE data (cie_tables.cpp cites its source).

/// CIE 1931 2° standard observer colour-matching functions x̄, ȳ, z̄ at the
/// given wavelength in nm, linearly interpolated from the 1 nm CIE table;
/// zero outside 360..830 nm.
Vec3 cie1931_cmf(double wavelength_nm);

/// CIE standard illuminant D65 relative spectral power (100 at 560 nm),
/// linearly interpolated from the CIE table; zero outside the table's range.
double cie_d65(double wavelength_nm);

// ---------------------------------------------------------------------------
// Spectra.

/// A spectral power distribution sampled uniformly from first_nm in step_nm.
/// Units are relative (radiometric power per nm); only ratios matter because
/// lights are normalised to a luminous intensity.
struct Spectrum {
    double first_nm = 360.0;
    double step_nm = 1.0;
    std::vector<double> values;

    double at(double wavelength_nm) const;  ///< linear interpolation, 0 outside
    double last_nm() const { return first_nm + step_nm * static_cast<double>(values.size() - 1); }
};

/// D65 as a Spectrum (1 nm, 300..830 nm or the table's range).
Spectrum d65_spectrum();

/// A Gaussian band: peak_nm, fwhm_nm (full width at half maximum), 1 nm samples 360..830.
Spectrum gaussian_spectrum(double peak_nm, double fwhm_nm);

/// The white LED of K2012 §6.1 / fig 3.2a: a blue pump Gaussian plus a broad
/// phosphor Gaussian (parameters documented in colour.cpp).
Spectrum white_led_spectrum();

/// Named SPDs: "d65", "led-white", "led-red", "led-green", "led-blue",
/// "led-yellow" (narrow-band coloured LEDs, peaks and widths documented), and
/// "iala-red", "iala-green", "iala-blue", "iala-yellow": the LED dies whose
/// chromaticities lie in those colours' signal-light areas (iala_colour_spectrum_name).
/// Returns nullopt for an unknown name.
std::optional<Spectrum> named_spectrum(std::string_view name);

/// Names accepted by named_spectrum(), for error messages.
std::vector<std::string> spectrum_names();

/// Spectrum -> CIE XYZ by integrating against the CMFs (K2012 eq 3.8), with
/// the step of the spectrum. Scale is arbitrary (relative SPD).
Vec3 spectrum_to_xyz(const Spectrum& spd);

// ---------------------------------------------------------------------------
// Colour spaces.

/// xy chromaticity of CIE D65 from the CIE 1931 2° observer (0.3127, 0.3290).
glm::dvec2 d65_white_xy();

/// RGB -> XYZ matrix derived from primaries' and white's xy chromaticities
/// (SMPTE RP 177 method): columns are the primaries' XYZ scaled so that
/// RGB (1,1,1) maps to the white with Y = 1.
Mat3 rgb_to_xyz_matrix(glm::dvec2 red_xy, glm::dvec2 green_xy, glm::dvec2 blue_xy, glm::dvec2 white_xy);

/// Rec.709 / sRGB primaries with D65 white (K2012 eq 3.11, derived, not the
/// rounded printed matrix).
const Mat3& rec709_rgb_to_xyz();
const Mat3& rec709_xyz_to_rgb();  ///< its inverse (K2012 eq 3.12; the thesis prints the input as Z,Y,X: a typo)

Vec3 xyz_to_linear_rgb(Vec3 xyz);
Vec3 linear_rgb_to_xyz(Vec3 rgb);
double luminance_of_linear_rgb(Vec3 rgb);  ///< Y = 0.2126 R + 0.7152 G + 0.0722 B (derived coefficients)

/// Brings linear RGB (relative to the display's white, 1 = full drive of a channel) into the
/// display's gamut [0, 1]³ keeping its luminance and giving up chroma: negatives and NaN are
/// black, and a colour with a channel above 1 is moved along the line to the grey of equal
/// luminance, Y + t (RGB - Y), with the largest t that keeps every channel <= 1. Luminance is
/// Y = w · RGB with the display's channel weights w (each channel's white luminance over the
/// white's; they sum to 1; Rec.709's for an sRGB display). A colour brighter than white
/// (Y >= 1) becomes white. So the luminance shown is min(1, Y) and never falls when Y rises,
/// whatever happens to chroma: a brightness match measures luminance (docs/tone-mapping.md
/// "Adding light never darkens").
Vec3 fit_to_gamut_keeping_luminance(Vec3 rgb, Vec3 channel_weights);

/// xyY <-> XYZ (K2012 eq 3.9, 3.10). xyz_to_xyY of black returns the D65 xy with Y = 0.
Vec3 xyY_to_xyz(Vec3 xyY);
Vec3 xyz_to_xyY(Vec3 xyz);

/// sRGB transfer functions (IEC 61966-2-1; K2012 eq 3.13), for values in [0, 1];
/// inputs outside are clamped.
double srgb_encode(double linear);
double srgb_decode(double encoded);

// ---------------------------------------------------------------------------
// Light colours. Every light colour is a linear RGB triple normalised to
// luminance Y = 1 (K2012 table 4.1), multiplied by the light's luminous
// intensity in cd to give per-channel intensity.

/// Linear RGB normalised to Y = 1 for chromaticity xy. Out-of-gamut chromaticities
/// give negative components; pass clip_to_gamut to clamp them at 0 and renormalise to Y = 1.
/// Clipped results are finite for every valid xy; unclipped components grow as 1/y and
/// overflow to ±inf for y below ~1e-307 (docs/numerical-behaviour.md).
Vec3 normalised_rgb_from_xy(glm::dvec2 xy, bool clip_to_gamut = false);

/// Linear RGB normalised to Y = 1 for an SPD (clipped to the gamut as above).
Vec3 normalised_rgb_from_spectrum(const Spectrum& spd);

/// IALA colour names of K2012 table 4.1: "white", "red", "red-optimum",
/// "green", "blue", "yellow". Returns the xy the thesis chose in the sRGB gamut.
std::optional<glm::dvec2> iala_colour_xy(std::string_view name);
/// The same as normalised linear RGB (table 4.1 reproduced).
std::optional<Vec3> iala_colour_rgb(std::string_view name);
std::vector<std::string> iala_colour_names();
/// The named_spectrum() a light of this IALA colour integrates its glare over
/// when it names no `spd`: one whose CIE 1931 chromaticity lies in the colour's
/// signal-light area ("d65" for white, "iala-red" for red and red-optimum,
/// "iala-green", "iala-blue", "iala-yellow"; colour.cpp gives each die). The
/// displayed colour stays iala_colour_rgb(). nullopt for an unknown name.
std::optional<std::string> iala_colour_spectrum_name(std::string_view name);

/// Chart letters -> IALA colour name: "W" white, "R" red, "G" green, "Bu" blue,
/// "Y" yellow (used by Al. rhythms such as "Al.WR").
std::optional<std::string> iala_colour_from_chart_letter(std::string_view letter);

}  // namespace atonlab::display
