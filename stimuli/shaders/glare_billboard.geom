// Expands each visible light of this SPD group into a screen-aligned quad
// (K2012 §5.3, listing 5.6). Visibility, occlusion (against the linear view
// depth with the source-radius offset, §5.3.2) and the light model were
// decided per light by light_eval.comp in an earlier compute pass, so nothing
// here reads a buffer the current pass writes. The quad covers the kernel plus
// the light's projected radius, culled against the image with that extent.
#include "light_model.glsl"

layout(points) in;
layout(triangle_strip, max_vertices = 4) out;

struct LightDraw {
    vec4 centre;       // xy: px (window coordinates); z: view depth (m); w: footprint area (px², 0 = not drawn)
    vec4 illuminance;  // rgb: lux at the eye
    vec4 factors;
    vec4 skip;         // x: cropped half-extent (px, 0 = uncropped; light_eval.comp)
};
layout(std430, binding = 3) readonly buffer Draws { LightDraw draws[]; };

flat in int v_light[];

uniform uint group;
uniform vec2 image_size;
uniform float kernel_half_px;   // (kernel size - 1) / 2
uniform float layer_half_px;    // (layer size - 1) / 2
uniform float layer_step_px;    // radius between area layers (0: one layer)
uniform int layer_count;

flat out vec2 g_centre;
flat out vec3 g_illuminance;
flat out float g_s_p;  // S/P of the light's spectrum (LightDraw skip.w)
flat out float g_layer;

void main() {
    int i = v_light[0];
    LightDraw d = draws[i];
    // Only the lights whose glare model draws a billboard (rhythm.w, scene.h GlarePath), of this group.
    if (d.centre.w <= 0.0 || lights[i].rhythm.w != 1u || lights[i].rhythm.z != group) return;
    float radius_px = sqrt(d.centre.w / PI);
    float layer = layer_step_px > 0.0 ? min(radius_px / layer_step_px, float(layer_count - 1)) : 0.0;
    float extent = min(kernel_half_px + ceil(radius_px) + 1.0, layer_half_px) + 1.0;
    if (d.skip.x > 0.0) extent = min(extent, d.skip.x);  // the display crop (frame_renderer.h DisplaySkips)
    vec2 c = d.centre.xy;
    if (any(lessThan(c + extent, vec2(0.0))) || any(greaterThan(c - extent, image_size))) return;
    for (int k = 0; k < 4; ++k) {
        vec2 corner = vec2(k & 1, (k >> 1) & 1) * 2.0 - 1.0;
        g_centre = c;
        g_illuminance = d.illuminance.rgb;
        g_s_p = d.skip.w;
        g_layer = layer;
        gl_Position = vec4((c + corner * extent) / image_size * 2.0 - 1.0, 0.0, 1.0);
        EmitVertex();
    }
    EndPrimitive();
}
