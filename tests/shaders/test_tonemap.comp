// Test harness for tonemap.glsl (tests/gl/test_tonemap.cpp): out[i] = tonemap_pixel(in[i].rgb,
// in[i].a, tm) for one ToneMapParams uploaded as a uniform block.
#include "tonemap.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Pixels { vec4 pixels[]; };  // rgb: cd/m²; a: adaptation (cd/m²)
layout(std430, binding = 1) writeonly buffer Mapped { vec4 mapped[]; };  // rgb: display-relative
layout(std140, binding = 0) uniform ToneMapBlock { ToneMapParams tm; };

uniform uint count;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    vec4 px = pixels[i];
    mapped[i] = vec4(tonemap_pixel(px.rgb, px.a, tm), 0.0);
}
