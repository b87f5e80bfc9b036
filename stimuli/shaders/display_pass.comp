// Tone mapping and display encoding of one frame (docs/architecture.md "The pipeline, one frame", steps 5-6):
// every pixel of the HDR frame (cd/m²) is tone-mapped at the adapted luminance
// that adaptation.comp left in the State buffer, then encoded to the display's
// code values with dithering. With LDR_PATH (K2012 §6.2.2, "adding glare to an
// LDR renderer") the input is a display-referred frame (linear, relative to the
// display's white) and only the separate glare buffer is tone-mapped and added.
#include "tonemap.glsl"
#define DISPLAY_LUT_BINDING 9
#include "display_encode.glsl"

layout(local_size_x = 16, local_size_y = 16) in;

layout(binding = 0) uniform sampler2D frame_in;  // HDR cd/m², or LDR relative (LDR_PATH)
#if defined(LDR_PATH)
layout(binding = 1) uniform sampler2D glare_hdr;  // glare billboards alone, cd/m²
#endif
layout(std140, binding = 0) uniform ToneBlock { ToneMapParams tone; };
layout(std140, binding = 1) uniform DisplayBlock { DisplayParams display; };
layout(std430, binding = 7) readonly buffer State { dvec4 state; };
layout(std430, binding = 8) writeonly buffer Codes { uvec2 codes[]; };  // (r | g << 16, b)

uniform ivec2 size;
uniform uint frame_index;
// 1: the input's alpha holds the pixel's scotopic luminance (scotopic cd/m², × pre-exposure like RGB;
// the FrameRenderer's frames, docs/tone-mapping.md "The scotopic channel"); 0: V from RGB's weights.
uniform int scotopic_alpha;
#if !defined(LDR_PATH)
uniform float inv_pre_exposure;  // the frame holds cd/m² × pre-exposure (frame_renderer.h)
#endif
#if defined(LDR_PATH)
// 0: frame_in is display-referred (relative to white); > 0: frame_in is an HDR
// frame in cd/m² that an LDR renderer would show by exposure, times this scale,
// clipped at white.
uniform float ldr_scale;
#endif

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, size))) return;
    float adaptation = float(state.x);
#if defined(LDR_PATH)
    vec3 scene = max(texelFetch(frame_in, p, 0).rgb, vec3(0.0));
    if (ldr_scale > 0.0) scene = min(scene * ldr_scale, vec3(1.0));
    vec4 g = texelFetch(glare_hdr, p, 0);
    vec3 relative = scene + tonemap_pixel_scotopic(g.rgb, scotopic_alpha != 0 ? max(g.a, 0.0) : -1.0, adaptation, tone);
#else
    vec4 hdr = texelFetch(frame_in, p, 0) * inv_pre_exposure;
    vec3 relative = tonemap_pixel_scotopic(hdr.rgb, scotopic_alpha != 0 ? max(hdr.a, 0.0) : -1.0, adaptation, tone);
#endif
    uvec3 c = encode_pixel(relative, p, frame_index, display);
    codes[p.y * size.x + p.x] = uvec2(c.r | (c.g << 16), c.b);
}
