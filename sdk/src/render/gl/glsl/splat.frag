// The splat pass's fragment stage. Defines as splat.vert's, and CROSSFADE:
// a draw with no cross-faded splat skips the second fetch and the branch
// entirely (software rasterizers execute both sides of a per-fragment
// branch). With FOG every premultiplied layer becomes f c + (1 - f) alpha
// C_fog, alpha unchanged, f the transmittance from the eye to the fragment
// (docs/fog.md).
#if FOG
#include "fog.glsl"
#endif
#if CUT
#include "partial.glsl"
#endif
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
#if CUT && GENERAL
uniform vec3 uFogEye;
#endif
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
layout(binding = 1) uniform sampler2D uHostDepth; // the host's depth texture (read only; the depth test is off)
#include "host_depth.glsl"
#endif
#if GENERAL
#include "splat_plane.glsl"
#endif
#endif

void main() {
#if CUT && GENERAL
    vec3 dir;
    float tP;
    vec2 uvk;
    if (!splatfx_splat_plane(dir, tP, uvk)) discard;
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
    float zD = splatfx_host_view_depth(texelFetch(uHostDepth, ivec2(gl_FragCoord.xy), 0).r);
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
#elif CUT && GENERAL
    float f = splatfx_fog_transmittance(vec3(0.0), uEye + tP * dir - uFogEye); // the point this fragment met
#else
    float f = splatfx_fog_transmittance(vec3(0.0), vFogRel);
#endif
    c = f * c + (1.0 - f) * a * splatfx_fog_colour;
#endif
    oColor = vec4(c, a);
}
