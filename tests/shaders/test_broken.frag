// Deliberately broken shader: the GL layer's tests check that the compile
// error names this file, the stage and the driver log's line.
out vec4 colour;
void main() {
    colour = vec4(undefined_symbol, 1.0);
}
