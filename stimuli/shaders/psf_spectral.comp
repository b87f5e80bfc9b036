// Spectral integration of the PSF (K2012 §4.2.4, eq 4.9-4.10): the GPU twin of
// spectral_psf_resampled() in psf.cpp. For each wavelength sample,
// F_λ(x) = F_λ0(x·λ0/λ)·(λ0/λ)², looked up trilinearly (levels 0 and 1,
// LOD = max(0, log2(λ0/λ)): Moiré-free minification for λ < λ0), weighted by
// CMF × SPD, then XYZ → linear Rec.709, clipped at 0. Manual bilinear lookups
// (texelFetch-style on buffers) keep the arithmetic identical to the CPU twin.
layout(local_size_x = 256) in;

const int MAX_SAMPLES = 128;
uniform uint n;
uniform int sample_count;
uniform float ratio[MAX_SAMPLES];   // λ0 / λ
uniform vec3 weight[MAX_SAMPLES];   // xyz weight · (λ0/λ)²
uniform mat3 xyz_to_rgb;

layout(std430, binding = 1) readonly buffer Mono { float mono[]; };
layout(std430, binding = 2) readonly buffer Level1 { float level1[]; };
layout(std430, binding = 3) writeonly buffer Rgb { vec4 rgb[]; };

float fetch0(int x, int y) {
    int m = int(n);
    return (x < 0 || y < 0 || x >= m || y >= m) ? 0.0 : mono[y * m + x];
}
float fetch1(int x, int y) {
    int m = int(n) / 2;
    return (x < 0 || y < 0 || x >= m || y >= m) ? 0.0 : level1[y * m + x];
}
float bilinear0(vec2 p) {
    vec2 f = floor(p);
    ivec2 i = ivec2(f);
    vec2 t = p - f;
    return mix(mix(fetch0(i.x, i.y), fetch0(i.x + 1, i.y), t.x), mix(fetch0(i.x, i.y + 1), fetch0(i.x + 1, i.y + 1), t.x), t.y);
}
float bilinear1(vec2 p) {
    vec2 f = floor(p);
    ivec2 i = ivec2(f);
    vec2 t = p - f;
    return mix(mix(fetch1(i.x, i.y), fetch1(i.x + 1, i.y), t.x), mix(fetch1(i.x, i.y + 1), fetch1(i.x + 1, i.y + 1), t.x), t.y);
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= n * n) return;
    float c = float(n / 2u);
    vec2 x = vec2(float(i % n), float(i / n)) - c;
    vec3 xyz = vec3(0.0);
    for (int s = 0; s < sample_count; ++s) {
        vec2 p = c + x * ratio[s];
        float v = bilinear0(p);
        float lod = max(0.0, log2(ratio[s]));
        if (lod > 0.0) v = mix(v, bilinear1((p - 0.5) * 0.5), min(lod, 1.0));
        xyz += weight[s] * v;
    }
    rgb[i] = vec4(max(xyz_to_rgb * xyz, vec3(0.0)), 0.0);
}
