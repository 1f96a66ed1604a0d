// Depth-aware upsampling of the premultiplied low-resolution image (ScaledRenderer).
layout(binding = 0) uniform sampler2D uLowColor;
layout(binding = 1) uniform sampler2D uLowDepth;
layout(binding = 2) uniform sampler2D uHostDepth;
uniform ivec4 uHostRect;
uniform ivec2 uViewportOrigin; // the host viewport's corner in window pixels
uniform int uScale;
uniform int uUseDepth;
uniform float uThreshold;
#include "host_depth.glsl"
layout(location = 0) out vec4 oColor;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy) - uViewportOrigin;
    ivec2 lowSize = textureSize(uLowColor, 0);
    // Low-resolution texel centres sit at (i + 0.5) * scale full-resolution pixels.
    vec2 q = (vec2(p) + 0.5) / float(uScale) - 0.5;
    ivec2 b = ivec2(floor(q));
    vec2 f = q - vec2(b);
    ivec2 t[4] = ivec2[4](b, b + ivec2(1, 0), b + ivec2(0, 1), b + ivec2(1, 1));
    float w[4] = float[4]((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * f.y);
    vec4 c[4];
    for (int k = 0; k < 4; ++k) {
        t[k] = clamp(t[k], ivec2(0), lowSize - 1);
        c[k] = texelFetch(uLowColor, t[k], 0);
    }
    // Nothing drawn near this pixel: blending zero would leave the host unchanged.
    if (max(max(c[0].a, c[1].a), max(c[2].a, c[3].a)) <= 0.0) discard;
    vec4 bilinear = c[0] * w[0] + c[1] * w[1] + c[2] * w[2] + c[3] * w[3];
    if (uUseDepth == 0) {
        oColor = bilinear;
        return;
    }
    float z = splatfx_host_view_depth(texelFetch(uHostDepth, uHostRect.xy + p, 0).r);
    // The taps on this pixel's surface (relative view depth within the
    // threshold) are interpolated, their weights renormalized; all four: the
    // plain bilinear. None: the one nearest in depth. Which taps count does
    // not hinge on the depths' last bits (the surfaces differ by far more
    // than the threshold), so the depth buffer's format and convention do
    // not change the picture; a choice by smallest difference alone did.
    vec4 acc = vec4(0.0);
    float wsum = 0.0, best = 1e30;
    int nearest = 0, same = 0;
    for (int k = 0; k < 4; ++k) {
        float zk = splatfx_host_view_depth(texelFetch(uLowDepth, t[k], 0).r);
        float dz = zk == z ? 0.0 : abs(zk - z); // the sky under an infinite far plane: inf on both
        if (dz <= uThreshold * z) {
            acc += w[k] * c[k];
            wsum += w[k];
            ++same;
        }
        if (dz < best) { best = dz; nearest = k; }
    }
    oColor = same == 4 ? bilinear : wsum > 0.0 ? acc / wsum : c[nearest];
}
