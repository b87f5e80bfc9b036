// The per-texel steps of the GPU PSF (K2012 §4.2.2-4.2.4), one variant per
// #define (Program::build defines):
//   OP_MAGNITUDE   mono[shift(x)] = |F(x)|²          (eq 4.6, cyclic shift eq 4.8)
//   OP_SCALE_MONO  mono[x] /= sum                    (§4.2.3, unit sum)
//   OP_DOWNSAMPLE  level1[x] = 2×2 box of mono       (the mip level the spectral lookup uses)
//   OP_SCALE_RGB   rgb[x] /= luminance sum           (the RGB PSF's luminance sums to 1)
layout(local_size_x = 256) in;

uniform uint n;  // texels per side of the level written
#if defined(OP_SCALE_RGB)
uniform vec3 luminance_weights;  // Y of linear Rec.709 R, G, B
#endif

layout(std430, binding = 0) buffer Spectrum { vec2 field[]; };
layout(std430, binding = 1) buffer Mono { float mono[]; };
layout(std430, binding = 2) buffer Level1 { float level1[]; };
layout(std430, binding = 3) buffer Rgb { vec4 rgb[]; };
layout(std430, binding = 4) readonly buffer Sums { dvec4 sums; };  // written by psf_reduce.comp

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= n * n) return;
    uint x = i % n, y = i / n;
#if defined(OP_MAGNITUDE)
    vec2 f = field[i];
    uint h = n / 2u;
    mono[((y + h) % n) * n + (x + h) % n] = dot(f, f);
#elif defined(OP_SCALE_MONO)
    mono[i] = float(double(mono[i]) / sums.x);
#elif defined(OP_DOWNSAMPLE)
    uint m = 2u * n;  // level-0 width
    uint b = (2u * y) * m + 2u * x;
    level1[i] = 0.25 * (mono[b] + mono[b + 1u] + mono[b + m] + mono[b + m + 1u]);
#elif defined(OP_SCALE_RGB)
    // Y's row of Rec.709 → XYZ as display::luminance_of_linear_rgb has it (the
    // rounded 0.2126/0.7152/0.0722 would leave a red light's sum 1.8e-4 off).
    double y_sum = dot(dvec3(luminance_weights), sums.xyz);
    rgb[i] = vec4(dvec4(rgb[i]) / y_sum);
#endif
}
