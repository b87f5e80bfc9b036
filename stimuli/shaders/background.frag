// The background (docs/architecture.md "The pipeline, one frame", step 1): a uniform field, or a sky of
// uniform luminance over a flat sea that mirrors it with Schlick's Fresnel
// factor (K2012 eq 3.17, §3.6.1), in the colour of the sky's spectrum ([environment] spd; D65 white by
// default), absolute cd/m².
// Also writes the linear view depth (m along the view axis; +inf for sky) that
// later stages use for occlusion tests (K2012 §5.3.2).
layout(location = 0) out vec4 radiance;
layout(location = 1) out float view_depth;

uniform vec2 principal_px;      // image centre (px, window coordinates)
uniform float focal_px;
uniform mat3 world_from_view;
uniform vec3 eye_position_m;
uniform float sky_luminance;    // cd/m²
uniform float sea_f0;           // Schlick R_F(0°)
uniform int sky_sea;            // 0: uniform field
uniform float pre_exposure;     // the HDR target stores luminance × pre_exposure (frame_renderer.h)
uniform float sky_s_p;          // S/P of the sky's spectrum (D65: 2.4645), for the scotopic channel
uniform vec3 sky_rgb;           // the sky's colour, linear Rec.709 with luminance 1 (D65: (1, 1, 1))

void main() {
    vec3 dir_view = normalize(vec3((gl_FragCoord.xy - principal_px) / focal_px, -1.0));
    vec3 dir = world_from_view * dir_view;
    float L = sky_luminance;
    float depth = 1.0 / 0.0;
    if (sky_sea != 0 && dir.y < 0.0 && eye_position_m.y > 0.0) {
        float cos_i = -dir.y;  // angle between the view ray and the sea's normal
        float fresnel = sea_f0 + (1.0 - sea_f0) * pow(1.0 - cos_i, 5.0);
        L = fresnel * sky_luminance;
        float t = eye_position_m.y / cos_i;
        depth = t * -dir_view.z;
    }
    // alpha: the scotopic channel (scotopic cd/m² × pre-exposure; docs/tone-mapping.md).
    radiance = vec4(sky_rgb * (L * pre_exposure), L * pre_exposure * sky_s_p);
    view_depth = depth;
}
