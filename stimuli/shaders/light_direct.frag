// Radiance of one pixel of a light's direct image: L = E · c / (max(A, 1) · Ω_pixel)
// (footprint.h), so that Σ L·Ω over the image equals the illuminance E at the
// eye; a generalisation of K2012 eq 4.5. Additively blended into the HDR target.
#include "footprint.glsl"

flat in vec2 v_centre;
flat in float v_area;
flat in float v_radius;
flat in vec3 v_illuminance;
flat in float v_scotopic;

uniform vec2 image_size;
uniform float focal_px;
uniform float pre_exposure;  // the HDR target stores luminance × pre_exposure (frame_renderer.h)

layout(location = 0) out vec4 radiance;

void main() {
    vec2 p0 = floor(gl_FragCoord.xy);
    float c = v_area >= 1.0 ? disc_pixel_coverage(v_centre, v_radius, p0)
                            : box_pixel_coverage(v_centre, p0);
    if (c <= 0.0) discard;
    float omega = pixel_solid_angle(p0 + 0.5 - 0.5 * image_size, focal_px);
    // The footprint holds max(A, 1) px² in all: A for a disc, 1 for the box.
    // alpha: the scotopic channel (scotopic cd/m², the light's own S/P; docs/tone-mapping.md).
    radiance = vec4(v_illuminance, v_scotopic) * (c / (max(v_area, 1.0) * omega) * pre_exposure);
}
