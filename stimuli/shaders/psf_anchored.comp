// The anchored spectral path on the GPU (spectral_path.h; the GPU twin of
// spectral_psf_anchored(), arithmetic in the same order), one variant per
// #define (Program::build defines):
//   OP_ANCHOR   one anchor's monochromatic PSF at unit sum: the scatter's |F|²
//               (or a one-scale eye's whole |F|²) plus the two-scale eye's
//               core |F|² binned by area onto the scatter's grid (psf.h
//               bin_into, gathered here: per axis the fine texels that overlap
//               each coarse texel, with their shares), over the sum of both
//               (docs/glare.md "Two scales"; K2012 eq 4.6, eq 4.8, §4.2.3).
//   OP_COMBINE  every spectral sample from its anchors, each term K2012 eq 4.9
//               by separable Lanczos-3 (zero outside the grid) times its
//               Lagrange weight and gain, weighted by CMF × SPD, then XYZ →
//               linear Rec.709 clipped at 0 (the recipe: spectral_terms.h).
layout(local_size_x = 256) in;

uniform uint n;  // texels per side

layout(std430, binding = 2) buffer Anchors { float anchor[]; };  // anchor k at k·n²

#if defined(OP_ANCHOR)
uniform uint anchor_index;
uniform bool two_scales;
layout(std430, binding = 1) readonly buffer Scatter { float scatter[]; };  // |F|², centred, unnormalised
layout(std430, binding = 4) readonly buffer ScatterSum { dvec4 scatter_sum; };
layout(std430, binding = 5) readonly buffer Core { float core[]; };
layout(std430, binding = 6) readonly buffer CoreSum { dvec4 core_sum; };
// bins[0 … n]: each coarse index's first entry; then entries of two words from
// bins[n + 1]: the fine index and its share (float bits).
layout(std430, binding = 7) readonly buffer Bins { uint bins[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= n * n) return;
    uint cx = i % n, cy = i / n;
    double total = scatter_sum.x;
    double v = double(scatter[i]);
    if (two_scales) {
        total += core_sum.x;
        float binned = 0.0;
        for (uint ey = bins[cy]; ey < bins[cy + 1u]; ++ey) {
            uint ky = bins[n + 1u + 2u * ey];
            float sy = uintBitsToFloat(bins[n + 2u + 2u * ey]);
            for (uint ex = bins[cx]; ex < bins[cx + 1u]; ++ex) {
                uint kx = bins[n + 1u + 2u * ex];
                float sx = uintBitsToFloat(bins[n + 2u + 2u * ex]);
                binned += core[ky * n + kx] * sy * sx;
            }
        }
        v += double(binned);
    }
    anchor[anchor_index * n * n + i] = total > 0.0LF ? float(v / total) : 0.0;
}

#elif defined(OP_COMBINE)
uniform uint sample_count;
uniform mat3 xyz_to_rgb;
struct Sample {
    vec4 xyz;  // CMF × SPD weight (w unused)
    uint first_term, term_count;
};
struct Term {
    uint anchor;
    int taps;  // the first of this term's n Tap records, or −1: the anchor as it is (ratio 1)
    float scale;
    uint unused;
};
struct Tap {
    int first;   // the first source texel of the six
    float w[6];  // Lanczos-3 weights
};
layout(std430, binding = 3) writeonly buffer Rgb { vec4 rgb[]; };
layout(std430, binding = 5) readonly buffer Samples { Sample samples[]; };
layout(std430, binding = 6) readonly buffer Terms { Term terms[]; };
layout(std430, binding = 7) readonly buffer Taps { Tap taps[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= n * n) return;
    int m = int(n);
    int x = int(i % n), y = int(i / n);
    vec3 xyz = vec3(0.0);
    for (uint s = 0u; s < sample_count; ++s) {
        float acc = 0.0;
        uint t_end = samples[s].first_term + samples[s].term_count;
        for (uint t = samples[s].first_term; t < t_end; ++t) {
            Term term = terms[t];
            uint base = term.anchor * n * n;
            if (term.taps < 0) {
                acc += term.scale * anchor[base + i];
                continue;
            }
            Tap tx = taps[term.taps + x], ty = taps[term.taps + y];
            for (int b = 0; b < 6; ++b) {
                int sy = ty.first + b;
                if (sy < 0 || sy >= m) continue;
                float row = 0.0;
                for (int a = 0; a < 6; ++a) {
                    int sx = tx.first + a;
                    if (sx >= 0 && sx < m) row += tx.w[a] * anchor[base + uint(sy * m + sx)];
                }
                acc += (term.scale * ty.w[b]) * row;
            }
        }
        xyz += samples[s].xyz.xyz * acc;
    }
    rgb[i] = vec4(max(xyz_to_rgb * xyz, vec3(0.0)), 0.0);
}
#endif
