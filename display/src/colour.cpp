// Colour science: spectra, CIE XYZ / xyY, linear Rec.709 RGB, the sRGB transfer function and the
// IALA light colours of K2012 §3.2-3.3 and §4.1. Tables live in cie_tables.cpp.
#include "atonlab/display/colour.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "atonlab/common/input_error.h"
#include "cie_tables.h"

namespace atonlab::display {
namespace {

// Rec. ITU-R BT.709-6 item 1.3/1.4 (= IEC 61966-2-1 sRGB) primaries and white, as specified (4 decimals).
// K2012 table 3.4 prints the blue x as 0.015: a typo for 0.15 (test Rec709Matrix.BluePrimaryTypoInTable34).
constexpr glm::dvec2 kRec709Red{0.64, 0.33};
constexpr glm::dvec2 kRec709Green{0.30, 0.60};
constexpr glm::dvec2 kRec709Blue{0.15, 0.06};
constexpr glm::dvec2 kD65WhiteXy{0.3127, 0.3290};

// Sampling of the Gaussian LED spectra: the CMF table's own range and step.
constexpr double kLedFirstNm = 360.0;
constexpr double kLedLastNm = 830.0;

// White LED (K2012 §6.1, fig 3.2a "Gaussian approximated white LED"): an InGaN blue pump plus a broad
// YAG:Ce phosphor band, both Gaussian. With the pump's peak 1.75 times the phosphor's, the CIE 1931 2°
// chromaticity is xy = (0.3165, 0.3270), about 6300 K by McCamy's CCT formula and within 0.001 of the
// Planckian locus: a cool white close to D65, like the white ATON LEDs of K2012 §2.3.
constexpr double kWhiteLedPumpPeakNm = 450.0;
constexpr double kWhiteLedPumpFwhmNm = 25.0;
constexpr double kWhiteLedPumpToPhosphor = 1.75;  // ratio of peak spectral powers (relative units)
constexpr double kWhiteLedPhosphorPeakNm = 565.0;
constexpr double kWhiteLedPhosphorFwhmNm = 120.0;

// Narrow-band coloured LEDs (typical AlInGaP red/amber and InGaN green/blue dies): peak, FWHM in nm,
// and the CIE 1931 xy that results (all four lie outside the Rec.709 gamut, so they are clipped):
//   led-red     625 nm, 20 nm  -> (0.6945, 0.3054)
//   led-green   525 nm, 30 nm  -> (0.1424, 0.7756)
//   led-blue    465 nm, 25 nm  -> (0.1353, 0.0471)
//   led-yellow  590 nm, 20 nm  -> (0.5704, 0.4289)
struct NarrowBandLed {
    const char* name;
    double peak_nm;
    double fwhm_nm;
};
//
// The IALA colours' glare spectra (iala_colour_spectrum_name): typical ATON LED dies, each tuned so its
// CIE 1931 xy lies inside its colour's signal-light area (COLREGs 1972 Annex I §7 for red, green and
// yellow; ICAO Annex 14 Vol I Appendix 1, after CIE S 004, for blue), with the FWHM of such dies:
//   iala-red     625 nm, 20 nm  -> (0.6945, 0.3054)  AlInGaP red (the led-red die)
//   iala-green   505 nm, 30 nm  -> (0.0477, 0.5977)  InGaN "signal green" (a 525 nm die, led-green,
//                                                    lies at y = 0.776, above the green area's yellow edge)
//   iala-blue    465 nm, 25 nm  -> (0.1353, 0.0471)  InGaN blue (the led-blue die)
//   iala-yellow  592 nm, 15 nm  -> (0.5835, 0.4159)  AlInGaP amber (a 590 nm, 20 nm die, led-yellow, lies
//                                                    at x = 0.570, left of the yellow area's x = 0.575 edge)
constexpr std::array<NarrowBandLed, 8> kNarrowBandLeds = {{
    {"led-red", 625.0, 20.0},
    {"led-green", 525.0, 30.0},
    {"led-blue", 465.0, 25.0},
    {"led-yellow", 590.0, 20.0},
    {"iala-red", 625.0, 20.0},
    {"iala-green", 505.0, 30.0},
    {"iala-blue", 465.0, 25.0},
    {"iala-yellow", 592.0, 15.0},
}};

// IALA light colours as K2012 table 4.1 maps them into the Rec.709 gamut. The thesis prints xy to two
// decimals only; what is stored here is the chromaticity that reproduces the table's normalised RGB:
//   white        D65 itself (Rec.709's 0.3127, 0.3290): RGB (1, 1, 1). The table's "(0.31, 0.33)" is
//                that point rounded.
//   red          the Rec.709 red primary (0.64, 0.33): RGB (1/0.2126, 0, 0).
//   red-optimum  (0.62, 0.32), the centre of the IALA "optimum" red region, slightly magenta.
//   green        (0.28, 0.52).
//   blue         the Rec.709 blue primary (0.15, 0.06): RGB (0, 0, 1/0.0722).
//   yellow       (0.5396, 0.4097), on the red-green edge of the gamut (B = 0), where K2012 §4.1 puts it
//                ("on the sRGB triangle boundary"). The printed (0.54, 0.41) lies just outside the gamut
//                and gives B = -0.0018 instead of the table's 0.0000.
// What the table was computed with: converting its RGB back with the forward matrix, and recomputing it
// from these xy, shows that it used the full-precision inverse of the matrix whose white is
// XYZ = (0.95047, 1, 1.08883), i.e. D65 integrated through the CIE tables (xy 0.31273, 0.32902). That
// matrix reproduces every printed digit for red (4.7021 = 1/0.2126729), blue (13.8552 = 1/0.0721750),
// green and red-optimum except its G (0.0058 vs 0.0059), and its inverse rounded to 4 decimals is exactly
// K2012 eq 3.12. Eq 3.11, by contrast, is the matrix derived from the specified white (0.3127, 0.3290).
// We derive both matrices from the specified white (Rec.709, docs/architecture.md), which moves the table's values
// by at most 2.4e-4 relative (red 4.7028, blue 13.8519): inside the 1e-3 the tests hold it to.
//
// `spectrum` is the named spectrum its glare is integrated over (docs/glare.md "The light's spectrum"):
// white keeps D65, whose xy lies 0.0027 inside the white area's blue edge (x = 0.310); red-optimum
// shares red's die (IALA's narrower "optimum" red area was not at hand; the die lies in the red area).
struct IalaColour {
    const char* name;
    glm::dvec2 xy;
    const char* spectrum;
};
constexpr std::array<IalaColour, 6> kIalaColours = {{
    {"white", kD65WhiteXy, "d65"},
    {"red", kRec709Red, "iala-red"},
    {"red-optimum", {0.62, 0.32}, "iala-red"},
    {"green", {0.28, 0.52}, "iala-green"},
    {"blue", kRec709Blue, "iala-blue"},
    {"yellow", {0.5396, 0.4097}, "iala-yellow"},
}};

// Chart abbreviations (IALA / INT 1 light characters): "Bu" is blue; a bare "B" is not a colour on
// charts, so it is not accepted.
struct ChartLetter {
    const char* letter;
    const char* colour;
};
constexpr std::array<ChartLetter, 5> kChartLetters = {{
    {"W", "white"},
    {"R", "red"},
    {"G", "green"},
    {"Bu", "blue"},
    {"Y", "yellow"},
}};

Vec3 xyz_of_unit_luminance(glm::dvec2 xy) { return xyY_to_xyz(Vec3(xy, 1.0)); }

void check_chromaticity(glm::dvec2 xy, const char* what) {
    if (!std::isfinite(xy.x) || !std::isfinite(xy.y) || xy.y <= 0.0 || xy.x < 0.0 || xy.x + xy.y > 1.0) {
        throw InputError(
            fmt::format("{} chromaticity xy = ({}, {}) is not a colour: it needs x >= 0, "
                        "y > 0 and x + y <= 1",
                        what, xy.x, xy.y));
    }
}

}  // namespace

// ---------------------------------------------------------------------------
// Spectra.

double Spectrum::at(double wavelength_nm) const {
    if (values.empty()) return 0.0;
    const double t = (wavelength_nm - first_nm) / step_nm;
    const auto last = static_cast<double>(values.size() - 1);
    if (!(t >= 0.0 && t <= last)) return 0.0;  // outside, or NaN
    if (values.size() == 1) return values[0];
    const auto i = std::min(static_cast<std::size_t>(std::floor(t)), values.size() - 2);
    const double f = t - static_cast<double>(i);
    return values[i] * (1.0 - f) + values[i + 1] * f;
}

Spectrum d65_spectrum() {
    const auto table = cie::d65_table();
    return Spectrum{cie::kD65FirstNm, 1.0, std::vector<double>(table.begin(), table.end())};
}

Spectrum gaussian_spectrum(double peak_nm, double fwhm_nm) {
    if (!std::isfinite(peak_nm) || !std::isfinite(fwhm_nm) || fwhm_nm <= 0.0) {
        throw InputError(
            fmt::format("a Gaussian spectrum needs a finite peak and a positive finite FWHM "
                        "(got peak {} nm, FWHM {} nm)",
                        peak_nm, fwhm_nm));
    }
    // FWHM = 2 sqrt(2 ln 2) sigma.
    const double sigma = fwhm_nm / (2.0 * std::sqrt(2.0 * std::numbers::ln2));
    Spectrum s{kLedFirstNm, 1.0, {}};
    const auto n = static_cast<std::size_t>(kLedLastNm - kLedFirstNm) + 1;
    s.values.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double d = (kLedFirstNm + static_cast<double>(i) - peak_nm) / sigma;
        s.values[i] = std::exp(-0.5 * d * d);
    }
    return s;
}

