// The host's window depth -> view depth, in every depth convention: the one
// formula of the passes that read the host depth (splatfx::depthUnprojection,
// depth_convention.hpp; its two ends set by render/gl/host_depth.cpp).
// Perspective: 1 / view depth is affine in window depth, the blend of its
// values at d = 0 and d = 1 (both >= 0: nothing cancels at any far / near
// ratio; 0 at the sky under an infinite far plane, whose view depth is then
// +inf). Orthographic: view depth itself is affine in d.
uniform vec3 uHostDepthMap; // (value at d = 0, at d = 1, 1: perspective (1 / view depth) / 0: orthographic (view depth))

// The affine part: 1 / view depth (perspective) or view depth (orthographic).
float splatfx_host_depth_blend(float d) { return (1.0 - d) * uHostDepthMap.x + d * uHostDepthMap.y; }
// View depth (distance along the view direction) of window depth d; +inf
// beyond an infinite far plane.
float splatfx_host_view_depth(float d) {
    float m = splatfx_host_depth_blend(d);
    if (uHostDepthMap.z < 0.5) return m;
    return m > 0.0 ? 1.0 / m : uintBitsToFloat(0x7f800000u);
}
