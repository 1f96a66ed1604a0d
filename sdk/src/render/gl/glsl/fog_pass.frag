// Fog of the host's opaque image (FogPass). MODE 0: per pixel, blended into
// the host colour; 1: reduced (f, distance) texture; 2: its depth-aware
// upsampling, blended into the host colour.
#include "fog.glsl"
#include "host_depth.glsl"
layout(binding = 0) uniform sampler2D uDepth; // host depth, framebuffer-sized
// Window position and depth -> world position relative to the eye, without a
// 4x4 inverse projection: its w at the far plane is the difference of two
// terms of size 1 / (2 near) whose true value is 1 / far, which float cannot
// hold when far / near is large. Instead (FogPass::draw, in double on the CPU):
//  perspective: 1 / view depth from host_depth.glsl (the blend of its values
//    at d = 0 and d = 1, in any depth convention: nothing cancels, 1 / far
//    exactly at the far plane, 0 under an infinite far plane), and the point
//    is the ray through the pixel at view depth 1 (uRay * (ndc, 1), rotated
//    to world) over it;
//  orthographic: the point is affine in (ndc, d): uRay * (ndc, 1) + d uDepthAxis.
uniform mat3 uRay;       // (ndc.x, ndc.y, 1) -> eye-relative world point (view depth 1, or d = 0 orthographic)
uniform vec3 uDepthAxis; // orthographic: the world offset from d = 0 to d = 1
uniform vec2 uOrigin;    // viewport origin, framebuffer pixels
uniform vec2 uSize;      // viewport size, pixels

// The point behind window position xy at window depth d, relative to the eye.
// False for NaN or a depth outside [0, 1] (fully fogged, as Fog::transmittance
// does), and for the sky under an infinite far plane (no finite point).
bool hostPoint(vec2 xy, float d, out vec3 rel) {
    rel = vec3(0.0);
    if (isnan(d) || !(d >= 0.0 && d <= 1.0)) return false;
    vec2 ndc = (xy - uOrigin) / uSize * 2.0 - 1.0;
    vec3 ray = uRay * vec3(ndc, 1.0);
    if (uHostDepthMap.z > 0.5)
        rel = ray / splatfx_host_depth_blend(d); // the far plane: its point (inf beyond an infinite one: no point)
    else
        rel = ray + d * uDepthAxis;
    return !(any(isnan(rel)) || any(isinf(rel)));
}
const float kInvalidDistance = 3.0e38;
float hostDistance(vec2 xy, float d) {
    vec3 rel;
    return hostPoint(xy, d, rel) ? length(rel) : kInvalidDistance;
}
float hostTransmittance(vec2 xy, float d, out float dist) {
    vec3 rel;
    if (!hostPoint(xy, d, rel)) {
        dist = kInvalidDistance;
        return 0.0;
    }
    dist = length(rel);
    if (splatfx_fog_far > 0.0 && dist > splatfx_fog_far) return 0.0; // sec. 4.2: no evaluation
    return splatfx_fog_transmittance(vec3(0.0), rel);
}

#if MODE == 0 // per pixel, blended into the host colour
layout(location = 0) out vec4 oColor;
void main() {
    float dist;
    float f = hostTransmittance(gl_FragCoord.xy, texelFetch(uDepth, ivec2(gl_FragCoord.xy), 0).r, dist);
    oColor = vec4((1.0 - f) * splatfx_fog_colour, 1.0 - f); // premultiplied: dst' = (1 - f) C_fog + f dst
}
#elif MODE == 1 // reduced: (f, distance) at the full-resolution pixel under each fog texel's centre
uniform vec2 uFogSize;
layout(location = 0) out vec2 oFog;
void main() {
    vec2 xy = uOrigin + gl_FragCoord.xy / uFogSize * uSize;
    ivec2 pix = ivec2(floor(xy));
    float dist;
    float f = hostTransmittance(vec2(pix) + 0.5, texelFetch(uDepth, pix, 0).r, dist);
    oFog = vec2(f, dist);
}
#else // reduced: depth-aware (joint bilinear) upsampling, blended into the host colour
layout(binding = 1) uniform sampler2D uFog;
uniform vec2 uFogSize;
uniform float uThreshold;
layout(location = 0) out vec4 oColor;
void main() {
    float dist = hostDistance(gl_FragCoord.xy, texelFetch(uDepth, ivec2(gl_FragCoord.xy), 0).r);
    vec2 g = (gl_FragCoord.xy - uOrigin) / uSize * uFogSize - 0.5;
    ivec2 g0 = ivec2(floor(g));
    vec2 a = g - vec2(g0);
    ivec2 last = ivec2(uFogSize) - 1;
    float wsum = 0.0, fsum = 0.0, best = 3.4e38, fbest = 0.0;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            vec2 s = texelFetch(uFog, clamp(g0 + ivec2(i, j), ivec2(0), last), 0).rg;
            float w = (i == 0 ? 1.0 - a.x : a.x) * (j == 0 ? 1.0 - a.y : a.y);
            float diff = abs(s.y - dist);
            // Neighbours on the same surface (relative distance within the threshold) are interpolated;
            // when none is, the one nearest in distance is taken (no fog bleeding across silhouettes).
            if (diff <= uThreshold * dist) {
                wsum += w;
                fsum += w * s.x;
            }
            if (diff < best) {
                best = diff;
                fbest = s.x;
            }
        }
    float f = wsum > 1e-6 ? fsum / wsum : fbest;
    oColor = vec4((1.0 - f) * splatfx_fog_colour, 1.0 - f);
}
#endif
