// The per-pixel fragment lists' storage (the node pool, its counters, the
// list heads), shared by the host's transparent include (transparent.glsl)
// and the fragment lists' compute passes. The bindings are the GL backend's
// (render/gl/transparent_bindings.hpp checks them against this file).
#define SPLATFX_NODE_BINDING 6
#define SPLATFX_COUNTER_BINDING 7
#define SPLATFX_HEAD_UNIT 6
struct splatfx_Node {
    uint rg, ba;   // premultiplied colour, packHalf2x16
    uint depthBits; // depth key (floatBitsToUint): the window depth, 1 - window depth under a reversed convention (nearer: smaller)
    uint next;     // next node of this pixel (0xffffffff ends the list)
};
layout(std430, binding = SPLATFX_NODE_BINDING) coherent buffer splatfx_NodePool { splatfx_Node splatfx_nodes[]; };
layout(std430, binding = SPLATFX_COUNTER_BINDING) coherent buffer splatfx_Counters {
    uint splatfx_allocated;    // nodes handed out this frame (may pass the pool's size: those were not stored)
    uint splatfx_fallback;     // fragments that found the pool full (blended by the caller instead)
    int splatfx_originX, splatfx_originY, splatfx_width, splatfx_height; // the lists' viewport
    uint splatfx_maxSurfaces;  // most surfaces stored on one pixel (counted after the hook, from the lists)
    uint splatfx_sectionOverflow, splatfx_overflowPixels, splatfx_mergedNodes;
    int splatfx_depthReversed; // 1: the host's depth convention is reversed (window depth falls with distance)
};
layout(r32ui, binding = SPLATFX_HEAD_UNIT) coherent uniform uimage2D splatfx_surfaceHeads;
const uint splatfx_kEnd = 0xffffffffu;
