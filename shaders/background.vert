// shaders/background.vert: one triangle over the whole image at the far plane (depth 0 in the lit
// pass's reversed Z), drawn after the scene where nothing covered a pixel (raster/lit_pass.h).
#version 450

void main() {
    // Vertices (-1, -1), (3, -1), (-1, 3): the triangle holds the square [-1, 1]².
    const vec2 p = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
