// Fragment lists: the resolved image "over" the framebuffer.
layout(binding = 1) uniform sampler2D uResolved;
uniform ivec2 uOrigin;
layout(location = 0) out vec4 oColor;
void main() {
    vec4 c = texelFetch(uResolved, ivec2(gl_FragCoord.xy) - uOrigin, 0);
    if (c == vec4(0.0)) discard;
    oColor = c;
}
