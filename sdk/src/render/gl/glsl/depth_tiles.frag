// Per 16 x 16 tile of the target (Renderer's kCutTile), the nearest and
// farthest host view depth (RG32F), read back so the CPU can give the cut
// program only to the splats whose support meets the surface.
layout(binding = 1) uniform sampler2D uHostDepth;
#include "host_depth.glsl"
uniform ivec4 uTarget;     // x, y, width, height of the target in the depth texture
layout(location = 0) out vec2 oRange;
void main() {
    ivec2 first = ivec2(gl_FragCoord.xy) * 16;
    ivec2 last = min(first + 16, uTarget.zw);
    float lo = 3.4e38, hi = 0.0;
    for (int y = first.y; y < last.y; ++y)
        for (int x = first.x; x < last.x; ++x) {
            float z = splatfx_host_view_depth(texelFetch(uHostDepth, ivec2(x, y) + uTarget.xy, 0).r);
            lo = min(lo, z);
            hi = max(hi, z);
        }
    oRange = vec2(lo, hi);
}
