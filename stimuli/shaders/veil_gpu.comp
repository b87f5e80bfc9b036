// The `cie` veil on the GPU (veiling_glare.h, GpuVeilingGlare; issue 27 item 1):
// one pass of the frame's convolution with the CIE glare spread function's
// pixel kernel K, split K = K_near + K_far at the square |dx|, |dy| <= R:
//   K_far by an fp32 FFT (zero-padded to Mx × My >= (2W − 1) × (2H − 1), linear,
//     nothing wraps): its largest values are those just outside the window,
//     so the FFT's rounding (≈ 1e-7 of ||K_far|| ||e||) stays far below the
//     veil at 15° — the whole kernel's central pixel would swamp it;
//   K_near by a direct sum over the (2R + 1)² window, from shared memory.
// Channels: R + iG in one complex image, B in a second: K is real and even, so
// its spectrum is real and each part of a complex image is convolved alone.
// The inverse transform is a forward one of the conjugate (the multiply pass
// writes conj(X·K̂); the unpack pass conjugates back).
//
// One of (prepended by GpuVeilingGlare):
//   VEIL_PACK      L (cd/m², texture) × Ω (sr) -> e (lux) into both complex images
//                  (rows < H, zeros beyond W), a copy of e for the near sum, and
//                  per workgroup Σe and Σe·S (S: the share of a light at that
//                  pixel that stays in the frame) for the outside fraction
//   VEIL_MULTIPLY  X <- conj(X · K̂) over Mx × My (K̂ real, 1/(Mx·My) included)
//   VEIL_UNPACK    e_out = max(0, far + near); L = e_out / Ω into the image
//                  (VEIL_ADD: added × scale to it, the HDR frame; else replacing
//                  it), and its scotopic luminance (the RGB weights) to or into
//                  alpha, the frame's scotopic channel; VEIL_IMAGE_FORMAT its format qualifier
// and VEIL_NEAR_RADIUS R (an int literal).

#if defined(VEIL_PACK) || defined(VEIL_UNPACK)
layout(local_size_x = 16, local_size_y = 16) in;
#else
layout(local_size_x = 256) in;
#endif

layout(std430, binding = 0) buffer RedGreen { vec2 rg[]; };  // Mx × My, row-major
layout(std430, binding = 1) buffer Blue { vec2 b[]; };       // Mx × My
layout(std430, binding = 2) buffer Lux { vec4 e_copy[]; };   // W × H: e (lux) per channel
layout(std430, binding = 3) readonly buffer Omega { float omega[]; };  // W × H (sr)

uniform ivec2 frame_size;  // W, H
uniform uint pitch;        // Mx

#ifdef VEIL_PACK
layout(binding = 0) uniform sampler2D light;                             // cd/m²
layout(std430, binding = 4) readonly buffer Kept { float kept[]; };      // W × H: S
layout(std430, binding = 5) writeonly buffer Partials { vec4 partials[]; };  // 2 per workgroup

shared vec4 sum_e[256];
shared vec4 sum_es[256];

void main() {
    const ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    const uint t = gl_LocalInvocationIndex;
    vec3 e = vec3(0.0);
    float s = 0.0;
    if (q.x < frame_size.x && q.y < frame_size.y) {
        const uint p = uint(q.y * frame_size.x + q.x);
        e = texelFetch(light, q, 0).rgb * omega[p];
        s = kept[p];
        e_copy[p] = vec4(e, 0.0);
    }
    if (uint(q.x) < pitch && q.y < frame_size.y) {
        const uint z = uint(q.y) * pitch + uint(q.x);
        rg[z] = e.rg;
        b[z] = vec2(e.b, 0.0);
    }
    sum_e[t] = vec4(e, 0.0);
    sum_es[t] = vec4(e * s, 0.0);
    barrier();
    for (uint half_size = 128u; half_size > 0u; half_size >>= 1u) {
        if (t < half_size) {
            sum_e[t] += sum_e[t + half_size];
            sum_es[t] += sum_es[t + half_size];
        }
        barrier();
    }
    if (t == 0u) {
        const uint g = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
        partials[2u * g] = sum_e[0];
        partials[2u * g + 1u] = sum_es[0];
    }
}
#endif

#ifdef VEIL_MULTIPLY
layout(std430, binding = 6) readonly buffer KernelSpectrum { float k_hat[]; };  // Mx × My

// One row of workgroups per image row (Mx · My / 256 groups in one dimension
// would pass GL's guaranteed 65535 at 4096 × 4096).
void main() {
    if (gl_GlobalInvocationID.x >= pitch) return;
    const uint i = gl_GlobalInvocationID.y * pitch + gl_GlobalInvocationID.x;
    const float k = k_hat[i];
    const vec2 x = rg[i] * k, y = b[i] * k;
    rg[i] = vec2(x.x, -x.y);
    b[i] = vec2(y.x, -y.y);
}
#endif

#ifdef VEIL_UNPACK
layout(std430, binding = 7) readonly buffer NearKernel { float k_near[]; };  // (R + 1)², [|dy| (R + 1) + |dx|]
layout(VEIL_IMAGE_FORMAT, binding = 0) uniform image2D target;
uniform float scale;  // VEIL_ADD: the HDR target's pre-exposure
// The veil's scotopic luminance per unit RGB (display::scotopic_weights_rgb()): the veil mixes its lights,
// so its scotopic channel is taken from its RGB, not from each light's spectrum (docs/tone-mapping.md).
uniform vec3 scotopic_weights;

const int R = VEIL_NEAR_RADIUS;
const int TILE = 16 + 2 * R;
// One float array per channel: a vec3 array is padded to vec4 (R = 16: 36 KiB, past GL's guaranteed 32).
shared float tile_r[TILE * TILE], tile_g[TILE * TILE], tile_b[TILE * TILE];

void main() {
    const ivec2 origin = ivec2(gl_WorkGroupID.xy) * 16 - R;
    for (uint k = gl_LocalInvocationIndex; k < uint(TILE * TILE); k += 256u) {
        const ivec2 s = origin + ivec2(int(k) % TILE, int(k) / TILE);
        const bool inside = all(greaterThanEqual(s, ivec2(0))) && all(lessThan(s, frame_size));
        const vec3 e = inside ? e_copy[s.y * frame_size.x + s.x].rgb : vec3(0.0);
        tile_r[k] = e.r;
        tile_g[k] = e.g;
        tile_b[k] = e.b;
    }
    barrier();
    const ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    if (q.x >= frame_size.x || q.y >= frame_size.y) return;
    const ivec2 l = ivec2(gl_LocalInvocationID.xy) + R;
    vec3 near = vec3(0.0);
    for (int dy = -R; dy <= R; ++dy)
        for (int dx = -R; dx <= R; ++dx) {
            const int t = (l.y - dy) * TILE + (l.x - dx);
            near += vec3(tile_r[t], tile_g[t], tile_b[t]) * k_near[abs(dy) * (R + 1) + abs(dx)];
        }
    const uint z = uint(q.y) * pitch + uint(q.x);
    const vec3 far = vec3(rg[z].x, -rg[z].y, b[z].x);
    const vec3 luminance = max(far + near, vec3(0.0)) / omega[q.y * frame_size.x + q.x];
    const vec4 old = imageLoad(target, q);
#ifdef VEIL_ADD
    imageStore(target, q, vec4(old.rgb + luminance * scale, old.a + dot(scotopic_weights, luminance) * scale));
#else
    imageStore(target, q, vec4(luminance, dot(scotopic_weights, luminance)));
#endif
}
#endif
