// One extended reference (scene.h Disc): a uniform disc of visual angle over
// the background, area-weighted at its edge. disc.h is the CPU reference and
// says why the coverage below is the pixel's covered area. Blended with
// (SRC_ALPHA, ONE_MINUS_SRC_ALPHA): L = (1 − c) L_below + c L_disc, so the
// inside holds the disc's luminance exactly (c = 1). Not a light: no glare. The
// scotopic channel (alpha) blends the same way through the blend constant
// (frame_renderer.cpp): a = (1 − c) a_below + c V_disc.
layout(location = 0) out vec4 radiance;

uniform vec2 principal_px;  // image centre (px, window coordinates)
uniform float focal_px;
uniform vec3 centre_view;   // unit direction of the disc's centre, view space
uniform float radius_rad;   // half the angular diameter
uniform vec3 rgb;           // the disc's linear Rec.709 (Y = cd/m²) × pre_exposure

float ray_angle(vec2 window_px) {
    vec3 d = normalize(vec3((window_px - principal_px) / focal_px, -1.0));
    return atan(length(cross(d, centre_view)), dot(d, centre_view));
}

void main() {
    vec2 p = gl_FragCoord.xy;  // the pixel's centre
    float theta = ray_angle(p);
    float gx = ray_angle(p + vec2(0.5, 0.0)) - ray_angle(p - vec2(0.5, 0.0));
    float gy = ray_angle(p + vec2(0.0, 0.5)) - ray_angle(p - vec2(0.0, 0.5));
    float w = length(vec2(gx, gy));
    float c = w > 0.0 ? clamp(0.5 - (theta - radius_rad) / w, 0.0, 1.0) : (theta <= radius_rad ? 1.0 : 0.0);
    if (c <= 0.0) discard;
    radiance = vec4(rgb, c);
}
