// Fragment lists, per 16 x 16 tile: the most surfaces on one pixel and the
// nearest and farthest surface window depth (as float bits), one work group
// per tile (FragmentListPass::split reads them back).
#include "transparent_lists.glsl"
layout(local_size_x = 8, local_size_y = 1) in;
layout(binding = 2) uniform usampler2D uHeads;
layout(rgba32ui, binding = 5) writeonly uniform uimage2D uTileRange;
uniform ivec2 uSize;
uniform ivec2 uTiles;
void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (t.x >= uTiles.x) return;
    ivec2 first = t * 16, last = min(first + 16, uSize);
    uint lo = 0xffffffffu, hi = 0u, most = 0u;
    for (int y = first.y; y < last.y; ++y)
        for (int x = first.x; x < last.x; ++x) {
            uint count = 0u;
            for (uint i = texelFetch(uHeads, ivec2(x, y), 0).x; i != splatfx_kEnd; i = splatfx_nodes[i].next) {
                uint z = floatBitsToUint(abs(uintBitsToFloat(splatfx_nodes[i].depthBits))); // -0 as +0
                lo = min(lo, z);
                hi = max(hi, z);
                ++count;
            }
            most = max(most, count);
        }
    imageStore(uTileRange, t, uvec4(lo, hi, most, 0u));
    // The most surfaces on one pixel (here rather than per fragment in the
    // include: one atomic per tile instead of two per surface fragment).
    if (most > 0u) atomicMax(splatfx_maxSurfaces, most);
}
