// Low-resolution depth: the farthest host depth in each scale x scale block
// (the largest window depth, or the smallest with a reversed convention).
layout(binding = 2) uniform sampler2D uHostDepth;
uniform ivec4 uHostRect; // x, y, width, height of the host depth region to read
uniform int uScale;
uniform int uReversed;   // 1: the host's depth convention is reversed (far = 0)
void main() {
    ivec2 base = ivec2(gl_FragCoord.xy) * uScale;
    float far = uReversed != 0 ? 1.0 : 0.0;
    for (int j = 0; j < uScale; ++j)
        for (int i = 0; i < uScale; ++i) {
            ivec2 p = min(base + ivec2(i, j), uHostRect.zw - 1);
            float d = texelFetch(uHostDepth, uHostRect.xy + p, 0).r;
            far = uReversed != 0 ? min(far, d) : max(far, d);
        }
    gl_FragDepth = far;
}
