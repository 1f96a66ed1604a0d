// Low-resolution depth: the farthest host depth in each scale x scale block.
layout(binding = 2) uniform sampler2D uHostDepth;
uniform ivec4 uHostRect; // x, y, width, height of the host depth region to read
uniform int uScale;
void main() {
    ivec2 base = ivec2(gl_FragCoord.xy) * uScale;
    float far = 0.0;
    for (int j = 0; j < uScale; ++j)
        for (int i = 0; i < uScale; ++i) {
            ivec2 p = min(base + ivec2(i, j), uHostRect.zw - 1);
            far = max(far, texelFetch(uHostDepth, uHostRect.xy + p, 0).r);
        }
    gl_FragDepth = far;
}
