// Shows encoded code values on the bound framebuffer: code / (2^bits - 1) in a
// unorm framebuffer of the same depth is the code itself (8 or 10 bits).
layout(std430, binding = 8) readonly buffer Codes { uvec2 codes[]; };
uniform ivec2 size;
uniform ivec2 origin;  // lower-left corner of the viewport (px)
uniform float max_code;
layout(location = 0) out vec4 colour;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy) - origin;
    if (any(lessThan(p, ivec2(0))) || any(greaterThanEqual(p, size))) discard;
    uvec2 c = codes[p.y * size.x + p.x];
    colour = vec4(float(c.x & 0xFFFFu), float(c.x >> 16), float(c.y), max_code) / max_code;
}
