// Test kernel: out[i] = a * in[i] + b, used by the GL layer's tests.
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer In { float values_in[]; };
layout(std430, binding = 1) writeonly buffer Out { float values_out[]; };
uniform float a;
uniform float b;
uniform uint count;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    values_out[i] = a * values_in[i] + b;
}
