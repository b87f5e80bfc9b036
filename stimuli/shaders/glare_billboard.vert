// Glare billboards (K2012 §5.3): one point per light, no attributes; the
// geometry shader reads the light's evaluation from the LightDraw buffer.
flat out int v_light;

void main() {
    v_light = gl_VertexID;
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
}
