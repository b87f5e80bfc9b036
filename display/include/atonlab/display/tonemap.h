#pragma once
// Tone mapping and adaptation (K2012 §3.5, §4.4; docs/architecture.md "The pipeline, one frame", steps 4-5): the CPU
// double-precision reference of stimuli/shaders/tonemap.glsl (stimuli also holds the
// image-level functions of atonlab/stimuli/tonemap.h). No GL here.
//
// Input: scene-referred linear Rec.709 RGB on an absolute scale (cd/m²: a pixel's
// Y = 0.2126 R + 0.7152 G + 0.0722 B is its luminance) and the adaptation luminance
// in cd/m². Output: display-referred *linear* Rec.709 RGB relative to the display's
// white (1 = the peak of that channel). Values above 1 are allowed and clipped later by
// the display encoder; outputs are never negative, NaN or infinite.
//
// Every operator acts on luminance (the tone curve), then colour is restored in the way
// HuePreservation names, with the scotopic blueshift mixed in by the rod sensitivity σ of
// each pixel's own luminance (K2012 eq 4.27-4.29 write σ(L_w), after Krawczyk et al.
// 2005), so a bright coloured light keeps its colour at night while its dim glare and a
// dark background turn blue; the reading of K2012 §4.4's prose, σ of the *adaptation*
// luminance for every pixel, is kept as BlueshiftLuminance::adaptation.
// docs/tone-mapping.md derives each step and lists where the thesis has a typo.
#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/display/gamut.h"

namespace atonlab::display {

// ---------------------------------------------------------------------------
// Settings.

/// The tone curve (the values match TONE_* in tonemap.glsl).
enum class ToneOperator : std::uint8_t {
    empirical = 0,   ///< K2012 eq 4.18-4.20: Krawczyk's automatic key + Reinhard's white point
    perceptual = 1,  ///< K2012 eq 4.21-4.26: Durand & Dorsey's TVI-matched linear scale, rods + cones
    reinhard = 2,    ///< Reinhard et al. 2002 global operator (eq 2 and 4 of the paper), fixed key
    kakimoto = 3,    ///< Kakimoto et al. 2005 eq 7 sigmoid of L_w / L_wa, rescaled so black maps to 0
    linear = 4,      ///< L_w / white_cd_m2 (exposure only)
    clamp = 5,       ///< linear, then every channel clipped to [0, 1] (the naive baseline)
};
std::string_view tone_operator_name(ToneOperator op);  ///< "empirical", "perceptual", ...
std::optional<ToneOperator> tone_operator_from_name(std::string_view name);
std::vector<std::string> tone_operator_names();

/// How colour is restored after the tone curve (values match HUE_* in tonemap.glsl).
enum class HuePreservation : std::uint8_t {
    none = 0,  ///< RGB scaled by L_d / L_w (blueshift: K2012 eq 4.29); channels may exceed 1
    xyY = 1,   ///< K2012 eq 4.28: chromaticity kept (blueshift mixes it in xy), Y_d = min(1, L_d)
    rgb = 2,   ///< K2012 eq 4.29, then eq 4.30: divided by max(1, largest channel)
};
/// Whose luminance the blueshift's rod sensitivity σ is taken of (K2012 eq 4.27). The
/// values match BLUE_* in tonemap.glsl (0 is "off").
enum class BlueshiftLuminance : std::uint8_t {
    adaptation = 1,  ///< σ(L_wa): one weight for the whole frame (K2012 §4.4's process list)
    pixel = 2,       ///< σ(L_w) of each pixel (K2012 eq 4.27-4.29; Krawczyk et al. 2005)
};
std::string_view blueshift_luminance_name(BlueshiftLuminance b);  ///< "adaptation", "pixel"
std::optional<BlueshiftLuminance> blueshift_luminance_from_name(std::string_view name);

/// Which luminance the tone curve aims for (tonemap.mesopic; docs/tone-mapping.md "The mesopic variant").
enum class MesopicModel : std::uint8_t {
    k2012 = 0,   ///< each operator's own: photopic L_w, and perceptual's rods by eq 4.21-4.26 (K2012)
    cie191 = 1,  ///< the pixel's MES2 mesopic luminance (CIE 191:2010) with m from the adaptation field
};
std::string_view mesopic_model_name(MesopicModel m);  ///< "k2012", "cie191"
std::optional<MesopicModel> mesopic_model_from_name(std::string_view name);

std::string_view hue_preservation_name(HuePreservation h);  ///< "none", "xyY", "rgb"
std::optional<HuePreservation> hue_preservation_from_name(std::string_view name);
std::vector<std::string> hue_preservation_names();

/// Rod half-saturation luminance σ₀ of K2012 eq 4.27 (after Krawczyk et al. 2005), cd/m².
inline constexpr double kRodSigmaCdM2 = 0.04;
/// Time constants of light adaptation (K2012 eq 4.17), seconds.
inline constexpr double kTauRodS = 0.4;
inline constexpr double kTauConeS = 0.1;
/// ε of the log-average (K2012 eq 4.15), cd/m²: the lower end of scotopic vision, the
/// usual figure for the absolute threshold of the dark-adapted eye. Darker pixels all
/// look black, so counting them as 1e-6 loses nothing visible, while a
/// starlight scene (~1e-3 cd/m²) is biased by only 0.1%. The more common 1e-4 would lift
/// a uniform 1e-3 field's log-average by 10%.
inline constexpr double kLogAverageEpsilonCdM2 = 1e-6;
/// Range tonemap_pixel() accepts: the adaptation luminance is clamped into
/// [kMinAdaptationCdM2, kMaxAdaptationCdM2] (NaN -> the minimum), RGB components into
/// [0, kMaxInputCdM2] (NaN -> 0). The sun's disc is 1.6e9 cd/m²; the limits keep every
/// intermediate finite in fp32 on the GPU.
inline constexpr double kMinAdaptationCdM2 = 1e-7;
inline constexpr double kMaxAdaptationCdM2 = 1e10;
inline constexpr double kMaxInputCdM2 = 1e15;
/// (Y+Z)/X of a real colour is at most 274 (monochromatic light at 504 nm, where x̄ is
/// smallest); scotopic_luminance() caps the ratio here so that X -> 0 stays finite.
inline constexpr double kMaxScotopicRatio = 1000.0;
/// The largest scotopic luminance the tone curve takes (scotopic cd/m²): scotopic_luminance()'s bound
/// 1.33 (1 + kMaxScotopicRatio) kMaxInputCdM2; larger values (and +inf) are capped to it.
inline constexpr double kMaxScotopicCdM2 = 1.33 * (1.0 + kMaxScotopicRatio) * kMaxInputCdM2;

/// Parameters of the tone-mapping stage. Units in every name; defaults follow K2012.
/// validate_tonemap_settings() says which values are allowed.
struct ToneMapSettings {
    ToneOperator tone_operator = ToneOperator::empirical;

