// Test harness for tonemap.glsl (tests/gl/test_tonemap.cpp): out[i] = tonemap_pixel(in[i].rgb,
// in[i].a, tm) for one ToneMapParams uploaded as a uniform block.
#include "tonemap.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Pixels { vec4 pixels[]; };  // rgb: cd/m²; a: adaptation (cd/m²)
layout(std430, binding = 1) writeonly buffer Mapped { vec4 mapped[]; };  // rgb: display-relative
layout(std140, binding = 0) uniform ToneMapBlock { ToneMapParams tm; };

uniform uint count;
// > 0: the pixel's scotopic luminance is scotopic_scale × its green channel (a rod signal that is not
// the RGB weights'), through tonemap_pixel_scotopic; 0: tonemap_pixel.
uniform float scotopic_scale;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    vec4 px = pixels[i];
    vec3 rgb = scotopic_scale > 0.0 ? tonemap_pixel_scotopic(px.rgb, scotopic_scale * px.g, px.a, tm)
                                    : tonemap_pixel(px.rgb, px.a, tm);
    mapped[i] = vec4(rgb, 0.0);
}