Spectrum white_led_spectrum() {
    Spectrum s = gaussian_spectrum(kWhiteLedPhosphorPeakNm, kWhiteLedPhosphorFwhmNm);
    const Spectrum pump = gaussian_spectrum(kWhiteLedPumpPeakNm, kWhiteLedPumpFwhmNm);
    for (std::size_t i = 0; i < s.values.size(); ++i) s.values[i] += kWhiteLedPumpToPhosphor * pump.values[i];
    return s;
}

std::optional<Spectrum> named_spectrum(std::string_view name) {
    if (name == "d65") return d65_spectrum();
    if (name == "led-white") return white_led_spectrum();
    for (const auto& led : kNarrowBandLeds) {
        if (name == led.name) return gaussian_spectrum(led.peak_nm, led.fwhm_nm);
    }
    return std::nullopt;
}

std::vector<std::string> spectrum_names() {
    std::vector<std::string> names{"d65", "led-white"};
    for (const auto& led : kNarrowBandLeds) names.emplace_back(led.name);
    return names;
}

Vec3 spectrum_to_xyz(const Spectrum& spd) {
    // K2012 eq 3.8 as a Riemann sum with the spectrum's own step; the CMFs are zero outside 360..830 nm.
    Vec3 xyz(0.0);
    for (std::size_t i = 0; i < spd.values.size(); ++i) {
        const double wavelength_nm = spd.first_nm + spd.step_nm * static_cast<double>(i);
        xyz += spd.values[i] * cie1931_cmf(wavelength_nm);
    }
    return xyz * spd.step_nm;
}

