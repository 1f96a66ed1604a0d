// Tetrahedra (TetraPass), pre-integrated. Defines: PERSPECTIVE, HAS_DEPTH, FOG, RGB.
layout(binding = 1) uniform sampler2D uHostDepth;
layout(binding = 2) uniform sampler3D uTable;
uniform vec3 uForward;      // unit view direction
#include "host_depth.glsl"
uniform vec3 uTexScale;     // (n-1)/n, (n-1)/n, (m-1)/m: texel centres at the table's samples
uniform vec3 uTexOffset;    // 0.5/n, 0.5/n, 0.5/m
uniform float uMaxLength;   // the table's maxLengthWorld
// A multisampled host's per-sample runs (uSampleRay = 1): each sample's ray
// from its own window position. The entry point interpolated at the sample
// (vRel, even `sample`-qualified) is not it on llvmpipe: up to 19/255 off the
// frames shifted onto the samples inside a cloud (tests/render/msaa_gl_test.cpp).
uniform int uSampleRay;
uniform mat4 uInvViewProjRel; // inverse of uViewProjRel
uniform vec4 uViewport;       // x, y, width, height
uniform float uNdcZ;          // ndc z of a finite point in front of the eye

// A point on this sample's ray, relative to the eye (gl_SamplePosition: the
// shader runs per sample).
vec3 sampleRayPoint() {
    vec2 ndc = (floor(gl_FragCoord.xy) + gl_SamplePosition - uViewport.xy) / uViewport.zw * 2.0 - 1.0;
    vec4 h = uInvViewProjRel * vec4(ndc, uNdcZ, 1.0);
    return h.xyz / h.w;
}
in vec3 vRel;
flat in vec4 vPlane[4];
flat in vec4 vScalar;
flat in vec4 vLength;
#if RGB
flat in vec4 vScalarG;
flat in vec4 vScalarB;
#endif
layout(location = 0) out vec4 oColor;

#if FOG
#include "fog.glsl"
// One medium with the clouds: the segment's premultiplied
// colour becomes f c + (1 - f) alpha C_fog (alpha unchanged), as every splat
// fragment does, f = the fog's transmittance from the eye (the origin of the
// eye-relative positions here) to one point of the segment. The point is the
// segment's opacity centroid for a homogeneous segment of the same alpha:
// with tau = -ln(1 - alpha), w = 1/tau - 1/(e^tau - 1) of the way in (1/2 for
// thin segments, the entry for opaque ones), so the error is second order in
// the fog's optical depth across the segment (docs/fog.md, "Tetrahedra").
vec4 fogSegment(vec4 c, vec3 pf, vec3 pb) {
    float a = clamp(c.a, 0.0, 1.0);
    float tau = -log(max(1.0 - a, 1.0e-30));
    float w = tau < 1.0e-2 ? 0.5 - tau / 12.0 : 1.0 / tau - 1.0 / (exp(min(tau, 80.0)) - 1.0);
    float f = splatfx_fog_transmittance(vec3(0.0), mix(pf, pb, w));
    return vec4(f * c.rgb + (1.0 - f) * c.a * splatfx_fog_colour, c.a);
}
#define FOGGED(c) fogSegment(c, pf, pb)
#else
#define FOGGED(c) (c)
#endif

vec4 table(float sf, float sb, float l) {
    return texture(uTable, vec3(clamp(sf, 0.0, 1.0), clamp(sb, 0.0, 1.0), l / uMaxLength) * uTexScale + uTexOffset);
}

#if RGB
// An RGB source per vertex (kappa_c(s_c) = A_c + B_c s_c, constant
// extinction): channel c is the table's channel c at that channel's scalars;
// alpha does not depend on the scalars.
vec4 segment(vec3 sf, vec3 sb, float l) {
    return vec4(table(sf.r, sb.r, l).r, table(sf.g, sb.g, l).g, table(sf.b, sb.b, l).ba);
}
#else
vec4 segment(float sf, float sb, float l) { return table(sf, sb, l); }
#endif

