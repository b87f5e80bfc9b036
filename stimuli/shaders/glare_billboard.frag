// A glare billboard's pixel (K2012 listing 5.7): the light's illuminance E
// (lux per channel) times the kernel's energy fraction for this pixel, divided
// by the pixel's solid angle, so Σ L·Ω over the billboard equals E (each
// kernel channel sums to 1). The kernel is looked up bilinearly at the light's
// sub-pixel offset (which keeps the sum) and linearly between area layers by
// projected radius (eq 4.13). Manual lookups in a buffer keep fp32 weights on
// every driver (hardware filtering may quantise them to 8 bits).
#include "footprint.glsl"

layout(std430, binding = 5) readonly buffer Layers { vec4 layers[]; };

uniform vec2 image_size;
uniform float focal_px;
uniform int layer_size;
uniform float layer_half_px;
uniform float pre_exposure;  // the HDR target stores luminance × pre_exposure (frame_renderer.h)

flat in vec2 g_centre;
flat in vec3 g_illuminance;
flat in float g_s_p;
flat in float g_layer;

layout(location = 0) out vec4 radiance;

vec3 fetch(int layer, ivec2 p) {
    if (any(lessThan(p, ivec2(0))) || any(greaterThanEqual(p, ivec2(layer_size)))) return vec3(0.0);
    return layers[(layer * layer_size + p.y) * layer_size + p.x].rgb;
}

vec3 bilinear(int layer, vec2 k) {
    vec2 f = floor(k);
    ivec2 i = ivec2(f);
    vec2 t = k - f;
    return mix(mix(fetch(layer, i), fetch(layer, i + ivec2(1, 0)), t.x),
               mix(fetch(layer, i + ivec2(0, 1)), fetch(layer, i + ivec2(1, 1)), t.x), t.y);
}

void main() {
    vec2 k = gl_FragCoord.xy - g_centre + layer_half_px;
    int z0 = int(floor(g_layer));
    float t = g_layer - float(z0);
    vec3 K = bilinear(z0, k);
    if (t > 0.0) K = mix(K, bilinear(z0 + 1, k), t);
    if (all(lessThanEqual(K, vec3(0.0)))) discard;
    vec2 p0 = floor(gl_FragCoord.xy);
    float omega = pixel_solid_angle(p0 + 0.5 - 0.5 * image_size, focal_px);
    // alpha: the scotopic channel, S/P × this pixel's photopic luminance. Its sum over the billboard is
    // S/P × E_Y (each kernel channel sums to 1); its shape is the kernel's luminance-weighted mix
    // (the V'-weighted PSF is not computed: docs/tone-mapping.md "The scotopic channel").
    vec3 rgb = g_illuminance * K / omega * pre_exposure;
    radiance = vec4(rgb, g_s_p * dot(vec3(0.2126, 0.7152, 0.0722), rgb));
}
