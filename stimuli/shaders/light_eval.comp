// Per light: evaluate the light model at the eye, project it, decide its
// footprint and whether the scene hides it (tested once, at its centre, against
// the linear view depth: K2012 §4.3.2). One invocation per light.
#include "light_model.glsl"

layout(local_size_x = 64) in;

struct LightDraw {
    vec4 centre;       // xy: projected centre (px, window coordinates); z: view depth (m); w: footprint area (px², 0 = not drawn)
    vec4 illuminance;  // rgb: illuminance at the eye (lux per channel); w: distance (m)
    vec4 factors;      // vertical, horizontal, rhythm, transmittance
};
layout(std430, binding = 3) writeonly buffer Draws { LightDraw draws[]; };

layout(binding = 0) uniform sampler2D scene_view_depth;  // R32F, m

uniform uint light_count;
uniform mat3 view_from_world;
uniform float focal_px;
uniform vec2 image_size;
uniform double time_s;  // s; double, see rhythm_level()
uniform float extinction_per_m;
uniform float glare_extent_px;  // billboard half-extent (px) beyond the light's disc; 0 without glare

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= light_count) return;
    GpuLight L = lights[i];
    LightEval ev = evaluate_light(L, time_s, extinction_per_m);
    LightDraw d;
    d.illuminance = vec4(ev.illuminance_rgb, ev.distance);
    d.factors = vec4(ev.vertical, ev.horizontal, ev.rhythm, ev.transmittance);
    d.centre = vec4(0.0);

    vec3 v = view_from_world * L.position_radius.xyz;
    float radius = L.position_radius.w;
    bool lit = any(greaterThan(ev.illuminance_rgb, vec3(0.0)));
    if (v.z < 0.0 && ev.distance > radius && lit) {
        float depth = -v.z;
        vec2 c = 0.5 * image_size + focal_px * v.xy / depth;
        // footprint.h: area = Ω_sphere f² / cos³α, Ω_sphere = 2π sin²β / (1 + cos β).
        float s = radius / ev.distance;
        float omega = 2.0 * PI * s * s / (1.0 + sqrt((1.0 - s) * (1.0 + s)));
        float cos_a = depth / ev.distance;
        float area = omega * focal_px * focal_px / (cos_a * cos_a * cos_a);
        // Occlusion by the scene, tested at the centre pixel against the linear
        // view depth offset by the source radius (K2012 §5.3.2). The depth was
        // written by an earlier pass; this compute pass only reads it. Lights
        // whose centre is off the image cannot be tested and count as visible
        // (their glare may still reach in; K2012 §4.3.2 multi-channel note).
        bool hidden = false;
        ivec2 pix = ivec2(floor(c));
        if (all(greaterThanEqual(pix, ivec2(0))) && all(lessThan(pix, ivec2(image_size)))) {
            float scene_depth = texelFetch(scene_view_depth, pix, 0).r;
            hidden = scene_depth < depth - radius;
        }
        // Cull what cannot touch the image: the footprint's extent beyond the edges.
        float extent = (area >= 1.0 ? sqrt(area / PI) : 0.5) + 1.0 + glare_extent_px;
        bool outside = any(lessThan(c + extent, vec2(0.0))) || any(greaterThan(c - extent, image_size));
        if (!hidden && !outside) d.centre = vec4(c, depth, area);
    }
    draws[i] = d;
}