void main() {
    // Compiled per camera kind and host depth (#defines), so no lane pays for
    // a branch it does not take (llvmpipe runs both sides of divergent code).
#if PERSPECTIVE
    // The fragment lies on the entry face: the ray from the eye enters here.
    float tIn = length(vRel);
    vec3 d = vRel / tIn, o = vec3(0.0);
    float tOut = 3.0e38;
    if (uSampleRay != 0) {
        // Not on the face at the sample: the entering planes bound tIn too.
        d = normalize(sampleRayPoint());
        tIn = 0.0;
        for (int i = 0; i < 4; ++i) {
            float s = dot(vPlane[i].xyz, d);
            if (s > 0.0) tIn = max(tIn, -vPlane[i].w / s);
        }
    }
    for (int i = 0; i < 4; ++i) {
        // lambda_i(t) = w + s t >= 0 inside (o = 0): only the leaving planes bound tOut.
        float s = dot(vPlane[i].xyz, d);
        if (s < 0.0) tOut = min(tOut, -vPlane[i].w / s);
    }
#else
    vec3 d = uForward, rel = uSampleRay != 0 ? sampleRayPoint() : vRel;
    vec3 o = rel - d * dot(rel, d); // o on the plane through the eye
    float tIn = -3.0e38, tOut = 3.0e38;
    for (int i = 0; i < 4; ++i) {
        float a = dot(vPlane[i].xyz, o) + vPlane[i].w, s = dot(vPlane[i].xyz, d);
        if (s > 0.0) tIn = max(tIn, -a / s);
        else if (s < 0.0) tOut = min(tOut, -a / s);
    }
#endif
#if HAS_DEPTH
    // The ray ends at the host's surface: the segment is cut there, and the
    // scalars below are interpolated at the cut (exact inside a tetrahedron).
    // View depth from the stored depth (host_depth.glsl); along the ray t = depth / dot(d, forward).
    float zView = splatfx_host_view_depth(texelFetch(uHostDepth, ivec2(gl_FragCoord.xy), 0).r);
#if PERSPECTIVE
    tOut = min(tOut, zView / dot(d, uForward));
#else
    tOut = min(tOut, zView);
#endif
#endif
    if (!(tOut > tIn)) discard;
    vec4 S = vScalar, M = vLength;
    vec3 pf = o + tIn * d, pb = o + tOut * d;
#if RGB
    vec3 sf = vec3(dot(S.xyz, pf) + S.w, dot(vScalarG.xyz, pf) + vScalarG.w, dot(vScalarB.xyz, pf) + vScalarB.w);
    vec3 sb = vec3(dot(S.xyz, pb) + S.w, dot(vScalarG.xyz, pb) + vScalarG.w, dot(vScalarB.xyz, pb) + vScalarB.w);
#else
    float sf = dot(S.xyz, pf) + S.w, sb = dot(S.xyz, pb) + S.w;
#endif
    float mf = dot(M.xyz, pf) + M.w, mb = dot(M.xyz, pb) + M.w;
    // The table assumes a constant length scale along the segment (eq. 9):
    // the mean of the ends, exact for constant m (docs/volume.md).
    float l = (tOut - tIn) * max(0.5 * (mf + mb), 0.0);
    if (l <= uMaxLength) {
        oColor = FOGGED(segment(sf, sb, l));
        return;
    }
    // Longer than the table: equal pieces (the scalar is linear, so each is
    // a segment), front to back, as PreIntegrationTable::lookup does.
    int n = min(int(ceil(l / uMaxLength)), 256);
    float piece = l / float(n);
    vec4 acc = vec4(0.0);
    for (int k = 0; k < n && acc.a < 0.99999; ++k) {
        vec4 c = segment(mix(sf, sb, float(k) / float(n)), mix(sf, sb, float(k + 1) / float(n)), piece);
        acc += (1.0 - acc.a) * c;
    }
    oColor = FOGGED(acc);
}
