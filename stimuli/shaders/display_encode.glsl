// Display encoding: the GPU twin of encode_pixel() in display/src/display_model.cpp
// (docs/display-calibration.md). Functions only; include it and pass a DisplayParams.
//
// - DisplayParams has the layout of GpuDisplayParams (display_model.h) under both
//   std140 and std430: fill it with gpu_display_params() and upload it as a UBO or SSBO.
// - Channels whose encoding has knots (lut: drive, cd/m², slope; doubles) read them from the SSBO at
//   DISPLAY_LUT_BINDING (default 7; #define it before the #include to move it),
//   filled with gpu_display_lut(). Shaders that never meet a LUT display may leave it unbound.
// - The encodings' inverse laws run in double precision. GLSL has no double
//   exp/log/pow, so display_log/display_exp below implement them (frexp/ldexp range
//   reduction and series good to ~1e-16); the dither is integer hashing only. The
//   CPU and the GPU therefore agree on every code value but for a rounding tie.

#ifndef DISPLAY_LUT_BINDING
#define DISPLAY_LUT_BINDING 7
#endif

const int DISPLAY_DITHER_NONE = 0;

struct DisplayChannel {
    double black_cd_m2;  // L(0)
    double white_cd_m2;  // L(1)
    double p0;  // p0 … p5: the encoding's parameters (DisplayEncoding::gpu_parameters)
    double p1;
    double p2;
    double p3;
    double p4;
    double p5;
    int kind;  // the encoding's place in display_encodings()
    int lut_first;
    int lut_count;
    int pad;
};

struct DisplayParams {
    DisplayChannel channel[3];
    int bits;
    int dither;
    uint seed;
    uint out_of_gamut;  // OutOfGamut (gamut.h): DISPLAY_KEEP_* below
};

layout(std430, binding = DISPLAY_LUT_BINDING) readonly buffer DisplayLutKnots { double display_lut[]; };

// ---------------------------------------------------------------------------
// Double-precision log, exp and pow.

const double DISPLAY_LN2_HI = 6.93147180369123816490e-01LF;  // fdlibm's split of ln 2
const double DISPLAY_LN2_LO = 1.90821492927058770002e-10LF;
const double DISPLAY_INV_LN2 = 1.44269504088896338700LF;

// ln x for finite x > 0.
double display_log(double x) {
    int e;
    double m = frexp(x, e);  // x = m 2^e, m in [0.5, 1)
    if (m < 0.70710678118654752440LF) {
        m *= 2.0LF;
        e -= 1;
    }
    // ln m = 2 atanh(s), s = (m - 1) / (m + 1), |s| <= 0.1716: the series to s^21 leaves < 1e-18.
    double s = (m - 1.0LF) / (m + 1.0LF);
    double s2 = s * s;
    double t = 1.0LF / 21.0LF;
    t = t * s2 + 1.0LF / 19.0LF;
    t = t * s2 + 1.0LF / 17.0LF;
    t = t * s2 + 1.0LF / 15.0LF;
    t = t * s2 + 1.0LF / 13.0LF;
    t = t * s2 + 1.0LF / 11.0LF;
    t = t * s2 + 1.0LF / 9.0LF;
    t = t * s2 + 1.0LF / 7.0LF;
    t = t * s2 + 1.0LF / 5.0LF;
    t = t * s2 + 1.0LF / 3.0LF;
    t = t * s2 + 1.0LF;
    double de = double(e);
    return de * DISPLAY_LN2_HI + (de * DISPLAY_LN2_LO + 2.0LF * s * t);
}

// e^x for x <= ~700 (underflows to 0 below -745).
double display_exp(double x) {
    if (x < -745.0LF) return 0.0LF;
    double n = floor(x * DISPLAY_INV_LN2 + 0.5LF);
    double r = (x - n * DISPLAY_LN2_HI) - n * DISPLAY_LN2_LO;  // |r| <= 0.347
    // Taylor series to r^14 / 14!: truncation < 1e-17 relative.
    double p = 1.0LF;
    for (int k = 14; k >= 1; --k) p = 1.0LF + p * r / double(k);
    return ldexp(p, int(n));
}

// x^y for x >= 0 and y > 0.
double display_pow(double x, double y) { return x > 0.0LF ? display_exp(y * display_log(x)) : 0.0LF; }

// ---------------------------------------------------------------------------
// Dither (display_model.cpp dither_threshold; integer arithmetic only).

