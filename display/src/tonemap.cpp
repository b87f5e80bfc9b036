// Tone mapping and adaptation (K2012 §4.4): the CPU reference of shaders/tonemap.glsl.
// Every expression here has a twin there; keep them in step (tests/gl/test_tonemap.cpp
// compares the two).
#include "atonlab/display/tonemap.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "atonlab/common/input_error.h"
#include "atonlab/display/colour.h"
#include "atonlab/display/mesopic.h"

namespace atonlab::display {
namespace {

constexpr std::array<std::string_view, 6> kOperatorNames = {"empirical", "perceptual", "reinhard",
                                                            "kakimoto",  "linear",     "clamp"};
constexpr std::array<std::string_view, 3> kHueNames = {"none", "xyY", "rgb"};
constexpr std::array<std::string_view, 2> kMesopicNames = {"k2012", "cie191"};

// Rows of the Rec.709 RGB -> XYZ matrix (glm is column-major: m[col][row]).
glm::dvec3 xyz_row(int row) {
    const Mat3& m = rec709_rgb_to_xyz();
    return {m[0][row], m[1][row], m[2][row]};
}

// Column sums: X+Y+Z of each primary at unit drive. All positive, so X+Y+Z of a
// non-negative RGB has no cancellation.
glm::dvec3 xyz_sum_row() {
    return xyz_row(0) + xyz_row(1) + xyz_row(2);
}

// The piecewise TVI polynomials of eq 4.23/4.24 ("otherwise" branches); the base is
// clamped at 0 so that a caller outside the branch's range cannot take pow of a negative.
double rod_middle(double l) {
    return std::pow(std::max(0.405 * l + 1.6, 0.0), 2.18) - 2.86;
}
double cone_middle(double l) {
    return std::pow(std::max(0.249 * l + 0.65, 0.0), 2.7) - 0.72;
}

double sanitize_component(double v) {
    return v > 0.0 ? std::min(v, kMaxInputCdM2) : 0.0;
}  // NaN -> 0

double clamp_adaptation(double l) {
    return l > kMinAdaptationCdM2 ? std::min(l, kMaxAdaptationCdM2) : kMinAdaptationCdM2;  // NaN -> min
}

// Reinhard et al. 2002 eq 4 (K2012 eq 4.20) as L/(1+L) · (1 + L/W²): no L² (fp32 on the GPU
// must not overflow) and no Inf/Inf. inv_white_sq = 1/W² (0 for W = ∞, their eq 3).
double reinhard_curve(double l, double inv_white_sq) {
    return l / (1.0 + l) * (1.0 + l * inv_white_sq);
}

double inverse_square(double w) {
    return std::isinf(w) ? 0.0 : 1.0 / (w * w);
}

void require_positive(double v, const char* key, const char* what) {
    if (!(v > 0.0) || !std::isfinite(v)) {
        throw InputError(SourceLocation{"", 0, 0, key},
                         fmt::format("{} must be a finite number greater than 0 (got {})", what, v));
    }
}

// Neumaier's compensated sum.
struct CompensatedSum {
    double sum = 0.0, c = 0.0;
    void add(double v) {
        const double t = sum + v;
        c += std::abs(sum) >= std::abs(v) ? (sum - t) + v : (v - t) + sum;
        sum = t;
    }
    double value() const { return sum + c; }
};

}  // namespace

std::string_view tone_operator_name(ToneOperator op) {
    return kOperatorNames.at(static_cast<std::size_t>(op));
}

std::optional<ToneOperator> tone_operator_from_name(std::string_view name) {
    for (std::size_t i = 0; i < kOperatorNames.size(); ++i) {
        if (kOperatorNames[i] == name) return static_cast<ToneOperator>(i);
    }
    return std::nullopt;
}

std::vector<std::string> tone_operator_names() {
    return {kOperatorNames.begin(), kOperatorNames.end()};
}

std::string_view hue_preservation_name(HuePreservation h) {
    return kHueNames.at(static_cast<std::size_t>(h));
}

std::optional<HuePreservation> hue_preservation_from_name(std::string_view name) {
    for (std::size_t i = 0; i < kHueNames.size(); ++i) {
        if (kHueNames[i] == name) return static_cast<HuePreservation>(i);
    }
    return std::nullopt;
}

std::string_view blueshift_luminance_name(BlueshiftLuminance b) {
    return b == BlueshiftLuminance::adaptation ? "adaptation" : "pixel";
}

std::optional<BlueshiftLuminance> blueshift_luminance_from_name(std::string_view name) {
    if (name == "adaptation") return BlueshiftLuminance::adaptation;
    if (name == "pixel") return BlueshiftLuminance::pixel;
    return std::nullopt;
}

std::string_view mesopic_model_name(MesopicModel m) {
    return kMesopicNames.at(static_cast<std::size_t>(m));
}

std::optional<MesopicModel> mesopic_model_from_name(std::string_view name) {
    for (std::size_t i = 0; i < kMesopicNames.size(); ++i) {
        if (kMesopicNames[i] == name) return static_cast<MesopicModel>(i);
    }
    return std::nullopt;
}

std::vector<std::string> hue_preservation_names() {
    return {kHueNames.begin(), kHueNames.end()};
}

void validate_tonemap_settings(const ToneMapSettings& s) {
    require_positive(s.white_relative, "tonemap.white_relative", "the empirical operator's white (L_white)");
    require_positive(s.reinhard_key, "tonemap.reinhard_key", "Reinhard's key");
    if (!(s.reinhard_white_relative > 0.0)) {
        throw InputError(
            SourceLocation{"", 0, 0, "tonemap.reinhard_white_relative"},
            fmt::format("Reinhard's white must be greater than 0 or infinite (got {})", s.reinhard_white_relative));
    }
    require_positive(s.kakimoto_g, "tonemap.kakimoto_g", "Kakimoto's exponent g");
    if (!(s.kakimoto_k > 1.0) || !std::isfinite(s.kakimoto_k)) {
        throw InputError(
            SourceLocation{"", 0, 0, "tonemap.kakimoto_k"},
            fmt::format("Kakimoto's contrast k must be a finite number greater than 1 (got {})", s.kakimoto_k));
    }
    if (s.white_cd_m2) require_positive(*s.white_cd_m2, "tonemap.white_cd_m2", "the linear operators' white (cd/m2)");
    require_positive(s.display_peak_cd_m2, "tonemap.display_peak_cd_m2", "the display's peak luminance (cd/m2)");
    if (s.display_adaptation_cd_m2) {
        require_positive(*s.display_adaptation_cd_m2, "tonemap.display_adaptation_cd_m2",
                         "the viewer's adaptation to the display (cd/m2)");
    }
    const glm::dvec2 xy = s.blueshift_xy;
    bool inside = std::isfinite(xy.x) && std::isfinite(xy.y) && xy.y > 0.0 && xy.x >= 0.0 && xy.x + xy.y <= 1.0;
    if (inside) {
        const glm::dvec3 rgb = xyz_to_linear_rgb(xyY_to_xyz(glm::dvec3(xy, 1.0)));
        inside = rgb.r >= 0.0 && rgb.g >= 0.0 && rgb.b >= 0.0;
    }
    if (!inside) {
        throw InputError(SourceLocation{"", 0, 0, "tonemap.blueshift_xy"},
                         fmt::format("the blueshift chromaticity xy = ({}, {}) is not inside the Rec.709 gamut "
                                     "(Durand & Dorsey use (0.3, 0.3))",
                                     xy.x, xy.y));
    }
}

double display_adaptation_cd_m2(const ToneMapSettings& s) {
    // K2012 §4.4: "the viewer is assumed to be adapted to half the display's maximum luminance".
    return s.display_adaptation_cd_m2 ? *s.display_adaptation_cd_m2 : 0.5 * s.display_peak_cd_m2;
}

double linear_white_cd_m2(double adaptation_cd_m2, const ToneMapSettings& s) {
    return s.white_cd_m2 ? *s.white_cd_m2 : adaptation_cd_m2 * s.display_peak_cd_m2 / display_adaptation_cd_m2(s);
}

double rod_sensitivity(double luminance_cd_m2) {
    // K2012 eq 4.27.
    return kRodSigmaCdM2 / (kRodSigmaCdM2 + std::max(luminance_cd_m2, 0.0));
}

double log10_tvi_rod(double l) {
    // K2012 eq 4.23, branches in the printed order.
    if (l <= -3.94) return -2.86;
    if (l >= -1.44) return l - 0.395;
    return rod_middle(l);
}

double log10_tvi_cone(double l) {
    // K2012 eq 4.24.
    if (l <= -2.6) return -0.72;
    if (l >= 1.9) return l - 1.255;
    return cone_middle(l);
}

double scotopic_luminance(glm::dvec3 xyz) {
    // K2012 eq 4.25 as in Larson, Rushmeier & Piatko 1997 (the thesis's (X+Y)/Z is a typo).
    const double x = std::max(xyz.x, 0.0), y = std::max(xyz.y, 0.0), z = std::max(xyz.z, 0.0);
    if (!(y > 0.0)) return 0.0;
    const double ratio = x > 0.0 ? std::min((y + z) / x, kMaxScotopicRatio) : kMaxScotopicRatio;
    return std::max(y * (1.33 * (1.0 + ratio) - 1.68), 0.0);
}

glm::dvec3 scotopic_weights_rgb() {
    // Scotopic cd/m² per unit of each channel (docs/tone-mapping.md "Scotopic weights"). The IALA
    // red and blue lights are drawn in the red and the blue primary alone (K2012 table 4.1), so
    // those channels carry their representative spectra's S/P (CIE S 010 V', V), times the
    // primary's luminance; green makes up D65 white's S/P. All three are positive.
    static const glm::dvec3 w = [] {
        const auto sp_of = [](std::string_view colour) {
            return scotopic_to_photopic_ratio(*named_spectrum(*iala_colour_spectrum_name(colour)));
        };
        const Mat3& m = rec709_rgb_to_xyz();  // m[c][1]: the luminance of primary c at unit drive
        const double r = m[0][1] * sp_of("red"), b = m[2][1] * sp_of("blue");
        return glm::dvec3(r, sp_of("white") - r - b, b);
    }();
    return w;
}

double scotopic_luminance_rgb(glm::dvec3 rgb) {
    return glm::dot(scotopic_weights_rgb(), glm::max(rgb, glm::dvec3(0.0)));
}

double mesopic_field_s_p_ratio() {
    static const double sp = scotopic_to_photopic_ratio(*named_spectrum("d65"));
    return sp;
}

double mesopic_field_adaptation(double adaptation_cd_m2) {
    // CIE 191:2010 MES2 for the field: m of (L_wa, S/P_field) by the standard's own solution. It depends
    // on L_wa alone, which a frame's pixels share: the last one is kept per thread, not solved per pixel.
    thread_local double last_lwa = std::numeric_limits<double>::quiet_NaN();
    thread_local double last_m = 0.0;
    const double lwa = clamp_adaptation(adaptation_cd_m2);
    if (!(lwa == last_lwa)) {
        last_m = mesopic_luminance_cd_m2(lwa, mesopic_field_s_p_ratio()).adaptation_m;
        last_lwa = lwa;
    }
    return last_m;
}

double mesopic_equivalent_cd_m2(double photopic_cd_m2, double scotopic_cd_m2, double adaptation_m) {
    // CIE 191:2010 MES2 L_mes of the pixel over L_mes of a field-spectrum pixel per cd/m², at one m: the
    // denominators (m + (1 - m) V'(λ0)) cancel.
    const double m = std::clamp(adaptation_m, 0.0, 1.0);
    const double v0 = kMesopicScotopicAt555;
    const double lp = std::max(photopic_cd_m2, 0.0), ls = std::max(scotopic_cd_m2, 0.0);
    return (m * lp + (1.0 - m) * v0 * ls) / (m + (1.0 - m) * v0 * mesopic_field_s_p_ratio());
}

double krawczyk_key(double adaptation_cd_m2) {
    // K2012 eq 4.19 with Krawczyk et al. 2005 eq 11's log10(L + 1). Written as
    // 0.002 + δ/(2 + δ), δ = log10(1 + L) — algebraically 1.002 - 2/(2 + δ) — so that the
    // GPU twin does not lose α (≈ 0.002 in the dark) to cancellation in fp32.
    const double delta = std::log1p(std::max(adaptation_cd_m2, 0.0)) / std::numbers::ln10;
    return 0.002 + delta / (2.0 + delta);
}

double adaptation_time_constant_s(double target_cd_m2) {
    // K2012 eq 4.17.
    const double sigma = rod_sensitivity(target_cd_m2);
    return sigma * kTauRodS + (1.0 - sigma) * kTauConeS;
}

double temporal_adaptation(double current_cd_m2, double target_cd_m2, double dt_s) {
    if (!std::isfinite(dt_s) || dt_s < 0.0) {
        throw InputError(
            fmt::format("the adaptation time step must be a finite number of seconds >= 0 (got {})", dt_s));
    }
    if (!std::isfinite(current_cd_m2) || !std::isfinite(target_cd_m2) || current_cd_m2 < 0.0 || target_cd_m2 < 0.0) {
        throw InputError(fmt::format("adaptation luminances must be finite and >= 0 cd/m2 (got {} and {})",
                                     current_cd_m2, target_cd_m2));
    }
    if (dt_s == 0.0) return current_cd_m2;
    // K2012 eq 4.16, rearranged as target - (target - current)·e^(-Δt/τ): exactly the target
    // once the exponential underflows.
    return target_cd_m2 - (target_cd_m2 - current_cd_m2) * std::exp(-dt_s / adaptation_time_constant_s(target_cd_m2));
}

double log_average_luminance(std::span<const float> rgba, std::size_t n, double epsilon_cd_m2) {
    if (!std::isfinite(epsilon_cd_m2) || !(epsilon_cd_m2 > 0.0)) {
        throw InputError(
            fmt::format("the log-average's epsilon must be a finite luminance > 0 cd/m2 (got {})", epsilon_cd_m2));
    }
    if (n == 0 || rgba.size() < n * 4) {
        throw InputError("an empty image has no log-average luminance");
    }
    CompensatedSum sum;
    for (std::size_t i = 0; i < n; ++i) {
        const float* p = &rgba[i * 4];
        const glm::dvec3 rgb(sanitize_component(p[0]), sanitize_component(p[1]), sanitize_component(p[2]));
        sum.add(std::log(luminance_of_linear_rgb(rgb) + epsilon_cd_m2));  // K2012 eq 4.15
    }
    return std::exp(sum.value() / static_cast<double>(n));
}

glm::dvec3 blueshift_rgb(glm::dvec2 xy) {
    return xyz_to_linear_rgb(xyY_to_xyz(glm::dvec3(xy, 1.0)));
}

double tone_curve(double luminance_cd_m2, double scotopic_cd_m2, double adaptation_cd_m2, const ToneMapSettings& s) {
    if (!(luminance_cd_m2 > 0.0)) return 0.0;  // black, negative or NaN
    const double lw = std::min(luminance_cd_m2, kMaxInputCdM2);
    const double lwa = clamp_adaptation(adaptation_cd_m2);
    switch (s.tone_operator) {
        case ToneOperator::empirical: {
            const double lr = krawczyk_key(lwa) * lw / lwa;               // K2012 eq 4.18
            return reinhard_curve(lr, inverse_square(s.white_relative));  // K2012 eq 4.20
        }
        case ToneOperator::reinhard: {
            const double l = s.reinhard_key * lw / lwa;                           // Reinhard et al. 2002 eq 2
            return reinhard_curve(l, inverse_square(s.reinhard_white_relative));  // their eq 4 (eq 3 for W = ∞)
        }
        case ToneOperator::kakimoto: {
            // Kakimoto et al. 2005 eq 7, sig(x) = D (x^g + 1)/(x^g + k), x = L_w/L_wa, rescaled
            // to (sig(x) - D/k)/(D - D/k) = x^g/(x^g + k) so that black is 0 and the limit is 1.
            const double xg = std::pow(lw / lwa, s.kakimoto_g);
            return xg / (xg + s.kakimoto_k);
        }
        case ToneOperator::perceptual: {
            // K2012 eq 4.21-4.26 (Durand & Dorsey 2000): m_C = ε_C(L_da)/ε_C(L_wa),
            // m_R = ε_C(L_da)/ε_R(L_wa); both systems see the photopic adaptation L_wa (the
            // pipeline keeps no scotopic adaptation luminance), rods weighted by σ(L_wa).
            const double lda = display_adaptation_cd_m2(s);
            const double log_lwa = std::log10(lwa);
            const double log_eps_display = log10_tvi_cone(std::log10(lda));
            const double m_c = std::pow(10.0, log_eps_display - log10_tvi_cone(log_lwa));  // eq 4.22
            const double m_r = std::pow(10.0, log_eps_display - log10_tvi_rod(log_lwa));
            const double v = scotopic_cd_m2 > 0.0 ? std::min(scotopic_cd_m2, kMaxScotopicCdM2) : 0.0;
            return (m_c * lw + rod_sensitivity(lwa) * m_r * v) / s.display_peak_cd_m2;  // eq 4.26
        }
        case ToneOperator::linear:
        case ToneOperator::clamp:
            return lw / linear_white_cd_m2(lwa, s);
    }
    return 0.0;
}

glm::dvec3 tonemap_pixel(glm::dvec3 rgb_cd_m2, double adaptation_cd_m2, const ToneMapSettings& s) {
    // Linear in RGB with non-negative weights: adding light never lowers V.
    const glm::dvec3 rgb(sanitize_component(rgb_cd_m2.r), sanitize_component(rgb_cd_m2.g),
                         sanitize_component(rgb_cd_m2.b));
    return tonemap_pixel(rgb, scotopic_luminance_rgb(rgb), adaptation_cd_m2, s);
}

glm::dvec3 tonemap_pixel(glm::dvec3 rgb_cd_m2, double scotopic_cd_m2, double adaptation_cd_m2,
                         const ToneMapSettings& s) {
    // NaN, negative -> 0; capped where tone_curve caps V (scotopic_luminance's bound at kMaxInputCdM2).
    const double scotopic = scotopic_cd_m2 > 0.0 ? std::min(scotopic_cd_m2, kMaxScotopicCdM2) : 0.0;
    const glm::dvec3 rgb(sanitize_component(rgb_cd_m2.r), sanitize_component(rgb_cd_m2.g),
                         sanitize_component(rgb_cd_m2.b));
    const double sum = glm::dot(xyz_sum_row(), rgb);  // X + Y + Z
    if (!(sum > 0.0)) return glm::dvec3(0.0);
    const double lwa = clamp_adaptation(adaptation_cd_m2);

    // Colour as RGB per unit X+Y+Z: bounded (each component <= 1/0.644) and free of
    // cancellation, so the xyY path needs no XYZ -> RGB matrix (whose negative entries cost
    // the GPU's fp32 its accuracy on saturated colours). Its y is the pixel's chromaticity y.
    const glm::dvec3 c = rgb / sum;
    const double y_w = glm::dot(xyz_row(1), c);
    const double lw = y_w * sum;
    double ld = 0.0;
    if (s.mesopic == MesopicModel::cie191) {
        // CIE 191:2010 MES2: the curve sees the field-spectrum luminance of equal L_mes, and (perceptual)
        // that pixel's scotopic luminance, so a field-spectrum pixel is drawn as under k2012.
        const double l_eq = mesopic_equivalent_cd_m2(lw, scotopic, mesopic_field_adaptation(lwa));
        ld = tone_curve(l_eq, mesopic_field_s_p_ratio() * l_eq, lwa, s);
    } else {
        // Only the perceptual operator's curve reads the rod signal.
        const double v = s.tone_operator == ToneOperator::perceptual ? scotopic : 0.0;
        ld = tone_curve(lw, v, lwa, s);
    }

    // Blueshift weights (K2012 eq 4.27-4.29) from the pixel's own luminance L_w (the
    // equations' σ(L_w)) or from the adaptation luminance; the cone weight is L/(σ₀ + L)
    // rather than 1 - σ, which fp32 would lose in the dark.
    const bool per_pixel = s.blueshift_luminance == BlueshiftLuminance::pixel;
    const glm::dvec3 b = blueshift_rgb(s.blueshift_xy);
    const double l_sigma = per_pixel ? std::min(lw, kMaxInputCdM2) : lwa;
    const double rod = s.blueshift ? rod_sensitivity(l_sigma) : 0.0;
    const double cone = s.blueshift ? l_sigma / (kRodSigmaCdM2 + l_sigma) : 1.0;

    glm::dvec3 out(0.0);
    switch (s.hue_preservation) {
        case HuePreservation::xyY: {
            // K2012 eq 4.28: x_d = x_w(1-σ) + x_b σ (likewise y), Y_d = min(1, L_d) — the thesis
            // prints max(1, L_d), a typo for the "rudimentary hue preservation" it describes.
            // A mix in xy with weights (1-σ, σ) is the additive mix of the two colours scaled
            // to equal X+Y+Z, so RGB_d = Y_d/y_d · ((1-σ) c_w + σ c_b), c = RGB/(X+Y+Z).
            const glm::dvec2 bxy = s.blueshift_xy;
            const glm::dvec3 c_b = xyz_to_linear_rgb(glm::dvec3(bxy, 1.0 - bxy.x - bxy.y));
            const double y_d = cone * y_w + rod * bxy.y;
            out = std::min(1.0, ld) / y_d * (cone * c + rod * c_b);
            break;
        }
        case HuePreservation::none:
        case HuePreservation::rgb: {
            // K2012 eq 4.29: RGB_w · L_d/L_w · (1-σ) + b · L_d · σ, with RGB_w/L_w = c / y_w.
            out = ld * (cone / y_w * c + rod * b);
            if (s.hue_preservation == HuePreservation::rgb) {
                // K2012 eq 4.30 divides by max(1, largest channel): no channel exceeds 1 and
                // the ratios stay, but luminance is lost, and more of it the more saturated
                // the pixel, so adding a red light to a grey pixel would darken it. Here
                // luminance wins instead: the colour moves towards the grey of its own
                // luminance until no channel exceeds 1 (docs/tone-mapping.md).
                if (s.out_of_gamut == OutOfGamut::keep_luminance) out = fit_to_gamut_keeping_luminance(out, xyz_row(1));
            }
            break;
        }
    }
    // clamp clips at the display's white: luminance first, then chroma (as for eq 4.30 above).
    // Clipping each channel instead would darken a pixel whose chroma turns towards a
    // saturated colour as light is added (a red light on a grey sky).
    // Any other display.out_of_gamut leaves the fit to the encoder (ToneMapSettings::out_of_gamut).
    if (s.tone_operator == ToneOperator::clamp && s.out_of_gamut == OutOfGamut::keep_luminance)
        out = fit_to_gamut_keeping_luminance(out, xyz_row(1));
    return glm::max(out, glm::dvec3(0.0));
}

ToneMapGpuParams tonemap_gpu_params(const ToneMapSettings& s) {
    validate_tonemap_settings(s);
    const auto f = [](double v) { return static_cast<float>(v); };
    const auto row = [&](int r) {
        const glm::dvec3 v = xyz_row(r);
        return std::array<float, 4>{f(v.x), f(v.y), f(v.z), 0.0f};
    };
    ToneMapGpuParams p;
    p.mode = {static_cast<std::uint32_t>(s.tone_operator), static_cast<std::uint32_t>(s.hue_preservation),
              s.blueshift ? static_cast<std::uint32_t>(s.blueshift_luminance) : 0u, s.white_cd_m2 ? 1u : 0u};
    p.curve = {f(inverse_square(s.white_relative)), f(s.reinhard_key), f(inverse_square(s.reinhard_white_relative)),
               f(s.kakimoto_g)};
    const double lda = display_adaptation_cd_m2(s);
    p.display = {f(s.kakimoto_k), f(s.white_cd_m2.value_or(0.0)), f(s.display_peak_cd_m2), f(lda)};
    const glm::dvec3 b = blueshift_rgb(s.blueshift_xy);
    p.tvi = {f(log10_tvi_cone(std::log10(lda))), f(kRodSigmaCdM2), f(static_cast<double>(s.out_of_gamut)),
             s.mesopic == MesopicModel::cie191 ? f(mesopic_field_s_p_ratio()) : 0.0f};
    p.blue_rgb = {f(b.r), f(b.g), f(b.b), f(s.blueshift_xy.y)};
    const glm::dvec2 bxy = s.blueshift_xy;
    const glm::dvec3 c_b = xyz_to_linear_rgb(glm::dvec3(bxy, 1.0 - bxy.x - bxy.y));
    p.blue_per_sum = {f(c_b.r), f(c_b.g), f(c_b.b), 0.0f};
    p.rgb_to_x = row(0);
    p.rgb_to_y = row(1);
    p.rgb_to_z = row(2);
    const glm::dvec3 w = scotopic_weights_rgb();
    p.scotopic = {f(w.r), f(w.g), f(w.b), 0.0f};
    return p;
}

}  // namespace atonlab::display
