// Test harness for display_encode.glsl (tests/gl/test_encode.cpp):
// codes[i] = encode_pixel(inputs[i].rgb, pixel i of a width-wide image, frame, display).
// PARAMS_IN_UBO reads the display from a std140 uniform block instead of a std430 SSBO,
// so that both layouts of GpuDisplayParams are exercised.
layout(local_size_x = 64) in;
#define DISPLAY_LUT_BINDING 3
#include "display_encode.glsl"

layout(std430, binding = 0) readonly buffer Inputs { vec4 inputs[]; };
#ifdef PARAMS_IN_UBO
layout(std140, binding = 1) uniform ParamsBlock { DisplayParams display; };
#else
layout(std430, binding = 1) readonly buffer ParamsBuffer { DisplayParams display; };
#endif
layout(std430, binding = 2) writeonly buffer Codes { uvec4 codes[]; };

uniform uint count;
uniform int width;
uniform uint frame;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= count) return;
    ivec2 pixel = ivec2(int(i) % width, int(i) / width);
    codes[i] = uvec4(encode_pixel(inputs[i].rgb, pixel, frame, display), 0u);
}
