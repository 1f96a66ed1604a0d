// GLSL for the splat pass (private to the GL backend).
#pragma once

namespace splatfx::gl::detail {

// Per instance: one Splat (see splats.hpp). Per vertex: a corner of the
// octagon (or square) circumscribing the unit disc, from gl_VertexID.
// Compiled after "#version 450 core\n#define FOG 0|1\n#define FOG_PER_SPLAT 0|1\n" (and,
// with FOG, fogGlsl()'s source): the fog variant (issue 14) passes the world
// position relative to the eye to the fragment, or the transmittance to the
// splat's centre, evaluated here once per vertex (RendererDesc::fogPerSplat).
inline constexpr const char* kSplatVertex = R"(
layout(location = 0) in vec4 aCenterDensity;
layout(location = 1) in vec4 aAxisUColor;
layout(location = 2) in vec4 aAxisVRow;
layout(location = 3) in uvec2 aLayers;
layout(location = 4) in float aBlend;
layout(location = 5) in vec4 aColor; // RGBA8, normalized by the vertex fetch

uniform mat4 uViewProj;
uniform int uOctagon;
uniform float uCut;

#if CUT
// The depth cut (issue 15, docs/architecture.md "The depth cut"); compiled
// after partialGlsl() (splatfx_ray_scale, splatfx_partial_before).
uniform vec3 uEye;          // camera position (orthographic: any point on its axis)
uniform vec3 uForward;      // unit view direction
uniform float uNearZ;       // view depth of the near plane
uniform int uPersp;         // 1: perspective, 0: orthographic
uniform float uKernelRadius; // Footprint::radius(), kernel units
flat out float vScale;      // world length of one kernel unit along the ray
out vec3 vRel;              // the fragment's point on the splat plane, minus uEye
#if GENERAL
flat out vec3 vCenter;
flat out vec3 vAxisU;
flat out vec3 vAxisV;
#endif
#endif

out vec2 vTex;
flat out float vDensity;
flat out vec3 vLayers;
flat out vec3 vColor;
#if FOG
uniform vec3 uFogEye;
#if FOG_PER_SPLAT
flat out float vFogF; // transmittance to the splat's centre (RendererDesc::fogPerSplat)
#else
out vec3 vFogRel;
#endif
#endif

// Octagon circumscribing the unit circle, in triangle-strip order.
const vec2 kOct[8] = vec2[8](vec2(1.0, -0.41421356), vec2(1.0, 0.41421356), vec2(0.41421356, -1.0), vec2(0.41421356, 1.0),
                             vec2(-0.41421356, -1.0), vec2(-0.41421356, 1.0), vec2(-1.0, -0.41421356), vec2(-1.0, 0.41421356));
const vec2 kQuad[4] = vec2[4](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0), vec2(1.0, 1.0));

void main() {
    vec2 corner = uOctagon != 0 ? kOct[gl_VertexID] : kQuad[gl_VertexID];
    vec2 uv = corner * uCut;
    vec3 p = aCenterDensity.xyz + uv.x * aAxisUColor.xyz + uv.y * aAxisVRow.xyz;
#if !CUT
    gl_Position = uViewProj * vec4(p, 1.0);
#else
    vec3 c = aCenterDensity.xyz, au = aAxisUColor.xyz, av = aAxisVRow.xyz;
    float l = splatfx_ray_scale(au, av, aColor.a);
    vScale = l;
    vRel = p - uEye; // interpolated on the drawn polygon, which is an affine image of this one
    // Nearest view depth of the drawn polygon (the same for every vertex).
    float a = abs(dot(au, uForward)), b = abs(dot(av, uForward));
    float reach = uOctagon != 0 ? max(a + 0.41421356 * b, 0.41421356 * a + b) : a + b;
    float minZ = dot(c - uEye, uForward) - uCut * reach;
    float zDraw = uNearZ * 1.0001 + 1e-7;
#if GENERAL
    // The polygon crosses (or nearly) the eye plane: cover the screen at the
    // near plane; the fragment intersects its ray with the splat plane.
    gl_Position = vec4(sign(corner), -1.0 + 1e-5, 1.0);
    vCenter = c;
    vAxisU = au;
    vAxisV = av;
#else
    // Draw the polygon moved along the rays so that (with a host depth) the
    // hardware depth test rejects only fragments whose whole support on the
    // ray lies behind the surface (z >= zp - R l), and never in front of the
    // near plane. A uniform scale about the eye (perspective) or a shift
    // along forward (orthographic) keeps its screen image and the
    // interpolation of vTex and vRel exactly (both are affine in position).
    if (uPersp != 0) {
        float k = 1.0;
#if HOST_DEPTH
        k = 1.0 - uKernelRadius * l / max(minZ, 1e-30);
#endif
        k = max(k, zDraw / max(minZ, 1e-30));
        if (k != 1.0) p = uEye + k * (p - uEye); // k = 1: the plain path's position, bit for bit
    } else {
        float d = 0.0;
#if HOST_DEPTH
        d = -uKernelRadius * l;
#endif
        d = max(d, zDraw - minZ);
        if (d != 0.0) p += d * uForward;
    }
    gl_Position = uViewProj * vec4(p, 1.0);
    // Crossing the eye plane: the general variant draws it (the CPU routes
    // such splats there with margin); here it is dropped.
    if (uPersp != 0 && minZ < 0.25 * uNearZ) gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
#endif
#endif
    // Layer images are stored top row first; +v is the splat's "up".
    vTex = vec2(0.5 + 0.5 * uv.x, 0.5 - 0.5 * uv.y);
    vDensity = aCenterDensity.w;
    vLayers = vec3(float(aLayers.x), float(aLayers.y), aBlend);
    vColor = aColor.rgb;
#if FOG
#if FOG_PER_SPLAT
    vFogF = splatfx_fog_transmittance(vec3(0.0), aCenterDensity.xyz - uFogEye);
#else
#if CUT
    vFogRel = vRel + (uEye - uFogEye); // the splat plane's point, not the drawn one
#else
    vFogRel = p - uFogEye;
#endif
#endif
#endif
}
)";

