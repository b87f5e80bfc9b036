// Per light: evaluate the light model at the eye, project it, decide its
// footprint and whether the scene hides it (tested once, at its centre, against
// the linear view depth: K2012 §4.3.2). One invocation per light.
//
// Culled here, exactly: lights behind the eye or inside their own sphere, dark
// ones (outside their sectors or dark in their rhythm: E = 0), hidden ones, and
// those whose footprint and glare cannot reach the image. With the display
// skips (frame_renderer.h DisplaySkips): lights whose brightest pixel stays
// below their invisible illuminance, and billboards cropped to where the
// kernel's envelope falls below it (docs/bench.md "Skips").
#include "light_model.glsl"

layout(local_size_x = 64) in;

struct LightDraw {
    vec4 centre;       // xy: projected centre (px, window coordinates); z: view depth (m); w: footprint area (px², 0 = not drawn)
    vec4 illuminance;  // rgb: illuminance at the eye (lux per channel); w: distance (m)
    vec4 factors;      // vertical, horizontal, rhythm, transmittance
    vec4 skip;         // x: cropped billboard half-extent (px, 0 = uncropped); y: invisible illuminance (lux);
                       // z: the light's glare path (0 direct, 1 billboard, 2 veil: scene.h GlarePath)
};
layout(std430, binding = 3) writeonly buffer Draws { LightDraw draws[]; };
// Per SPD group, envelope_stride entries (glare_stage.h envelope_buffer()):
// 0 … stride-2, the largest kernel texel (any channel) at Chebyshev distance
// >= e from the centre, non-increasing, ending in 0; stride-1, the group's
// area-layer step (px).
layout(std430, binding = 4) readonly buffer Envelope { float envelope[]; };

layout(binding = 0) uniform sampler2D scene_view_depth;  // R32F, m

uniform uint light_count;
uniform mat3 view_from_world;
uniform float focal_px;
uniform vec2 image_size;
uniform double time_s;  // s; double, see rhythm_level()
uniform float extinction_per_m;
uniform float glare_extent_px;  // billboard half-extent (px) beyond the light's disc; 0 without glare
uniform int cull_invisible;     // 1: lights below their invisible illuminance emit nothing
uniform int crop_billboards;    // 1: billboards cropped by the envelope
uniform uint envelope_stride;   // 0: no glare

const vec3 LUMINANCE = vec3(0.2126, 0.7152, 0.0722);

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= light_count) return;
    GpuLight L = lights[i];
    LightEval ev = evaluate_light(L, time_s, extinction_per_m);
    LightDraw d;
    d.illuminance = vec4(ev.illuminance_rgb, ev.distance);
    d.factors = vec4(ev.vertical, ev.horizontal, ev.rhythm, ev.transmittance);
    d.centre = vec4(0.0);
    float invisible = L.rhythm_period.y;  // lux (Y); 0: never culled or cropped
    uint path = L.rhythm.w;  // scene.h GlarePath of the light's own glare model, else the eye's
    bool billboard = path == 1u;
    // w: the S/P of the light's spectrum (scotopic cd/m² per cd/m²), for the frame's scotopic channel.
    d.skip = vec4(0.0, invisible, float(path), L.rhythm_period.z);

    vec3 v = view_from_world * L.position_radius.xyz;
    float radius = L.position_radius.w;
    bool lit = any(greaterThan(ev.illuminance_rgb, vec3(0.0)));
    // Drawn only with the whole sphere in front of the camera's plane (depth > radius):
    // a sphere reaching that plane has an unbounded pinhole image, and the disc model's
    // centre and area (1/cos³α) overflow (docs/numerical-behaviour.md).
    if (-v.z > radius && ev.distance > radius && lit) {
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
        float disc_px = area >= 1.0 ? sqrt(area / PI) : 0.5;
        float extent = disc_px + 1.0 + (billboard ? glare_extent_px : 0.0);
        // Display skips: a pixel receives at most E_Y · K_peak / Ω (glare) or
        // E_Y / (max(A, 1) Ω) (direct image), Ω ≥ the smallest pixel solid
        // angle, which `invisible` (= ΔY · Ω_min) already holds.
        bool invisible_light = false;
        if (invisible > 0.0) {
            float e_y = dot(ev.illuminance_rgb, LUMINANCE);
            if (envelope_stride > 0u && billboard) {
                uint base = L.rhythm.z * envelope_stride;
                invisible_light = cull_invisible != 0 && e_y * envelope[base] < invisible;
                if (crop_billboards != 0 && !invisible_light) {
                    // Smallest e with e_y · envelope[e] < invisible (entry stride-2 is 0).
                    uint lo = 0u, hi = envelope_stride - 2u;
                    if (e_y * envelope[base] < invisible) {
                        hi = 0u;
                    } else {
                        while (hi - lo > 1u) {
                            uint mid = (lo + hi) / 2u;
                            if (e_y * envelope[base + mid] < invisible) hi = mid; else lo = mid;
                        }
                    }
                    // A pixel samples texels up to 1 px nearer (bilinear), and an
                    // area layer of disc radius r (at most the light's radius plus
                    // one layer step, eq 4.13 interpolates) reaches r px further:
                    // its texels are averages over discs of the kernel's.
                    float step = envelope[base + envelope_stride - 1u];
                    float layer_reach = step > 0.0 && area >= 1.0 ? ceil(disc_px + step) : 0.0;
                    float cropped = float(hi) + 2.0 + layer_reach;
                    d.skip.x = cropped;
                    extent = min(extent, cropped);
                }
            } else {
                invisible_light = cull_invisible != 0 && e_y / max(area, 1.0) < invisible;
            }
        }
        // Cull what cannot touch the image: the footprint's extent beyond the edges.
        bool outside = any(lessThan(c + extent, vec2(0.0))) || any(greaterThan(c - extent, image_size));
        if (!hidden && !outside && !invisible_light) d.centre = vec4(c, depth, area);
    }
    draws[i] = d;
}
