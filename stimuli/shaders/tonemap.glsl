// Tone mapping (K2012 §4.4): the GLSL twin of display/src/tonemap.cpp. Functions only: no
// main, no bindings. Include it, declare a block holding a ToneMapParams (filled on the CPU
// by tonemap_gpu_params(), tonemap.h, whose ToneMapGpuParams has this exact layout) and call
//   vec3 tonemap_pixel(vec3 rgb_cd_m2, float adaptation_cd_m2, ToneMapParams p)
// or, with the pixel's own scotopic luminance (scotopic cd/m², the frame's scotopic channel),
//   vec3 tonemap_pixel_scotopic(vec3 rgb_cd_m2, float scotopic_cd_m2, float adaptation_cd_m2, ToneMapParams p)
// Input: linear Rec.709 RGB in cd/m²; output: display-relative linear Rec.709 RGB
// (1 = display peak), never negative or NaN.
//
// All fp32: every step is arranged so that fp32 keeps a relative 1e-5 or better against the
// double reference (tests/gl/test_tonemap.cpp): log1p by its series for small L, the cone
// weight L/(σ₀+L) instead of 1-σ, and colour carried as RGB per unit X+Y+Z (no XYZ -> RGB
// matrix with its cancellations). GLSL 4.5 has no fp64 exp/log, and nothing here needs one.
#ifndef ATONLAB_TONEMAP_GLSL
#define ATONLAB_TONEMAP_GLSL

// ToneOperator, HuePreservation and (0 = off) BlueshiftLuminance (tonemap.h).
const uint TONE_EMPIRICAL = 0u;
const uint TONE_PERCEPTUAL = 1u;
const uint TONE_REINHARD = 2u;
const uint TONE_KAKIMOTO = 3u;
const uint TONE_LINEAR = 4u;
const uint TONE_CLAMP = 5u;
const uint HUE_NONE = 0u;
const uint HUE_XYY = 1u;
const uint HUE_RGB = 2u;
const uint BLUE_OFF = 0u;
const uint BLUE_ADAPTATION = 1u;
const uint BLUE_PIXEL = 2u;

// kMinAdaptationCdM2, kMaxAdaptationCdM2, kMaxInputCdM2, kMaxScotopicRatio (tonemap.h).
const float TM_MIN_ADAPTATION = 1e-7;
const float TM_MAX_ADAPTATION = 1e10;
const float TM_MAX_INPUT = 1e15;
const float TM_MAX_SCOTOPIC_RATIO = 1000.0;
const float TM_LOG10_E = 0.43429448190325182;  // 1/ln 10
const float TM_LOG2_10 = 3.3219280948873623;

struct ToneMapParams {
    uvec4 mode;          // x: operator (TONE_*), y: hue preservation (HUE_*), z: blueshift (BLUE_*), w: white_cd_m2 given 0/1
    vec4 curve;          // x: 1/L_white² (empirical), y: Reinhard key, z: 1/L_white² (Reinhard), w: Kakimoto g
    vec4 display;        // x: Kakimoto k, y: white_cd_m2, z: L_dmax (cd/m²), w: L_da (cd/m²)
    vec4 tvi;            // x: log10 ε_C(L_da), y: σ₀ (cd/m², eq 4.27), z: display.out_of_gamut (0 = keep-luminance), w: field S/P if mesopic = cie191, else 0
    vec4 blue_rgb;       // xyz: blueshift RGB at Y = 1 (eq 4.29); w: blueshift y
    vec4 blue_per_sum;   // xyz: blueshift RGB per unit X+Y+Z (eq 4.28 path)
    vec4 rgb_to_x;       // rows of the Rec.709 RGB -> XYZ matrix
    vec4 rgb_to_y;
    vec4 rgb_to_z;
    vec4 scotopic;       // xyz: scotopic luminance per unit R, G, B (scotopic_weights_rgb(), eq 4.25 at the primaries)
};

// ln(1 + x) for x >= 0. Below 0.1 by its series (to x⁷: relative error < 2e-8), because
// 1 + x rounds away x's low bits in fp32; above, log(1 + x) is relatively accurate.
float tm_log1p(float x) {
    if (x < 0.1) {
        float t = 1.0 / 5.0 - x * (1.0 / 6.0 - x / 7.0);
        return x * (1.0 - x * (1.0 / 2.0 - x * (1.0 / 3.0 - x * (1.0 / 4.0 - x * t))));
    }
    return log(1.0 + x);
}

float tm_log10(float x) { return log2(x) * 0.30102999566398120; }
float tm_exp10(float x) { return exp2(x * TM_LOG2_10); }

// K2012 eq 4.27.
float rod_sensitivity(float luminance, float sigma0) { return sigma0 / (sigma0 + max(luminance, 0.0)); }