    /// empirical: L_white of K2012 eq 4.20, in units of the relative luminance L_r (the
    /// smallest L_r shown as white). The thesis uses 2.
    double white_relative = 2.0;

    /// reinhard: the key a of Reinhard et al. 2002 eq 2 (middle grey), and L_white of
    /// their eq 4 in units of the scaled luminance. Infinity (the default) is their eq 3,
    /// L/(1 + L), which never exceeds 1.
    double reinhard_key = 0.18;
    double reinhard_white_relative = std::numeric_limits<double>::infinity();

    /// kakimoto: exponent g and contrast k of Kakimoto et al. 2005 eq 7 (the paper's
    /// D = 640 cancels: the output is display-relative). k must exceed 1.
    double kakimoto_g = 0.465;
    double kakimoto_k = 20.0;

    /// linear, clamp: the scene luminance (cd/m²) shown as the display's peak white.
    /// nullopt: L_wa · display_peak / display_adaptation, i.e. the adaptation luminance is
    /// shown at the display's own adaptation level (twice L_wa with the defaults), the
    /// same assumption the perceptual operator makes (K2012 §4.4: viewer adapted to L_dmax/2).
    std::optional<double> white_cd_m2;

    /// L_dmax of K2012 eq 4.21 (cd/m²): the display's peak white luminance.
    double display_peak_cd_m2 = 100.0;
    /// L_da of K2012 eq 4.22 (cd/m²): the viewer's adaptation; nullopt: display_peak / 2 (K2012).
    std::optional<double> display_adaptation_cd_m2;