// ---------------------------------------------------------------------------
// Colour spaces.

glm::dvec2 d65_white_xy() { return kD65WhiteXy; }

Mat3 rgb_to_xyz_matrix(glm::dvec2 red_xy, glm::dvec2 green_xy, glm::dvec2 blue_xy, glm::dvec2 white_xy) {
    check_chromaticity(red_xy, "the red primary's");
    check_chromaticity(green_xy, "the green primary's");
    check_chromaticity(blue_xy, "the blue primary's");
    check_chromaticity(white_xy, "the white point's");
    // SMPTE RP 177-1993 §3.3: columns are the primaries' XYZ at Y = 1, each scaled by S so that
    // P S = W (the white at Y = 1), i.e. RGB (1,1,1) -> white.
    const Mat3 p(xyz_of_unit_luminance(red_xy), xyz_of_unit_luminance(green_xy),
                 xyz_of_unit_luminance(blue_xy));
    if (std::abs(glm::determinant(p)) < 1e-12) {
        throw InputError(
            fmt::format("the primaries ({}, {}), ({}, {}), ({}, {}) are collinear: they span no "
                        "colour space",
                        red_xy.x, red_xy.y, green_xy.x, green_xy.y, blue_xy.x, blue_xy.y));
    }
    const Vec3 s = glm::inverse(p) * xyz_of_unit_luminance(white_xy);
    return Mat3(p[0] * s.x, p[1] * s.y, p[2] * s.z);
}

