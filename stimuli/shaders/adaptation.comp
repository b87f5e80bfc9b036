// Adaptation luminance on the GPU (K2012 eq 4.15-4.17), without a CPU round trip:
//   PASS_PARTIAL: each workgroup sums log(Y + ε) over its share of the HDR frame
//                 (every `stride`-th pixel in x and y) in double precision;
//   PASS_FINAL:   one workgroup sums the partials, forms the log-average
//                 L̄w = exp(mean) (eq 4.15) and steps the adapted luminance
//                 L̄wa towards it by eq 4.16 with τ from eq 4.17 — or sets it to
//                 the fixed level when the protocol fixes adaptation.
// state.x: adapted luminance L̄wa (cd/m²); state.y: last log-average (cd/m²);
// state.z: 1 once initialised (the first frame adopts the target at once).
layout(local_size_x = 256) in;

layout(std430, binding = 6) buffer Partials { double partial_sums[]; };
layout(std430, binding = 7) buffer State { dvec4 state; };

#if defined(PASS_PARTIAL)
layout(binding = 0) uniform sampler2D hdr;  // RGBA32F, cd/m²
uniform ivec2 size;
uniform int stride;
uniform float epsilon_cd_m2;
uniform float inv_pre_exposure;  // the frame holds cd/m² × pre-exposure (frame_renderer.h)
shared double sums[256];

void main() {
    uint t = gl_LocalInvocationID.x;
    ivec2 grid = (size + stride - 1) / stride;
    uint total = uint(grid.x * grid.y);
    uint per_group = (total + gl_NumWorkGroups.x - 1u) / gl_NumWorkGroups.x;
    uint begin = gl_WorkGroupID.x * per_group, end = min(total, begin + per_group);
    double s = 0.0LF;
    for (uint i = begin + t; i < end; i += 256u) {
        ivec2 p = ivec2(int(i) % grid.x, int(i) / grid.x) * stride;
        // As log_average_luminance() (tonemap.cpp): NaN and negatives count as 0 and values are
        // capped at kMaxInputCdM2, so a +inf texel (an overflowed RGBA16F frame) or a NaN cannot
        // make the adapted luminance inf or NaN for good (max() leaves NaN undefined).
        vec3 v = texelFetch(hdr, p, 0).rgb * inv_pre_exposure;
        vec3 c = vec3(v.r > 0.0 ? min(v.r, 1e15) : 0.0, v.g > 0.0 ? min(v.g, 1e15) : 0.0,
                      v.b > 0.0 ? min(v.b, 1e15) : 0.0);
        float y = dot(c, vec3(0.2126, 0.7152, 0.0722));
        s += double(log(y + epsilon_cd_m2));
    }
    sums[t] = s;
    barrier();
    for (uint k = 128u; k > 0u; k >>= 1) {
        if (t < k) sums[t] += sums[t + k];
        barrier();
    }
    if (t == 0u) partial_sums[gl_WorkGroupID.x] = sums[0];
}
#elif defined(PASS_FINAL)
uniform uint partial_count;
uniform uint sample_count;
uniform float epsilon_cd_m2;
uniform int fixed_mode;        // 1: state.x = fixed_cd_m2
uniform double fixed_cd_m2;    // the eye's level (Scene::adaptation_cd_m2); fixed mode only
uniform double dt_s;           // frame time (s), ≥ 0
uniform float tau_rod_s;       // K2012: 0.4 s
uniform float tau_cone_s;      // K2012: 0.1 s
uniform float rod_sigma_cd_m2; // eq 4.27: 0.04 cd/m²
shared double sums[256];

void main() {
    uint t = gl_LocalInvocationID.x;
    double s = 0.0LF;
    for (uint i = t; i < partial_count; i += 256u) s += partial_sums[i];
    sums[t] = s;
    barrier();
    for (uint k = 128u; k > 0u; k >>= 1) {
        if (t < k) sums[t] += sums[t + k];
        barrier();
    }
    if (t != 0u) return;
    // eq 4.15; ε is added inside the log only, as the thesis writes it.
    double target = double(exp(float(sums[0] / double(sample_count))));
    dvec4 st = state;
    st.y = target;
    if (fixed_mode == 1) {
        st.x = fixed_cd_m2;
        st.y = fixed_cd_m2;
    } else if (st.z == 0.0LF) {
        st.x = target;
    } else {
        // eq 4.16-4.17: τ from the rod sensitivity at the target (eq 4.27).
        float sigma = rod_sigma_cd_m2 / (rod_sigma_cd_m2 + float(target));
        float tau = sigma * tau_rod_s + (1.0 - sigma) * tau_cone_s;
        double k = 1.0LF - double(exp(-float(dt_s) / tau));
        st.x = st.x + (target - st.x) * k;
    }
    st.z = 1.0LF;
    state = st;
}
#endif
