// ---- splatfx transparent-surface include (splatfx/transparency.hpp) ----
layout(early_fragment_tests) in;
#include "transparent_lists.glsl"

vec4 splatfx_emitTransparent(vec4 premultipliedColour, float windowDepth) {
    ivec2 p = ivec2(gl_FragCoord.xy) - ivec2(splatfx_originX, splatfx_originY);
    bool inside = p.x >= 0 && p.y >= 0 && p.x < splatfx_width && p.y < splatfx_height;
    vec4 result = inside ? vec4(0.0) : premultipliedColour;
    // Helper invocations (the unused lanes of a 2x2 quad at a triangle's
    // edge) must not touch the lists.
    if (inside && !gl_HelperInvocation && any(notEqual(premultipliedColour, vec4(0.0)))) {
        uint i = atomicAdd(splatfx_allocated, 1u);
        if (i < uint(splatfx_nodes.length())) {
            // One 16-byte store (a software rasterizer scatters each store per lane).
            uint next = imageAtomicExchange(splatfx_surfaceHeads, p, i);
            splatfx_nodes[i] = splatfx_Node(packHalf2x16(premultipliedColour.rg), packHalf2x16(premultipliedColour.ba),
                                            floatBitsToUint(clamp(splatfx_depthReversed != 0 ? 1.0 - windowDepth : windowDepth, 0.0, 1.0)), next);
        } else {
            atomicAdd(splatfx_fallback, 1u);
            result = premultipliedColour;
        }
    }
    return result;
}
// ---- end splatfx transparent-surface include ----
