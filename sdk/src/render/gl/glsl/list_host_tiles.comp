// Fragment lists, per 16 x 16 tile: the nearest host opaque depth, as the lists' key
// (the window depth, 1 - window depth under a reversed convention).
layout(local_size_x = 8, local_size_y = 1) in;
layout(binding = 3) uniform sampler2D uHostDepth;
layout(r32f, binding = 5) writeonly uniform image2D uHostTiles;
uniform ivec2 uSize, uTiles, uOrigin; // the lists' viewport size, the tiles, its origin in the depth texture
uniform int uReversed;
void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (t.x >= uTiles.x) return;
    ivec2 first = t * 16, last = min(first + 16, uSize);
    float host = 1.0;
    for (int y = first.y; y < last.y; ++y)
        for (int x = first.x; x < last.x; ++x) {
            float d = texelFetch(uHostDepth, ivec2(x, y) + uOrigin, 0).r;
            host = min(host, uReversed != 0 ? 1.0 - d : d);
        }
    imageStore(uHostTiles, t, vec4(max(host, 0.0)));
}