// Compiled twice, after "#version 450 core\n#define CROSSFADE 0|1\n#define FOG 0\n": a draw
// with no cross-faded splat skips the second fetch and the branch entirely
// (software rasterizers execute both sides of a per-fragment branch).
// With a fog, twice more with FOG 1 and fogGlsl()'s source before this one:
// every premultiplied layer becomes f c + (1 - f) alpha C_fog, alpha
// unchanged, f the transmittance from the eye to the fragment (docs/fog.md).
inline constexpr const char* kSplatFragment = R"(
layout(binding = 0) uniform sampler2DArray uLayers;
in vec2 vTex;
flat in float vDensity;
flat in vec3 vLayers;
flat in vec3 vColor;
#if FOG
#if FOG_PER_SPLAT
flat in float vFogF;
#else
in vec3 vFogRel;
#endif
#endif
layout(location = 0) out vec4 oColor;
#if CUT
uniform vec3 uForward;
uniform float uNearZ;
uniform int uPersp;
uniform float uKernelRadius;
flat in float vScale;
in vec3 vRel;
#if HOST_DEPTH
layout(binding = 1) uniform sampler2D uHostDepth;
uniform vec4 uDepthToView; // inverse projection's (z, w) rows at (z, w) columns
#endif
#if GENERAL
uniform mat4 uInvViewProj;
uniform vec4 uViewport; // x, y, width, height
uniform vec3 uEye;
uniform float uCut;
uniform int uOctagon;
flat in vec3 vCenter;
flat in vec3 vAxisU;
flat in vec3 vAxisV;
#endif
#endif

void main() {
#if CUT && GENERAL
    // The pixel ray from the eye, met by the splat's plane (the line, so a
    // plane just behind the eye still gives its tail in front: continuous).
    vec2 ndc = (gl_FragCoord.xy - uViewport.xy) / uViewport.zw * 2.0 - 1.0;
    vec4 farPoint = uInvViewProj * vec4(ndc, 1.0, 1.0);
    vec3 dir = normalize(farPoint.xyz / farPoint.w - uEye);
    vec3 n = cross(vAxisU, vAxisV);
    float dn = dot(dir, n);
    if (abs(dn) <= 1e-6 * length(n)) discard; // edge-on
    float tP = dot(vCenter - uEye, n) / dn;
    vec3 g = uEye + tP * dir - vCenter;
    float g00 = dot(vAxisU, vAxisU), g01 = dot(vAxisU, vAxisV), g11 = dot(vAxisV, vAxisV);
    float b0 = dot(vAxisU, g), b1 = dot(vAxisV, g);
    vec2 uvk = vec2(g11 * b0 - g01 * b1, g00 * b1 - g01 * b0) / (g00 * g11 - g01 * g01);
    if (max(abs(uvk.x), abs(uvk.y)) > uCut || (uOctagon != 0 && abs(uvk.x) + abs(uvk.y) > uCut * 1.41421356)) discard;
    vec2 tex = vec2(0.5 + 0.5 * uvk.x, 0.5 - 0.5 * uvk.y);
    float invCos = 1.0 / dot(dir, uForward);
#else
    vec2 tex = vTex;
#if CUT
    vec2 uvk = vec2(2.0 * vTex.x - 1.0, 1.0 - 2.0 * vTex.y);
    float zP = dot(vRel, uForward);
    float tP = uPersp != 0 ? length(vRel) : zP;  // along the ray from the eye (ortho: from its plane)
    float invCos = uPersp != 0 ? tP / zP : 1.0;  // along-ray length per unit of view depth
#endif
#endif
    vec4 t = texture(uLayers, vec3(tex, vLayers.x));
#if CROSSFADE
    if (vLayers.z > 0.0) t = mix(t, texture(uLayers, vec3(tex, vLayers.y)), vLayers.z);
#endif
#if CUT
    // The share of the kernel's line integral between the near plane and the
    // host's surface on this ray: s in kernel units from the splat plane.
    float r = uKernelRadius * length(uvk);
    float invL = 1.0 / vScale;
    float share = 1.0;
#if NEAR_CUT
    share -= splatfx_partial_before(r, (uNearZ * invCos - tP) * invL);
#endif
#if HOST_DEPTH
    float nz = texelFetch(uHostDepth, ivec2(gl_FragCoord.xy), 0).r * 2.0 - 1.0;
    float zD = abs((uDepthToView.x * nz + uDepthToView.y) / (uDepthToView.z * nz + uDepthToView.w));
    share -= 1.0 - splatfx_partial_before(r, (zD * invCos - tP) * invL);
#endif
    // Opacity from the optical depth in front: alpha = 1 - 2^(-density * detail * share).
    float a = 1.0 - exp2(-vDensity * t.a * max(share, 0.0));
#else
    // Opacity from optical depth: alpha = 1 - 2^(-density * detail).
    float a = 1.0 - exp2(-vDensity * t.a);
#endif
    vec3 c = vColor * t.rgb * a;
#if FOG
#if FOG_PER_SPLAT
    float f = vFogF;
#else
    float f = splatfx_fog_transmittance(vec3(0.0), vFogRel);
#endif
    c = f * c + (1.0 - f) * a * splatfx_fog_colour;
#endif
    oColor = vec4(c, a);
}
)";

} // namespace splatfx::gl::detail
