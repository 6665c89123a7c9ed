#version 450
// Full-target "quad": one triangle that covers the whole viewport, so the fragment
// shader runs exactly once per texel of the render area (the texture-era GPGPU pass).
void main() {
    vec2 p = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
