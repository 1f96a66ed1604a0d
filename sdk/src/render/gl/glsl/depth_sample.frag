// A multisampled host depth as the single-sample depth the passes read
// (HostPass): sample uSample of each pixel, or (uSample < 0) the nearest of
// its uSamples samples (the smallest window depth; the largest under a
// reversed convention). Written as depth: the value is copied, not converted.
layout(binding = 0) uniform sampler2DMS uDepth;
uniform int uSample;
uniform int uSamples;
uniform int uReversed; // 1: the host's depth convention is reversed (near = 1)
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float d = texelFetch(uDepth, p, max(uSample, 0)).r;
    if (uSample < 0)
        for (int s = 1; s < uSamples; ++s) {
            float e = texelFetch(uDepth, p, s).r;
            d = uReversed != 0 ? max(d, e) : min(d, e);
        }
    gl_FragDepth = d;
}
