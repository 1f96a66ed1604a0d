// Fragment lists, resolve: sorts each pixel's surface list and composites it
// with the splat sections. Defines: K (entries kept per pixel), FRAG: 0 a
// compute shader (one invocation per pixel, list_resolve.comp), 1 a
// full-screen fragment shader reading the pool through a texture buffer
// (list_resolve.frag).
#if FRAG
// The fragment variant: nodes through a texture buffer view of the pool
// (RGBA32UI: rg, ba, depth bits, next), composited "over" the framebuffer
// by the blend unit. No storage-buffer access (see above).
layout(binding = 4) uniform usamplerBuffer uNodes;
layout(location = 0) out vec4 oColor;
const uint splatfx_kEnd = 0xffffffffu;
#define NODE(i) texelFetch(uNodes, int(i))
#else
#include "transparent_lists.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba16f, binding = 5) writeonly uniform image2D uResolved;
#define NODE(i) uvec4(splatfx_nodes[i].rg, splatfx_nodes[i].ba, splatfx_nodes[i].depthBits, splatfx_nodes[i].next)
#endif
layout(binding = 1) uniform sampler2DArray uSections;
layout(binding = 2) uniform usampler2D uHeads;
uniform ivec2 uOrigin;      // the lists' viewport origin in the section targets
uniform ivec2 uSize;        // the lists' viewport size
uniform int uSectionCount;  // 0: the splats were not drawn into sections

vec4 over(vec4 front, vec4 back) { return front + (1.0 - front.a) * back; }
vec4 section(ivec2 p, int k) { return k < uSectionCount ? texelFetch(uSections, ivec3(p + uOrigin, k), 0) : vec4(0.0); }

void main() {
#if FRAG
    ivec2 p = ivec2(gl_FragCoord.xy) - uOrigin;
    if (p.x < 0 || p.y < 0 || p.x >= uSize.x || p.y >= uSize.y) discard;
#else
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= uSize.x || p.y >= uSize.y) return;
#endif
#if FRAG && K == 1
    // At most one surface on any pixel (the variant is chosen so): no walk, no sort.
    uint i = texelFetch(uHeads, p, 0).x;
    vec4 acc = section(p, 0);
    if (i != splatfx_kEnd) {
        uvec4 node = NODE(i);
        acc = over(over(acc, vec4(unpackHalf2x16(node.x), unpackHalf2x16(node.y))), section(p, 1));
    } else {
        acc = over(acc, section(p, 1));
    }
#else
    // (d, c) into the depth-sorted entries [0, from]: the nearer ones stay, the farther move back one.
#define INSERT_SORTED(from)                         \
    {                                               \
        int j = from;                               \
        while (j > 0 && d < eDepth[j - 1]) {        \
            eDepth[j] = eDepth[j - 1];              \
            eColour[j] = eColour[j - 1];            \
            --j;                                    \
        }                                           \
        eDepth[j] = d;                              \
        eColour[j] = c;                             \
    }
    float eDepth[K];
    vec4 eColour[K];
    int n = 0;
    uint merged = 0u;
    uint i = texelFetch(uHeads, p, 0).x;
    while (i != splatfx_kEnd) {
        uvec4 node = NODE(i);
        i = node.w;
        float d = uintBitsToFloat(node.z);
        vec4 c = vec4(unpackHalf2x16(node.x), unpackHalf2x16(node.y));
        if (n == K) {
            // Full: the farthest two of the K + 1 become one ("over").
            ++merged;
            if (d >= eDepth[K - 1]) {
                eColour[K - 1] = over(eColour[K - 1], c);
                continue;
            }
            vec4 last = eColour[K - 1];
            INSERT_SORTED(K - 1);
            eColour[K - 1] = over(eColour[K - 1], last);
            continue;
        }
        INSERT_SORTED(n++);
    }
#if !FRAG
    if (merged > 0u) {
        atomicAdd(splatfx_overflowPixels, 1u);
        atomicAdd(splatfx_mergedNodes, merged);
    }
#endif
    // Front to back: section 0, surface 0, section 1, ... The sections past
    // the last kept surface (more surfaces than sections or than K) follow it.
    vec4 acc = section(p, 0);
    for (int k = 0; k < n; ++k) {
        acc = over(acc, eColour[k]);
        if (k + 1 < n) acc = over(acc, section(p, k + 1));
    }
    for (int k = max(n, 1); k < uSectionCount; ++k) acc = over(acc, section(p, k));
#endif
#if FRAG
    if (acc == vec4(0.0)) discard;
    oColor = acc;
#else
    imageStore(uResolved, p, acc);
#endif
}
