// One triangle covering the viewport, from gl_VertexID; no vertex buffer.
// Corners (-1, -1), (3, -1), (-1, 3) in this order (every full-screen pass).
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    gl_Position = vec4(p, 0.0, 1.0);
}
