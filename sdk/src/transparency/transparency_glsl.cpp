// The transparent-surface include (transparency.hpp). The node layout here is
// the one fragment_list_pass.cpp's shaders read: keep the two in step.
#include "splatfx/transparency.hpp"

namespace splatfx {

std::string transparentGlsl() {
    std::string s;
    s += "#define SPLATFX_NODE_BINDING " + std::to_string(kTransparentNodeBinding) + "\n";
    s += "#define SPLATFX_COUNTER_BINDING " + std::to_string(kTransparentCounterBinding) + "\n";
    s += "#define SPLATFX_HEAD_UNIT " + std::to_string(kTransparentHeadImageUnit) + "\n";
    s += R"(
// ---- splatfx transparent-surface include (splatfx/transparency.hpp) ----
layout(early_fragment_tests) in;
struct splatfx_Node {
    uint rg, ba;   // premultiplied colour, packHalf2x16
    uint depthBits; // window depth (floatBitsToUint)
    uint next;     // next node of this pixel (0xffffffff ends the list)
};
layout(std430, binding = SPLATFX_NODE_BINDING) coherent buffer splatfx_NodePool { splatfx_Node splatfx_nodes[]; };
layout(std430, binding = SPLATFX_COUNTER_BINDING) coherent buffer splatfx_Counters {
    uint splatfx_allocated;    // nodes handed out this frame (may pass the pool's size: those were not stored)
    uint splatfx_fallback;     // fragments that found the pool full (blended by the caller instead)
    int splatfx_originX, splatfx_originY, splatfx_width, splatfx_height; // the lists' viewport
    uint splatfx_maxSurfaces;  // most surfaces stored on one pixel (counted after the hook, from the lists)
    uint splatfx_sectionOverflow, splatfx_overflowPixels, splatfx_mergedNodes;
};
layout(r32ui, binding = SPLATFX_HEAD_UNIT) coherent uniform uimage2D splatfx_surfaceHeads;
const uint splatfx_kEnd = 0xffffffffu;

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
                                            floatBitsToUint(clamp(windowDepth, 0.0, 1.0)), next);
        } else {
            atomicAdd(splatfx_fallback, 1u);
            result = premultipliedColour;
        }
    }
    return result;
}
// ---- end splatfx transparent-surface include ----
)";
    return s;
}

} // namespace splatfx
