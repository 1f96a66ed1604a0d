// Fragment lists: splat fragments into their sections (FragmentListPass).
// Shares splat.vert (FOG 0, CROSSFADE 1). Defines: CUT, HOST_DEPTH,
// NEAR_CUT, GENERAL, SECTIONS (2, 4 or 8 targets).
#if CUT
#include "partial.glsl"
#endif
#include "transparent.glsl"
layout(binding = 0) uniform sampler2DArray uLayers;
layout(binding = 2) uniform sampler2DArray uDepths; // the pixel's nearest SECTIONS - 1 surface depth keys, sorted; 2.0: none
uniform ivec2 uOrigin; // the lists' viewport origin
uniform int uReversed; // the keys are 1 - window depth (transparent_lists.glsl)
float windowOfKey(float key) { return uReversed != 0 ? 1.0 - key : key; }
in vec2 vTex;
flat in float vDensity;
flat in vec3 vLayers;
flat in vec3 vColor;
layout(location = 0) out vec4 oSection[SECTIONS];

#if CUT
// The kernel's partial line integral (the splat pass's, whose vertex stage
// this program shares).
uniform vec3 uForward;
uniform float uNearZ;
uniform int uPersp;
uniform float uKernelRadius;
layout(binding = 1) uniform sampler2D uHostDepth;
#include "host_depth.glsl"
flat in float vScale;
in vec3 vRel;
#if GENERAL
// The polygon crosses the eye plane (the camera inside the kernel).
#include "splat_plane.glsl"
#endif
float gR, gTP, gInvCos, gInvL, gLo, gHi;
float viewDepth(float key) { return splatfx_host_view_depth(windowOfKey(key)); }
// Share of the kernel's line integral on this ray in front of view depth z.
float beforeView(float z) { return splatfx_partial_before(gR, (z * gInvCos - gTP) * gInvL); }
// The share of this fragment's optical depth (between the near plane and the
// host's opaque surface) in front of the surface with key d: non-decreasing in d.
float sectionFraction(float d) { return clamp(beforeView(viewDepth(d)), gLo, gHi) - gLo; }
#else
// Without the cut the kernel is concentrated on its plane: a step at the
// plane's depth (LEQUAL on the keys, as the ordered blend's depth test).
float sectionFraction(float d) { return (uReversed != 0 ? 1.0 - gl_FragCoord.z : gl_FragCoord.z) <= d ? 1.0 : 0.0; }
#endif

void main() {
    vec4 acc[SECTIONS];
    for (int k = 0; k < SECTIONS; ++k) acc[k] = vec4(0.0);
#if CUT && GENERAL
    vec3 dir;
    float tPlane;
    vec2 uvk;
    if (!splatfx_splat_plane(dir, tPlane, uvk)) discard;
    vec2 tex = vec2(0.5 + 0.5 * uvk.x, 0.5 - 0.5 * uvk.y);
#else
    vec2 tex = vTex;
#endif
    vec4 t = texture(uLayers, vec3(tex, vLayers.x));
    if (vLayers.z > 0.0) t = mix(t, texture(uLayers, vec3(tex, vLayers.y)), vLayers.z);
#if CUT
#if GENERAL
    gTP = tPlane;
    gInvCos = 1.0 / dot(dir, uForward);
#else
    vec2 uvk = vec2(2.0 * vTex.x - 1.0, 1.0 - 2.0 * vTex.y);
    float zP = dot(vRel, uForward);
    gTP = uPersp != 0 ? length(vRel) : zP; // along the ray from the eye (ortho: from its plane)
    gInvCos = uPersp != 0 ? gTP / zP : 1.0;
#endif
    gR = uKernelRadius * length(uvk);
    gInvL = 1.0 / vScale;
    // The near and host cuts only where the CPU found the support may meet
    // them (per-draw variants: a software rasterizer runs masked branches).
#if NEAR_CUT
    gLo = beforeView(uNearZ);
#else
    gLo = 0.0;
#endif
#if HOST_DEPTH
    gHi = max(beforeView(splatfx_host_view_depth(texelFetch(uHostDepth, ivec2(gl_FragCoord.xy), 0).r)), gLo);
#else
    gHi = 1.0;
#endif
    float total = gHi - gLo;
#else
    float total = 1.0;
#endif
    float tau = vDensity * t.a; // log2 optical depth of the whole (uncut) fragment
    vec3 colour = vColor * t.rgb;
    if (tau > 0.0 && total > 0.0) {
        ivec2 p = ivec2(gl_FragCoord.xy) - uOrigin;
        // base: surfaces wholly in front; cuts: those inside the kernel, near to far.
        int base = 0, n = 0;
        float cuts[SECTIONS];
        float fracs[SECTIONS];
        // The pixel's surfaces, nearest first, from the depth layers the
        // prepare pass sorted (a texture: on Mesa's llvmpipe a fragment
        // shader's storage-buffer reads return wrong data in partially
        // covered blocks, so the lists are walked only in compute shaders).
        for (int k = 0; k < SECTIONS - 1; ++k) {
            float d = texelFetch(uDepths, ivec3(p, k), 0).r;
            if (d > 1.5) break; // no more surfaces
            float f = sectionFraction(d);
            if (f <= 0.0) { ++base; continue; }
            if (f >= total) break; // this and every farther surface lie behind the kernel
            cuts[n] = d;
            fracs[n] = f;
            ++n;
        }
        // Bounded loop, no continue: llvmpipe dropped the last trip of the
        // data-dependent form of this loop (the section behind the last cut).
        float before = 0.0;
        for (int k = 0; k <= SECTIONS; ++k) {
            if (k > n) break;
            float F = k < n ? fracs[k] : total;
            float frac = max(F - before, 0.0);
            before = max(before, F);
            if (frac > 0.0) {
                // A section's alpha from its share: the sections' transmittances
                // multiply back to the (cut) splat's.
                float a = 1.0 - exp2(-tau * frac);
                int s = min(base + k, SECTIONS - 1); // base + n <= SECTIONS - 1 by construction
                // Nearer parts first; a constant index per target.
                for (int q = 0; q < SECTIONS; ++q)
                    if (q == s) acc[q] += (1.0 - acc[q].a) * vec4(colour * a, a);
            }
        }
    }
    for (int k = 0; k < SECTIONS; ++k) oSection[k] = acc[k];
}