uint display_hash32(uint x) {  // "lowbias32" (C. Wellons)
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

uint display_bayer64(uint x, uint y) {
    uint v = 0u;
    for (uint i = 0u; i < 6u; ++i) {
        uint xb = (x >> i) & 1u;
        uint yb = (y >> i) & 1u;
        v = (v << 2) | (((xb ^ yb) << 1) | yb);
    }
    return v;
}

// In [0, 1), 24-bit resolution: code = floor(V (2^bits - 1) + threshold).
double display_dither_threshold(ivec2 pixel, uint frame, int channel, uint seed) {
    uint key = display_hash32(seed + 0x9e3779b9u * (uint(channel) + 1u));
    uint x = uint(pixel.x) + (key & 63u);
    uint y = uint(pixel.y) + ((key >> 6) & 63u);
    uint phase =
        (display_bayer64(x & 63u, y & 63u) << 20) + 0x80000u + frame * 0x9e3779b9u + display_hash32(key ^ 0x5bd1e995u);
    return double(phase >> 8) * (1.0LF / 16777216.0LF);
}

// ---------------------------------------------------------------------------
// The encodings' laws: each encoding's GLSL (the twin of its CPU inverse, from its
// file display/src/encodings/NAME.cpp) and display_drive_by_kind(c, L), the function
// of c's kind, generated from the registry (display_encodings.h).
#include "display_encodings.glsl"

double display_drive_for(DisplayChannel c, double L) {
    if (!(L > c.black_cd_m2)) return 0.0LF;
    L = min(L, c.white_cd_m2);
    return clamp(display_drive_by_kind(c, L), 0.0LF, 1.0LF);
}

// ---------------------------------------------------------------------------
// display.out_of_gamut: the twin of fit_to_gamut() (display/src/gamut.cpp).

const uint DISPLAY_KEEP_LUMINANCE = 0u;
const uint DISPLAY_KEEP_SIGNAL_COLOUR = 1u;
const uint DISPLAY_KEEP_CHROMATICITY = 2u;
const uint DISPLAY_CLIP_CHANNELS = 3u;

// SIGNAL_AREA, SIGNAL_SHOWN, SIGNAL_*_CORNERS, SIGNAL_RGB_TO_XYZ, SIGNAL_XYZ_TO_RGB:
// generated from gamut.cpp's tables.
#include "signal_colour_areas.glsl"

double display_cross(dvec2 a, dvec2 b) { return a.x * b.y - a.y * b.x; }

bool display_on_segment(dvec2 p, dvec2 a, dvec2 b) {
    const double eps = 1e-12LF;
    return abs(display_cross(b - a, p - a)) <= eps && p.x >= min(a.x, b.x) - eps && p.x <= max(a.x, b.x) + eps &&
           p.y >= min(a.y, b.y) - eps && p.y <= max(a.y, b.y) + eps;
}

// inside_polygon(): the even-odd rule, the edge counting as inside.
bool display_inside_polygon(dvec2 xy, dvec2 poly[8], int n) {
    bool inside = false;
    for (int i = 0, j = n - 1; i < n; j = i++) {
        dvec2 a = poly[i], b = poly[j];
        if (display_on_segment(xy, a, b)) return true;
        if ((a.y > xy.y) != (b.y > xy.y) && xy.x < (b.x - a.x) * (xy.y - a.y) / (b.y - a.y) + a.x) inside = !inside;
    }
    return inside;
}

// nearest_point_of_polygon().
dvec2 display_nearest_point(dvec2 xy, dvec2 poly[8], int n) {
    if (n == 1) return poly[0];
    if (display_inside_polygon(xy, poly, n)) return xy;
    dvec2 best = poly[0];
    double best_d = 1e300LF;
    for (int i = 0; i < n; ++i) {
        dvec2 a = poly[i], ab = poly[(i + 1) % n] - a;
        double len2 = dot(ab, ab);
        double t = len2 > 0.0LF ? clamp(dot(xy - a, ab) / len2, 0.0LF, 1.0LF) : 0.0LF;
        dvec2 p = a + t * ab;
        double d = length(p - xy);
        if (d < best_d) {
            best_d = d;
            best = p;
        }
    }
    return best;
}

dvec2[8] display_polygon_corners(bool shown, int colour, out int n) {
    n = shown ? SIGNAL_SHOWN_CORNERS[colour] : SIGNAL_AREA_CORNERS[colour];
    dvec2 poly[8];
    for (int i = 0; i < 8; ++i) poly[i] = shown ? SIGNAL_SHOWN[8 * colour + i] : SIGNAL_AREA[8 * colour + i];
    return poly;
}

// nearest_signal_colour(): 0 white, 1 red, 2 green, 3 yellow. White inside white's area or
// near the display's white; else the coloured area nearest in hue angle, within a limit.
int display_nearest_signal_colour(dvec2 xy) {
    int n;
    dvec2 white_area[8] = display_polygon_corners(false, 0, n);
    if (display_inside_polygon(xy, white_area, n)) return 0;
    dvec2 v = xy - SIGNAL_WHITE;
    double s = length(v);
    if (!(s >= SIGNAL_MIN_SATURATION)) return 0;
    dvec2 u = v / s;
    int best = 0;
    double best_cos = SIGNAL_MAX_ANGLE_COS;
    for (int c = 1; c < 4; ++c) {
        dvec2 first = SIGNAL_SPAN_FIRST[c], last = SIGNAL_SPAN_LAST[c];
        bool inside = display_cross(first, u) >= 0.0LF && display_cross(u, last) >= 0.0LF;
        double k = inside ? 1.0LF : max(dot(u, first), dot(u, last));
        if (k > best_cos) {
            best_cos = k;
            best = c;
        }
    }
    return best;
}

dvec3 display_keep_luminance(dvec3 rgb, dvec3 w) {
    double y = dot(w, rgb);
    if (!(y < 1.0LF)) return dvec3(1.0LF);
    double m = max(rgb.r, max(rgb.g, rgb.b));
    if (m <= 1.0LF) return rgb;
    double t = (1.0LF - y) / (m - y);
    return dvec3(y) + t * (rgb - dvec3(y));
}

// Twin of fit_to_gamut(): NaN and negatives are black; a colour with no channel above 1
// is shown as it is; otherwise p.out_of_gamut decides.
dvec3 display_fit_to_gamut(vec3 relative_rgb, DisplayParams p) {
    dvec3 rgb;
    for (int c = 0; c < 3; ++c) rgb[c] = relative_rgb[c] > 0.0 ? double(relative_rgb[c]) : 0.0LF;
    dvec3 w = dvec3(p.channel[0].white_cd_m2, p.channel[1].white_cd_m2, p.channel[2].white_cd_m2);
    w /= w.r + w.g + w.b;
    double m = max(rgb.r, max(rgb.g, rgb.b));
    if (m <= 1.0LF) return rgb;
    if (p.out_of_gamut == DISPLAY_CLIP_CHANNELS) return min(rgb, dvec3(1.0LF));
    if (p.out_of_gamut == DISPLAY_KEEP_CHROMATICITY)
        return isinf(m) ? dvec3(rgb.r == m ? 1.0LF : 0.0LF, rgb.g == m ? 1.0LF : 0.0LF, rgb.b == m ? 1.0LF : 0.0LF)
                        : rgb / m;
    if (p.out_of_gamut == DISPLAY_KEEP_SIGNAL_COLOUR && !isinf(m)) {
        dvec3 xyz = SIGNAL_RGB_TO_XYZ * rgb;
        dvec2 xy = xyz.xy / (xyz.x + xyz.y + xyz.z);
        int colour = display_nearest_signal_colour(xy);
        if (colour != 0) {
            int n;
            dvec2 poly[8] = display_polygon_corners(true, colour, n);
            dvec2 t = display_nearest_point(xy, poly, n);
            double k = 1.0LF / t.y;  // xyY_to_xyz at Y = 1
            dvec3 full = max(SIGNAL_XYZ_TO_RGB * dvec3(k * t.x, 1.0LF, k * (1.0LF - t.x - t.y)), dvec3(0.0LF));
            full /= max(full.r, max(full.g, full.b));
            return full * min(1.0LF, dot(w, rgb) / dot(w, full));
        }
    }
    return display_keep_luminance(rgb, w);
}

// The encoder: relative_rgb is linear Rec.709 relative to the display's white
// (1 = full drive), brought into the gamut by p.out_of_gamut (display_fit_to_gamut).
uvec3 encode_pixel(vec3 relative_rgb, ivec2 pixel, uint frame, DisplayParams p) {
    double max_code = double((1 << p.bits) - 1);
    dvec3 shown = display_fit_to_gamut(relative_rgb, p);
    uvec3 code;
    for (int c = 0; c < 3; ++c) {
        double dd = shown[c];
        double v = display_drive_for(p.channel[c], dd * p.channel[c].white_cd_m2);
        double u = p.dither == DISPLAY_DITHER_NONE ? 0.5LF : display_dither_threshold(pixel, frame, c, p.seed);
        code[c] = uint(clamp(floor(v * max_code + u), 0.0LF, max_code));
    }
    return code;
}
