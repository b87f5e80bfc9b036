// Pixel coverage of a light's direct image: the GLSL twin of stimuli/src/footprint.cpp
// (see footprint.h for why the image is a disc of the light's projected area,
// or a unit box below 1 px², and why L = E · c / (max(A, 1) · Ω_pixel)).

float half_chord(float r, float x) { return sqrt(max(0.0, (r - x) * (r + x))); }

// ∫_p^q sqrt(R² − X²) dX with the asin difference as one atan.
float chord_integral(float r, float p, float q) {
    float sp = half_chord(r, p), sq = half_chord(r, q);
    float dasin = atan(q * sp - p * sq, sp * sq + p * q);
    return 0.5 * (q * sq - p * sp) + 0.5 * r * r * dasin;
}

float chord_excess(float r, float a, float b, float c) {
    if (c >= r) return 0.0;
    float w = half_chord(r, c);
    float p = max(a, -w), q = min(b, w);
    if (p >= q) return 0.0;
    return chord_integral(r, p, q) - c * (q - p);
}

float clamped_chord(float r, float a, float b, float lo, float hi) {
    if (hi <= 0.0) return hi * (b - a);
    float l = max(lo, 0.0);
    return l * (b - a) + chord_excess(r, a, b, l) - chord_excess(r, a, b, hi);
}

// Area (px²) of the disc (centre c, radius r) inside the pixel [p0, p0 + 1]².
float disc_pixel_coverage(vec2 c, float r, vec2 p0) {
    float a = p0.x - c.x, b = a + 1.0, lo = p0.y - c.y, hi = lo + 1.0;
    vec2 nearest = vec2(clamp(0.0, a, b), clamp(0.0, lo, hi));
    if (dot(nearest, nearest) >= r * r) return 0.0;
    vec2 far_corner = vec2(max(abs(a), abs(b)), max(abs(lo), abs(hi)));
    if (dot(far_corner, far_corner) <= r * r) return 1.0;
    return clamp(clamped_chord(r, a, b, lo, hi) + clamped_chord(r, a, b, -hi, -lo), 0.0, 1.0);
}

// Overlap (px²) of the unit square centred at c with the pixel [p0, p0 + 1]².
float box_pixel_coverage(vec2 c, vec2 p0) {
    vec2 o = max(vec2(0.0), min(c + 0.5, p0 + 1.0) - max(c - 0.5, p0));
    return o.x * o.y;
}

// Solid angle (sr) of a pinhole pixel whose centre is at q (px from the
// principal point): f / (|q|² + f²)^(3/2), within ~1e-8 of the exact corner formula.
float pixel_solid_angle(vec2 q, float f) {
    float r2 = dot(q, q) + f * f;
    return f / (r2 * sqrt(r2));
}
