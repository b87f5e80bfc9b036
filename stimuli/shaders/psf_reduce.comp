// Sum of a PSF buffer in double precision (§4.2.3 normalisation: a GPU
// reduction). One workgroup: each invocation adds a strided share in double,
// then a shared-memory tree. Variants: REDUCE_MONO (float buffer → sums.x),
// REDUCE_RGB (vec4 buffer → sums.xyz per channel).
layout(local_size_x = 256) in;

uniform uint count;

layout(std430, binding = 1) readonly buffer Mono { float mono[]; };
layout(std430, binding = 3) readonly buffer Rgb { vec4 rgb[]; };
layout(std430, binding = 4) writeonly buffer Sums { dvec4 sums; };

shared dvec3 partial[256];

void main() {
    uint t = gl_LocalInvocationID.x;
    dvec3 s = dvec3(0.0);
    for (uint i = t; i < count; i += 256u) {
#if defined(REDUCE_MONO)
        s.x += double(mono[i]);
#else
        s += dvec3(rgb[i].rgb);
#endif
    }
    partial[t] = s;
    barrier();
    for (uint stride = 128u; stride > 0u; stride >>= 1) {
        if (t < stride) partial[t] += partial[t + stride];
        barrier();
    }
    if (t == 0u) sums = dvec4(partial[0], 0.0);
}