const Mat3& rec709_rgb_to_xyz() {
    // K2012 eq 3.11, derived rather than the printed (4-decimal) matrix.
    static const Mat3 m = rgb_to_xyz_matrix(kRec709Red, kRec709Green, kRec709Blue, kD65WhiteXy);
    return m;
}

const Mat3& rec709_xyz_to_rgb() {
    // K2012 eq 3.12: its input vector is (X, Y, Z), not the printed (Z, Y, X).
    static const Mat3 m = glm::inverse(rec709_rgb_to_xyz());
    return m;
}

Vec3 xyz_to_linear_rgb(Vec3 xyz) { return rec709_xyz_to_rgb() * xyz; }

Vec3 linear_rgb_to_xyz(Vec3 rgb) { return rec709_rgb_to_xyz() * rgb; }

Vec3 fit_to_gamut_keeping_luminance(Vec3 rgb, Vec3 w) {
    for (int c = 0; c < 3; ++c) rgb[c] = rgb[c] > 0.0 ? rgb[c] : 0.0;  // NaN and negatives: black
    const double y = glm::dot(w, rgb);
    if (!(y < 1.0)) return Vec3(1.0);  // at or beyond white (or +inf)
    const double m = std::max(rgb.r, std::max(rgb.g, rgb.b));
    if (m <= 1.0) return rgb;
    // m > 1 > y >= 0, so 0 <= t < 1; every channel stays >= y (1 - t) >= 0 and the largest is 1.
    const double t = (1.0 - y) / (m - y);
    return Vec3(y) + t * (rgb - Vec3(y));
}

double luminance_of_linear_rgb(Vec3 rgb) {
    // The Y row of eq 3.11 (glm is column-major: m[column][row]).
    const Mat3& m = rec709_rgb_to_xyz();
    return m[0][1] * rgb.r + m[1][1] * rgb.g + m[2][1] * rgb.b;
}

Vec3 xyY_to_xyz(Vec3 xyY) {
    // K2012 eq 3.10. A chromaticity with y = 0 carries no luminance: black.
    const double x = xyY.x;
    const double y = xyY.y;
    const double big_y = xyY.z;
    if (y == 0.0) return Vec3(0.0);
    return {big_y / y * x, big_y, big_y / y * (1.0 - x - y)};
}

Vec3 xyz_to_xyY(Vec3 xyz) {
    // K2012 eq 3.9. Black has no chromaticity; report the white's so that callers stay finite.
    const double sum = xyz.x + xyz.y + xyz.z;
    if (sum == 0.0) return Vec3(kD65WhiteXy, 0.0);
    return {xyz.x / sum, xyz.y / sum, xyz.y};
}

