// The splat pass's vertex stage (also the fragment lists' section programs).
// Per instance: one Splat (splats.hpp). Per vertex: a corner of the octagon
// (or square) circumscribing the unit disc, from gl_VertexID.
// Defines: FOG, FOG_PER_SPLAT (the transmittance to the splat's centre, once
// per vertex: RendererDesc::fogPerSplat), CUT, HOST_DEPTH, NEAR_CUT, GENERAL.
#if FOG
#include "fog.glsl"
#endif
#if CUT
#include "partial.glsl"
#endif
layout(location = 0) in vec4 aCenterDensity;
layout(location = 1) in vec4 aAxisUColor; // w: colorCoord (< 0: an HDR lit colour's scale)
layout(location = 2) in vec4 aAxisVRow;
layout(location = 3) in uvec2 aLayers;
layout(location = 4) in float aBlend;
layout(location = 5) in vec4 aColor; // RGBA8, normalized by the vertex fetch

uniform mat4 uViewProj;
uniform int uOctagon;
uniform float uCut;

#if CUT
// The depth cut (docs/architecture.md, "The depth cut").
uniform vec3 uEye;          // camera position (orthographic: any point on its axis)
uniform vec3 uForward;      // unit view direction
uniform float uNearZ;       // view depth of the near plane
uniform int uPersp;         // 1: perspective, 0: orthographic
uniform float uKernelRadius; // Footprint::radius(), kernel units
flat out float vScale;      // world length of one kernel unit along the ray
out vec3 vRel;              // the fragment's point on the splat plane, minus uEye
#if HOST_DEPTH && !GENERAL
#include "host_depth.glsl"
#endif
#if GENERAL
// x: clip z / w of the screen-covering polygon, just inside the near plane
// (in the host's depth convention); y: splat_plane.glsl's.
uniform vec2 uNdcZ;
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
    gl_Position = vec4(sign(corner), uNdcZ.x, 1.0);
    vCenter = c;
    vAxisU = au;
    vAxisV = av;
#else
    // A polygon in front of the near plane is moved behind it along the rays
    // (GL would clip it; its support may reach past the near plane). A
    // uniform scale about the eye (perspective) or a shift along forward
    // (orthographic) keeps its screen image and the interpolation of vTex and
    // vRel exactly (both are affine in position). With a host depth the
    // hardware depth test is off (the CPU drops splats wholly behind the
    // surface per tile; the shader cuts the rest), so nothing else moves.
    // With the host depth read, the far plane is a cut like the host's
    // surface (a fragment keeps its share in front of it: the sky's depth is
    // the far plane's), so a polygon reaching beyond it is moved in front of
    // it the same way (GL would clip the part beyond, whose kernels still
    // reach in front of the far plane), never past the near plane.
#if HOST_DEPTH
    float farZ = max(splatfx_host_view_depth(0.0), splatfx_host_view_depth(1.0)); // +inf without a far plane
    float maxZ = dot(c - uEye, uForward) + uCut * reach;
    float zFarDraw = farZ * 0.9999;
#endif
    if (uPersp != 0) {
        float k = max(1.0, zDraw / max(minZ, 1e-30));
#if HOST_DEPTH
        if (k == 1.0 && maxZ > zFarDraw) k = max(zFarDraw / maxZ, zDraw / max(minZ, 1e-30)); // never past the near plane
#endif
        if (k != 1.0) p = uEye + k * (p - uEye); // k = 1: the plain path's position, bit for bit
    } else {
        float d = max(0.0, zDraw - minZ);
#if HOST_DEPTH
        if (d == 0.0 && maxZ > zFarDraw) d = max(zFarDraw - maxZ, zDraw - minZ);
#endif
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
    // colorCoord < 0: an HDR lit colour's scale (splats.hpp, Splat); else exactly the RGBA8 colour.
    vColor = aAxisUColor.w < 0.0 ? -aAxisUColor.w * aColor.rgb : aColor.rgb;
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
