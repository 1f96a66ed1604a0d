// Tetrahedra (TetraPass): the per-tetrahedron records as flat varyings. Define: RGB.
layout(std430, binding = 0) readonly buffer Tets { vec4 uTets[]; };
uniform mat4 uViewProjRel; // proj * view * translate(eye)
uniform int uFirst;        // the vec4 the draw's first record starts at
#if RGB
const int kStride = 12; // + the green and blue sources (vScalar is the red one)
flat out vec4 vScalarG;
flat out vec4 vScalarB;
#else
const int kStride = 10;
#endif
out vec3 vRel;
// The per-tetrahedron functions as flat varyings: the fragment reads no buffer.
flat out vec4 vPlane[4];
flat out vec4 vScalar;
flat out vec4 vLength;
// Vertex 4 t + k is corner k of the draw's tetrahedron t: the index buffer
// (kTetraFaces) makes its four faces of the four corners, so each corner is
// shaded once, not once per face.
void main() {
    int base = uFirst + (gl_VertexID / 4) * kStride;
    vec3 p = uTets[base + gl_VertexID % 4].xyz;
    vRel = p;
    for (int i = 0; i < 4; ++i) vPlane[i] = uTets[base + 4 + i];
    vScalar = uTets[base + 8];
    vLength = uTets[base + 9];
#if RGB
    vScalarG = uTets[base + 10];
    vScalarB = uTets[base + 11];
#endif
    gl_Position = uViewProjRel * vec4(p, 1.0);
}