    /// Scotopic blueshift (K2012 eq 4.27-4.29): mix towards blueshift_xy by σ of
    /// blueshift_luminance.
    bool blueshift = true;
    /// σ of each pixel's own luminance (default) or of the adaptation luminance.
    BlueshiftLuminance blueshift_luminance = BlueshiftLuminance::pixel;
    /// The blueshift's CIE 1931 xy: (0.3, 0.3) after Durand & Dorsey 2000 / Hunt 1952.
    /// Must lie inside the Rec.709 gamut.
    glm::dvec2 blueshift_xy{0.3, 0.3};

    HuePreservation hue_preservation = HuePreservation::xyY;

    /// display.out_of_gamut (gamut.h). Its home is EncodeSettings::out_of_gamut: the GPU display
    /// pipeline and the scene reader copy it here; code calling tonemap_pixel itself sets both. Under keep_luminance
    /// the rgb hue mode and the clamp operator bring their output into the gamut here, keeping luminance (as always);
    /// under any other choice they leave it to the encoder, which applies the choice, so that the two never disagree.
    OutOfGamut out_of_gamut = OutOfGamut::keep_luminance;
    /// The luminance the tone curve aims for: K2012's (default) or CIE 191:2010's MES2 mesopic
    /// luminance of the pixel's (L_p, L_s) with m of the adaptation field (mesopic_equivalent_cd_m2).
    MesopicModel mesopic = MesopicModel::k2012;
};

/// Throws InputError naming the key ("tonemap.white_relative", ...) in its SourceLocation
/// for a value outside its range: white_relative, reinhard_key, white_cd_m2, display peak
/// and adaptation must be finite and > 0; reinhard_white_relative > 0 (infinity allowed);
/// kakimoto_g > 0, kakimoto_k > 1; blueshift_xy inside the Rec.709 gamut. Callers that
/// read a file re-throw with its file and line.
void validate_tonemap_settings(const ToneMapSettings& s);

/// L_da: display_adaptation_cd_m2 or, unset, display_peak_cd_m2 / 2 (cd/m²).
double display_adaptation_cd_m2(const ToneMapSettings& s);
/// The scene luminance (cd/m²) the linear and clamp operators show as display
/// white at adaptation L_wa: white_cd_m2, or unset L_wa · L_dmax / L_da.
double linear_white_cd_m2(double adaptation_cd_m2, const ToneMapSettings& s);

// ---------------------------------------------------------------------------
// The pieces, each with its equation.

/// K2012 eq 4.27 (Krawczyk et al. 2005): rod sensitivity σ(L) = σ₀ / (σ₀ + L), σ₀ = 0.04
/// cd/m²; 1 in the dark, 0.5 at 0.04 cd/m², -> 0 in daylight. L in cd/m² (>= 0).
double rod_sensitivity(double luminance_cd_m2);

/// K2012 eq 4.23: log10 of the rod threshold ε_R (cd/m²) at adaptation log10 L (cd/m²),
/// piecewise (Ferwerda et al. 1996). Not continuous: going up in L it jumps by +6.9e-6 log
/// units at -3.94 and by -0.01199 at -1.44 (tests/unit/test_tonemap.cpp measures them).
double log10_tvi_rod(double log10_adaptation_cd_m2);

/// K2012 eq 4.24: log10 of the cone threshold ε_C (cd/m²), piecewise; jumps by +1.0e-7 log
/// units at -2.6 and by -0.00314 at 1.9.
double log10_tvi_cone(double log10_adaptation_cd_m2);

/// K2012 eq 4.25, as Larson, Rushmeier & Piatko 1997 give it: scotopic luminance
/// V = Y (1.33 (1 + (Y + Z)/X) - 1.68) of CIE XYZ (Y in cd/m²). The thesis prints
/// (X + Y)/Z: a typo. Negative components are clipped to 0 first, (Y + Z)/X is capped at
/// kMaxScotopicRatio (X = 0 is not a real colour), V >= 0, black gives 0. For D65 white,
/// V = 2.573 Y.
double scotopic_luminance(glm::dvec3 xyz);

/// The scotopic luminance the perceptual operator uses, in scotopic cd/m², linear in linear
/// Rec.709 RGB (cd/m²): V = w · RGB with non-negative weights, negative components counted as 0.
/// Scotopic luminance is an integral of the spectrum against CIE 1951 V'(λ), so it adds; eq 4.25
/// of a pixel's XYZ does not (adding red light to a D65 pixel lowers its (Y + Z)/X and can lower
/// V), which made a red light darken a night sky. w (scotopic_weights_rgb) gives the IALA red and
/// blue lights (drawn in the red and blue primary alone) their representative spectra's S/P
/// ratios and D65 white its S/P (2.4645); docs/tone-mapping.md "Scotopic weights".
double scotopic_luminance_rgb(glm::dvec3 rgb_cd_m2);
glm::dvec3 scotopic_weights_rgb();  ///< the weights w above, scotopic cd/m² per cd/m² of each channel

/// S/P ratio the cie191 variant gives the adaptation field: D65's (2.4645, scotopic_to_photopic_ratio of
/// the CIE D65 table). The pipeline adapts to a photopic log-average only; its sky defaults to D65.
double mesopic_field_s_p_ratio();

/// CIE 191:2010 (MES2) adaptation coefficient m of the adaptation field L_wa (cd/m², clamped as in
/// tonemap_pixel) of S/P mesopic_field_s_p_ratio(): mesopic_luminance_cd_m2(L_wa, S/P).adaptation_m,
/// 0 at or below 0.005 cd/m², 1 at or above 5 cd/m².
double mesopic_field_adaptation(double adaptation_cd_m2);

/// The photopic luminance (cd/m²) of a pixel of the field's spectrum (S/P_f = mesopic_field_s_p_ratio())
/// whose MES2 mesopic luminance at the field's m equals that of a pixel of photopic L_p and scotopic L_s:
///   L_eq = (m L_p + (1 − m) V'(λ0) L_s) / (m + (1 − m) V'(λ0) S/P_f),  V'(λ0) = 683/1699,
/// CIE 191:2010's L_mes = (m L_p + (1 − m) L_s V'(λ0)) / (m + (1 − m) V'(λ0)) divided by the same of a
/// field-spectrum pixel per cd/m². A pixel of the field's spectrum gets L_eq = L_p; the cie191 variant
/// feeds L_eq to the tone curve, so ratios of displayed luminance follow ratios of L_mes. Linear with
/// non-negative weights in (L_p, L_s), so adding light never lowers it. m in [0, 1].
double mesopic_equivalent_cd_m2(double photopic_cd_m2, double scotopic_cd_m2, double adaptation_m);

/// K2012 eq 4.19 with Krawczyk et al. 2005 eq 11's log10(L + 1): the scene key
/// α(L_wa) = 1.002 - 2 / (2 + log10(L_wa + 1)). The thesis drops the "+ 1", which makes
/// α singular at L_wa = 0.01 cd/m² and negative below it; with it, α runs from 0.002 in
/// the dark through 0.133 at 1 cd/m² to 0.835 at 1e10 cd/m². The thesis's own change (1.03 -> 1.002) is kept.
double krawczyk_key(double adaptation_cd_m2);

/// K2012 eq 4.17: τ(L) = σ(L) τ_rod + (1 - σ(L)) τ_cone (s), of the *target* luminance L
/// (cd/m²) as the thesis writes it (τ(L̄_w)); dark adaptation is not modelled separately.
double adaptation_time_constant_s(double target_cd_m2);

/// K2012 eq 4.16: one step of temporal adaptation, from current towards target (cd/m²)
/// over dt_s seconds: target - (target - current) exp(-dt / τ(target)). dt = 0 returns
/// current exactly; a very long dt returns target exactly. Throws InputError for a
/// negative or non-finite dt_s, or a negative or non-finite luminance.
double temporal_adaptation(double current_cd_m2, double target_cd_m2, double dt_s);

/// K2012 eq 4.15: the log-average (geometric mean) luminance exp(mean(ln(L + ε))) of
/// `pixel_count` interleaved linear Rec.709 RGBA pixels (cd/m²), accumulated in double
/// with compensated (Neumaier) summation. Components are clipped to >= 0 (NaN -> 0)
/// before Y is taken. Throws InputError for no pixels, fewer than 4 · pixel_count
/// floats, or an ε that is not finite and > 0. A uniform field L gives L + ε.
/// (stimuli's log_average_luminance(ImageRGBA32F) calls this for an image.)
double log_average_luminance(std::span<const float> rgba, std::size_t pixel_count,
                             double epsilon_cd_m2 = kLogAverageEpsilonCdM2);

/// The blueshift colour as linear Rec.709 RGB with Y = 1 (the constant vector of K2012
/// eq 4.29), derived from its xy through the colour module. For (0.3, 0.3) it is
/// (1.03877, 0.96213, 1.26095); the thesis prints (1.016784, 0.983176, 1.107126), whose
/// chromaticity is (0.3073, 0.3163), not (0.3, 0.3).
glm::dvec3 blueshift_rgb(glm::dvec2 xy);

/// The tone curve alone: display-relative luminance L_d (1 = display peak) of a pixel of
/// photopic luminance L_w and scotopic luminance V_w (cd/m²; V_w is used by the
/// perceptual operator only) at adaptation L_wa (cd/m², clamped as in tonemap_pixel),
/// before colour restoration and before the clamp operator's clip; L_w and V_w are capped
/// like tonemap_pixel's inputs (kMaxInputCdM2). Non-decreasing in
/// L_w (and V_w), 0 at 0.
double tone_curve(double luminance_cd_m2, double scotopic_cd_m2, double adaptation_cd_m2, const ToneMapSettings& s);

/// One pixel: scene-referred linear Rec.709 RGB (cd/m²) at adaptation L_wa (cd/m²) ->
/// display-referred linear Rec.709 RGB (1 = display peak white; may exceed 1 except for
/// clamp and in eq 4.28/4.30's hue-preserving modes). Settings must be valid
/// (validate_tonemap_settings).
glm::dvec3 tonemap_pixel(glm::dvec3 rgb_cd_m2, double adaptation_cd_m2, const ToneMapSettings& s);

/// The same with the pixel's own scotopic luminance (scotopic cd/m², the V'-weighted channel the renderer
/// carries beside RGB from each light's spectrum; docs/tone-mapping.md "The scotopic channel"): the rod
/// signal of the perceptual operator and cie191's L_s. The overload above uses scotopic_luminance_rgb(rgb).
/// Negative or NaN scotopic luminance counts as 0.
glm::dvec3 tonemap_pixel(glm::dvec3 rgb_cd_m2, double scotopic_cd_m2, double adaptation_cd_m2,
                         const ToneMapSettings& s);

// ---------------------------------------------------------------------------
// The GPU twin's parameters: `struct ToneMapParams` of tonemap.glsl, byte for byte (all
// members 16-byte vectors, so the std140 and std430 layouts are this struct's layout).
// Upload it into a uniform or storage block and pass the block's member to
// tonemap_pixel(rgb, adaptation, params) in GLSL.
struct ToneMapGpuParams {
    std::array<std::uint32_t, 4>
        mode{};  ///< operator, hue preservation, blueshift (0 off, BlueshiftLuminance), white_cd_m2 given (0/1)
    std::array<float, 4> curve{};    ///< 1/L_white² (empirical), Reinhard key, 1/L_white² (Reinhard), Kakimoto g
    std::array<float, 4> display{};  ///< Kakimoto k, white_cd_m2, L_dmax, L_da (cd/m²)
    std::array<float, 4>
        tvi{};  ///< log10 ε_C(L_da), σ₀ (cd/m²), OutOfGamut as a float, field S/P if mesopic = cie191 else 0
    std::array<float, 4> blue_rgb{};      ///< blueshift RGB at Y = 1 (eq 4.29); w: its y
    std::array<float, 4> blue_per_sum{};  ///< blueshift RGB per unit X+Y+Z (the xyY path); w: 0
    std::array<float, 4> rgb_to_x{};      ///< rows of the Rec.709 RGB -> XYZ matrix (w: 0)
    std::array<float, 4> rgb_to_y{};
    std::array<float, 4> rgb_to_z{};
    std::array<float, 4> scotopic{};  ///< scotopic_weights_rgb() (w: 0)
};
static_assert(sizeof(ToneMapGpuParams) == 10 * 16, "must match ToneMapParams in tonemap.glsl");

/// Validates the settings and fills the GPU parameters (constants precomputed in double).
ToneMapGpuParams tonemap_gpu_params(const ToneMapSettings& s);

}  // namespace atonlab::display