// K2012 eq 4.23 / 4.24 (log10 of the threshold in cd/m² at log10 adaptation).
float log10_tvi_rod(float l) {
    if (l <= -3.94) return -2.86;
    if (l >= -1.44) return l - 0.395;
    return pow(max(0.405 * l + 1.6, 0.0), 2.18) - 2.86;
}
float log10_tvi_cone(float l) {
    if (l <= -2.6) return -0.72;
    if (l >= 1.9) return l - 1.255;
    return pow(max(0.249 * l + 0.65, 0.0), 2.7) - 0.72;
}

// Twin of fit_to_gamut_keeping_luminance() (colour.cpp) at Rec.709's weights w: the colour
// moves towards the grey of its own luminance until no channel exceeds 1; white beyond it.
vec3 tm_fit_to_gamut(vec3 rgb, vec3 w) {
    rgb = max(rgb, vec3(0.0));
    float y = dot(w, rgb);
    if (!(y < 1.0)) return vec3(1.0);
    float m = max(rgb.r, max(rgb.g, rgb.b));
    if (m <= 1.0) return rgb;
    return vec3(y) + ((1.0 - y) / (m - y)) * (rgb - vec3(y));
}

// K2012 eq 4.19 with Krawczyk et al. 2005's log10(L + 1), as 0.002 + δ/(2 + δ).
float krawczyk_key(float adaptation) {
    float delta = tm_log1p(max(adaptation, 0.0)) * TM_LOG10_E;
    return 0.002 + delta / (2.0 + delta);
}

// CIE 191:2010 MES2 (mesopic.h): m = a + b log10(L_mes), V'(λ0) = 683/1699, range 0.005-5 cd/m².
const float MES_A = 0.7670;
const float MES_B = 0.3334;
const float MES_V0 = 0.40200117715;  // 683/1699

// Twin of mesopic_field_adaptation() (tonemap.cpp): m of the field (L_wa, S/P sp). For S/P > 1, L_mes
// falls as m rises, so h(m) = a + b log10 L_mes(m) - m falls and has one root in [0, 1]; bisection
// finds the fixed point mesopic_luminance_cd_m2's iteration converges to (to 2^-24 in m).
float tm_mesopic_m(float lwa, float sp) {
    if (lwa <= 0.005) return 0.0;
    if (lwa >= 5.0) return 1.0;
    float lo = 0.0, hi = 1.0;
    for (int i = 0; i < 24; ++i) {
        float m = 0.5 * (lo + hi);
        float lmes = lwa * (m + (1.0 - m) * MES_V0 * sp) / (m + (1.0 - m) * MES_V0);
        float h = clamp(MES_A + MES_B * tm_log10(lmes), 0.0, 1.0) - m;
        if (h > 0.0) lo = m; else hi = m;
    }
    return 0.5 * (lo + hi);
}

// Twin of mesopic_equivalent_cd_m2(): the field-spectrum luminance of equal MES2 L_mes at m.
float tm_mesopic_equivalent(float lp, float ls, float m, float sp) {
    return (m * lp + (1.0 - m) * MES_V0 * ls) / (m + (1.0 - m) * MES_V0 * sp);
}

// Reinhard et al. 2002 eq 4 / K2012 eq 4.20 as L/(1+L)·(1 + L/W²).
float reinhard_curve(float l, float inv_white_sq) { return l / (1.0 + l) * (1.0 + l * inv_white_sq); }

// The tone curve: display-relative L_d of photopic L_w and scotopic V_w (cd/m²) at adaptation
// lwa (already clamped). Twin of tone_curve() in tonemap.cpp.
float tone_curve(float lw, float vw, float lwa, ToneMapParams p) {
    if (!(lw > 0.0)) return 0.0;
    lw = min(lw, TM_MAX_INPUT);
    uint op = p.mode.x;
    if (op == TONE_EMPIRICAL) {
        float lr = krawczyk_key(lwa) * (lw / lwa);  // eq 4.18
        return reinhard_curve(lr, p.curve.x);       // eq 4.20
    }
    if (op == TONE_REINHARD) {
        return reinhard_curve(p.curve.y * (lw / lwa), p.curve.z);
    }
    if (op == TONE_KAKIMOTO) {
        // Kakimoto et al. 2005 eq 7 rescaled: x^g/(x^g + k), x = L_w/L_wa.
        float xg = exp2(p.curve.w * log2(lw / lwa));
        return xg / (xg + p.display.x);
    }
    if (op == TONE_PERCEPTUAL) {
        // eq 4.21-4.26: m_C = ε_C(L_da)/ε_C(L_wa), m_R = ε_C(L_da)/ε_R(L_wa).
        float log_lwa = tm_log10(lwa);
        float m_c = tm_exp10(p.tvi.x - log10_tvi_cone(log_lwa));
        float m_r = tm_exp10(p.tvi.x - log10_tvi_rod(log_lwa));
        float v = vw > 0.0 ? min(vw, 1.33 * (1.0 + TM_MAX_SCOTOPIC_RATIO) * TM_MAX_INPUT) : 0.0;
        return (m_c * lw + rod_sensitivity(lwa, p.tvi.y) * m_r * v) / p.display.z;
    }
    // TONE_LINEAR, TONE_CLAMP: white = white_cd_m2, or L_wa · L_dmax / L_da.
    float white = p.mode.w != 0u ? p.display.y : lwa * (p.display.z / p.display.w);
    return lw / white;
}

