// Fragment lists, prepare: each pixel's nearest uLayers surface depths,
// sorted, into a texture array for the section shader (2.0 past the last).
#include "transparent_lists.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 2) uniform usampler2D uHeads;
layout(r32f, binding = 5) writeonly uniform image2DArray uDepthsOut;
uniform ivec2 uSize;
uniform int uLayers;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= uSize.x || p.y >= uSize.y) return;
    float d[7];
    int n = 0, all = 0;
    for (uint i = texelFetch(uHeads, p, 0).x; i != splatfx_kEnd; i = splatfx_nodes[i].next) {
        float z = uintBitsToFloat(splatfx_nodes[i].depthBits);
        ++all;
        if (n == uLayers && z >= d[n - 1]) continue;
        int j = n < uLayers ? n++ : n - 1; // full: the farthest kept one drops out
        while (j > 0 && z < d[j - 1]) {
            d[j] = d[j - 1];
            --j;
        }
        d[j] = z;
    }
    for (int k = 0; k < uLayers; ++k) imageStore(uDepthsOut, ivec3(p, k), vec4(k < n ? d[k] : 2.0));
    // More surfaces than the section targets separate: the gas behind the
    // extra ones is composited after the last kept surface (counted).
    if (all > uLayers) atomicAdd(splatfx_sectionOverflow, 1u);
}