double srgb_encode(double linear) {
    // IEC 61966-2-1 / K2012 eq 3.13. NaN is treated as black so the encoder never emits NaN.
    const double v = std::isnan(linear) ? 0.0 : std::clamp(linear, 0.0, 1.0);
    if (v <= 0.0031308) return 12.92 * v;
    // The standard's rounded constants put the power segment 2.9e-8 below the linear one's
    // end just above the switch (they meet at 0.00313067, not 0.0031308): hold it at that end
    // until it catches up (within 2.2e-9 of the switch), so the encoder never decreases.
    return std::max(1.055 * std::pow(v, 1.0 / 2.4) - 0.055, 12.92 * 0.0031308);
}

double srgb_decode(double encoded) {
    // IEC 61966-2-1 inverse; the breakpoint 0.04045 is the encoder's 12.92 * 0.0031308 rounded.
    const double v = std::isnan(encoded) ? 0.0 : std::clamp(encoded, 0.0, 1.0);
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

// ---------------------------------------------------------------------------
// Light colours.

Vec3 normalised_rgb_from_xy(glm::dvec2 xy, bool clip_to_gamut) {
    check_chromaticity(xy, "the light's");
    // K2012 §4.1: xyY with Y = 1 -> XYZ (eq 3.10) -> RGB (eq 3.12).
    if (clip_to_gamut) {
        // Dropping negative (unrealisable) amounts of a primary can only add luminance, so the
        // luminance after clamping is >= y > 0 and the renormalisation is well defined. Clipping
        // and renormalising are scale-free, so start from XYZ = (x, y, 1 - x - y), Y = y: going
        // through Y = 1 first divides by y, which overflows to inf (then NaN) as y -> 0.
        Vec3 rgb = glm::max(xyz_to_linear_rgb(Vec3(xy.x, xy.y, 1.0 - xy.x - xy.y)), Vec3(0.0));
        return rgb / luminance_of_linear_rgb(rgb);
    }
    return xyz_to_linear_rgb(xyz_of_unit_luminance(xy));
}

Vec3 normalised_rgb_from_spectrum(const Spectrum& spd) {
    const Vec3 xyz = spectrum_to_xyz(spd);
    const double sum = xyz.x + xyz.y + xyz.z;
    if (!(xyz.y > 0.0) || !std::isfinite(sum)) {
        throw InputError("the spectrum has no luminance between 360 and 830 nm, so it has no colour");
    }
    // Z >= 0 puts x + y <= 1, but the two divisions can round it an ulp above 1 (a 10 nm
    // LED at 723 nm has Z/X ~ 1e-70), which check_chromaticity would refuse: cap x at 1 - y.
    const double y = xyz.y / sum;
    return normalised_rgb_from_xy(glm::dvec2(std::min(xyz.x / sum, 1.0 - y), y), true);
}

std::optional<glm::dvec2> iala_colour_xy(std::string_view name) {
    for (const auto& c : kIalaColours) {
        if (name == c.name) return c.xy;
    }
    return std::nullopt;
}

std::optional<Vec3> iala_colour_rgb(std::string_view name) {
    const auto xy = iala_colour_xy(name);
    if (!xy) return std::nullopt;
    // All table 4.1 colours are inside the gamut or on its edge; clipping only guards rounding.
    return normalised_rgb_from_xy(*xy, true);
}

std::optional<std::string> iala_colour_spectrum_name(std::string_view name) {
    for (const auto& c : kIalaColours) {
        if (name == c.name) return std::string(c.spectrum);
    }
    return std::nullopt;
}

std::vector<std::string> iala_colour_names() {
    std::vector<std::string> names;
    for (const auto& c : kIalaColours) names.emplace_back(c.name);
    return names;
}

std::optional<std::string> iala_colour_from_chart_letter(std::string_view letter) {
    for (const auto& l : kChartLetters) {
        if (letter == l.letter) return std::string(l.colour);
    }
    return std::nullopt;
}

}  // namespace atonlab::display
