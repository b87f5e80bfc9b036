// The ATON light model at the eye (K2012 §4.1, §4.3.1, §5.1): the GLSL twin of
// stimuli/src/light_model.cpp, profile.cpp and rhythm.cpp. Same arithmetic, in
// fp32, so the tests can compare the two.

struct GpuLight {
    vec4 position_radius;   // xyz: light centre minus eye (m, world axes); w: radius (m)
    vec4 orientation;       // world-from-light quaternion (x, y, z, w)
    vec4 intensity_phase;   // rgb: I · rgb_per_cd (cd per channel); w: rhythm phase (s)
    uvec4 tables;           // x, y: vertical profile offset, count; z, w: horizontal offset, count
    uvec4 rhythm;           // x, y: rhythm knot offset, count; z: glare group; w: glare path (scene.h GlarePath)
    vec4 rhythm_period;     // x: rhythm period (s), 0 = fixed; y: invisible lux; z: S/P of the light's spectrum
};

layout(std430, binding = 0) readonly buffer Lights { GpuLight lights[]; };
layout(std430, binding = 1) readonly buffer ProfileValues { float profile_values[]; };
layout(std430, binding = 2) readonly buffer RhythmKnots { vec2 rhythm_knots[]; };  // (t_s, level)

const float PI = 3.14159265358979;

// v rotated by unit quaternion q = (x, y, z, w).
vec3 qrot(vec4 q, vec3 v) { return v + 2.0 * cross(q.xyz, cross(q.xyz, v) + q.w * v); }
vec4 qconj(vec4 q) { return vec4(-q.xyz, q.w); }

// atan2 in double precision (core since GL 4.0), so the bearing does not depend
// on the driver's atan (Mesa's fp32 atan is off by ~1.5e-6 rad) and the table
// index keeps its fraction: in fp32 a bearing near 300° has an ulp of 3e-5°,
// which on a 1° sector edge is a 3e-5 error in intensity. Evaluated once per
// light per frame, so fp64's cost on consumer GPUs does not matter.
// Range reduction: a = min/max in [0, 1]; above tan(π/8) use
// atan(a) = π/4 + atan((a−1)/(a+1)), leaving |t| <= 0.4142 where the Taylor
// series to t^21 is accurate to 6e-10 rad.
double precise_atan2(double y, double x) {
    double ax = abs(x), ay = abs(y);
    double mx = max(ax, ay);
    if (mx == 0.0LF) return 0.0LF;
    double a = min(ax, ay) / mx;
    double base = 0.0LF;
    if (a > 0.41421356237309515LF) {
        base = 0.78539816339744831LF;
        a = (a - 1.0LF) / (a + 1.0LF);
    }
    double t2 = a * a;
    double p = 1.0LF / 21.0LF;
    p = p * t2 - 1.0LF / 19.0LF;
    p = p * t2 + 1.0LF / 17.0LF;
    p = p * t2 - 1.0LF / 15.0LF;
    p = p * t2 + 1.0LF / 13.0LF;
    p = p * t2 - 1.0LF / 11.0LF;
    p = p * t2 + 1.0LF / 9.0LF;
    p = p * t2 - 1.0LF / 7.0LF;
    p = p * t2 + 1.0LF / 5.0LF;
    p = p * t2 - 1.0LF / 3.0LF;
    p = p * t2 + 1.0LF;
    double r = base + a * p;
    if (ay > ax) r = 1.5707963267948966LF - r;
    if (x < 0.0LF) r = 3.1415926535897931LF - r;
    return y < 0.0LF ? -r : r;
}

// Light-space bearing of a direction, degrees in [0, 360): atan2(x, −z),
// clockwise from −z (profile.h; K2012 eq 4.4 rotated by 180°).
double bearing_deg(vec3 e) {
    double b = precise_atan2(double(e.x), -double(e.z)) * (180.0LF / 3.1415926535897931LF);
    return b < 0.0LF ? b + 360.0LF : b;
}

// K2012 eq 4.1: table in p = (cos θ + 1)/2, n values at p_j = j/(n−1), clamped.
float vertical_profile(uint offset, uint n, float cos_theta) {
    float p = clamp(0.5 * cos_theta + 0.5, 0.0, 1.0);
    float u = p * float(n - 1u);
    uint j0 = min(uint(floor(u)), n - 2u);
    float f = u - float(j0);
    return mix(profile_values[offset + j0], profile_values[offset + j0 + 1u], f);
}

// K2012 eq 4.3: n values at bearing i·360/n, periodic; index in double (see above).
float horizontal_profile(uint offset, uint n, double bearing) {
    double b = bearing - 360.0LF * floor(bearing / 360.0LF);
    double u = b / 360.0LF * double(n);
    double fl = floor(u);
    float f = float(u - fl);
    uint i0 = uint(fl) % n;
    uint i1 = (i0 + 1u) % n;
    return mix(profile_values[offset + i0], profile_values[offset + i1], f);
}

// Piecewise-linear periodic B(t): wrap, binary search, interpolate (rhythm.h).
// Time in double: a 20 ms ramp needs ~1e-7 s, and fp32 time has an ulp of
// 1e-6 s at 14 s and 2e-4 s after an hour of simulation.
float rhythm_level(uint offset, uint n, float period, double t) {
    if (n < 2u || period <= 0.0) return rhythm_knots[offset].y;
    double P = double(period);
    double tau = t - P * floor(t / P);
    uint lo = 0u, hi = n - 1u;  // invariant: knot[lo].t <= tau < knot[hi].t
    while (hi - lo > 1u) {
        uint mid = (lo + hi) / 2u;
        if (double(rhythm_knots[offset + mid].x) <= tau) lo = mid; else hi = mid;
    }
    vec2 a = rhythm_knots[offset + lo], b = rhythm_knots[offset + hi];
    double span = double(b.x) - double(a.x);
    return span > 0.0LF ? mix(a.y, b.y, float(clamp((tau - double(a.x)) / span, 0.0LF, 1.0LF))) : b.y;
}

struct LightEval {
    vec3 illuminance_rgb;  // lux per channel
    float distance;        // m
    float vertical, horizontal, rhythm, transmittance;
};

// E = I · rgb · P_v · P_h · B(t) · T(d) / d² (K2012 §4.1; Bouguer eq 4.14).
LightEval evaluate_light(GpuLight L, double time_s, float extinction_per_m) {
    LightEval r;
    vec3 to_eye = -L.position_radius.xyz;
    r.distance = length(to_eye);
    if (!(r.distance > 0.0)) {
        r.illuminance_rgb = vec3(0.0);
        r.vertical = r.horizontal = r.rhythm = r.transmittance = 0.0;
        return r;
    }
    // Listing 5.1: the profiles are looked up in light space. Rotate the
    // unnormalised vector (atan2 needs no normalisation) and divide once for cos θ.
    vec3 e = qrot(qconj(L.orientation), to_eye);
    r.vertical = vertical_profile(L.tables.x, L.tables.y, e.y / r.distance);
    r.horizontal = horizontal_profile(L.tables.z, L.tables.w, bearing_deg(e));
    r.rhythm = rhythm_level(L.rhythm.x, L.rhythm.y, L.rhythm_period.x, time_s + double(L.intensity_phase.w));
    r.transmittance = exp(-extinction_per_m * r.distance);
    float factor = r.vertical * r.horizontal * r.rhythm * r.transmittance / (r.distance * r.distance);
    r.illuminance_rgb = L.intensity_phase.rgb * factor;
    return r;
}
