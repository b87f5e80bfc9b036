// Each light's direct image as an instanced screen-space quad over its
// footprint (disc of area A, or a unit box below 1 px²) plus a pixel of margin.
struct LightDraw {
    vec4 centre;
    vec4 illuminance;
    vec4 factors;
    vec4 skip;
};
layout(std430, binding = 3) readonly buffer Draws { LightDraw draws[]; };

uniform vec2 image_size;
uniform int path;  // draw only the lights of this glare path (LightDraw skip.z); -1: every light

flat out vec2 v_centre;
flat out float v_area;
flat out float v_radius;  // disc radius (px), for disc footprints
flat out vec3 v_illuminance;
flat out float v_scotopic;  // scotopic illuminance (scotopic lux): S/P (skip.w) × the photopic lux

void main() {
    LightDraw d = draws[gl_InstanceID];
    v_centre = d.centre.xy;
    v_area = d.centre.w;
    v_illuminance = d.illuminance.rgb;
    v_scotopic = d.skip.w * dot(vec3(0.2126, 0.7152, 0.0722), d.illuminance.rgb);
    v_radius = sqrt(max(d.centre.w, 0.0) / 3.14159265358979);
    if (d.centre.w <= 0.0 || (path >= 0 && int(d.skip.z) != path)) {  // not drawn: a degenerate quad outside the clip volume
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        return;
    }
    float half_extent = (d.centre.w >= 1.0 ? v_radius : 0.5) + 1.0;
    vec2 corner = vec2(gl_VertexID & 1, (gl_VertexID >> 1) & 1) * 2.0 - 1.0;
    vec2 p = d.centre.xy + corner * half_extent;
    gl_Position = vec4(p / image_size * 2.0 - 1.0, 0.0, 1.0);
}
