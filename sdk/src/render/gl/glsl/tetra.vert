// Tetrahedra (TetraPass): the per-tetrahedron records as flat varyings.
layout(std430, binding = 0) readonly buffer Tets { vec4 uTets[]; };
uniform mat4 uViewProjRel; // proj * view * translate(eye)
uniform int uFirst;
out vec3 vRel;
// The per-tetrahedron functions as flat varyings: the fragment reads no buffer.
flat out vec4 vPlane[4];
flat out vec4 vScalar;
flat out vec4 vLength;
// Vertex 4 t + k is corner k of the draw's tetrahedron t: the index buffer
// (kTetraFaces) makes its four faces of the four corners, so each corner is
// shaded once, not once per face.
void main() {
    int tet = uFirst + gl_VertexID / 4;
    vec3 p = uTets[tet * 10 + gl_VertexID % 4].xyz;
    vRel = p;
    for (int i = 0; i < 4; ++i) vPlane[i] = uTets[tet * 10 + 4 + i];
    vScalar = uTets[tet * 10 + 8];
    vLength = uTets[tet * 10 + 9];
    gl_Position = uViewProjRel * vec4(p, 1.0);
}