// scotopic_cd_m2: the pixel's scotopic luminance (the frame's scotopic channel), or < 0 for none:
// then V = the scotopic weights · RGB (scotopic_luminance_rgb()). NaN counts as 0 (tonemap.cpp).
vec3 tonemap_pixel_scotopic(vec3 rgb_cd_m2, float scotopic_cd_m2, float adaptation_cd_m2, ToneMapParams p) {
    // Clip to [0, max]; the comparisons send NaN to 0 (and NaN adaptation to the minimum).
    vec3 rgb = vec3(rgb_cd_m2.r > 0.0 ? min(rgb_cd_m2.r, TM_MAX_INPUT) : 0.0,
                    rgb_cd_m2.g > 0.0 ? min(rgb_cd_m2.g, TM_MAX_INPUT) : 0.0,
                    rgb_cd_m2.b > 0.0 ? min(rgb_cd_m2.b, TM_MAX_INPUT) : 0.0);
    vec3 sum_row = p.rgb_to_x.xyz + p.rgb_to_y.xyz + p.rgb_to_z.xyz;
    float sum = dot(sum_row, rgb);  // X + Y + Z
    if (!(sum > 0.0)) return vec3(0.0);
    float lwa = adaptation_cd_m2 > TM_MIN_ADAPTATION ? min(adaptation_cd_m2, TM_MAX_ADAPTATION) : TM_MIN_ADAPTATION;

    vec3 c = rgb / sum;  // RGB per unit X+Y+Z
    float y_w = dot(p.rgb_to_y.xyz, c);
    if (!(y_w > 0.0)) return vec3(0.0);
    float lw = y_w * sum;
    // scotopic_luminance_rgb(): linear, so adding light never lowers V
    const float v_max = 1.33 * (1.0 + TM_MAX_SCOTOPIC_RATIO) * TM_MAX_INPUT;  // kMaxScotopicCdM2
    float v_in = scotopic_cd_m2 < 0.0 ? dot(p.scotopic.xyz, rgb)
                                      : (scotopic_cd_m2 > 0.0 ? min(scotopic_cd_m2, v_max) : 0.0);
    float ld;
    if (p.tvi.w > 0.0) {
        // mesopic = cie191 (tonemap.cpp): the curve sees the field-spectrum luminance of equal L_mes.
        float sp = p.tvi.w;
        float l_eq = tm_mesopic_equivalent(lw, v_in, tm_mesopic_m(lwa, sp), sp);
        ld = tone_curve(l_eq, sp * l_eq, lwa, p);
    } else {
        float v = p.mode.x == TONE_PERCEPTUAL ? v_in : 0.0;
        ld = tone_curve(lw, v, lwa, p);
    }

    // Blueshift weights (eq 4.27) from the pixel's own luminance (BLUE_PIXEL) or the
    // adaptation luminance (BLUE_ADAPTATION); cone weight without 1 - σ.
    bool blue = p.mode.z != BLUE_OFF;
    bool per_pixel = p.mode.z == BLUE_PIXEL;
    float sigma0 = p.tvi.y;
    float l_sigma = per_pixel ? lw : lwa;
    float rod = blue ? sigma0 / (sigma0 + l_sigma) : 0.0;
    float cone = blue ? l_sigma / (sigma0 + l_sigma) : 1.0;

    vec3 outc;
    if (p.mode.y == HUE_XYY) {
        // eq 4.28 with min(1, L_d): mix in xy = mix of RGB-per-unit-sum, scaled to Y_d.
        float y_d = cone * y_w + rod * p.blue_rgb.w;
        outc = (min(1.0, ld) / y_d) * (cone * c + rod * p.blue_per_sum.xyz);
    } else {
        // eq 4.29; eq 4.30 for HUE_RGB.
        outc = ld * ((cone / y_w) * c + rod * p.blue_rgb.xyz);
        if (p.mode.y == HUE_RGB) {
            // eq 4.30 with luminance kept instead of the division (tonemap.cpp).
            if (p.tvi.z == 0.0) outc = tm_fit_to_gamut(outc, p.rgb_to_y.xyz);
        }
    }
    // Luminance first (tonemap.cpp); another display.out_of_gamut leaves the fit to the encoder.
    if (p.mode.x == TONE_CLAMP && p.tvi.z == 0.0) outc = tm_fit_to_gamut(outc, p.rgb_to_y.xyz);
    return max(outc, vec3(0.0));
}

vec3 tonemap_pixel(vec3 rgb_cd_m2, float adaptation_cd_m2, ToneMapParams p) {
    return tonemap_pixel_scotopic(rgb_cd_m2, -1.0, adaptation_cd_m2, p);
}

#endif  // ATONLAB_TONEMAP_GLSL
