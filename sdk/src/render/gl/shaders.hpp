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
    vec2 uv = (uOctagon != 0 ? kOct[gl_VertexID] : kQuad[gl_VertexID]) * uCut;
    vec3 p = aCenterDensity.xyz + uv.x * aAxisUColor.xyz + uv.y * aAxisVRow.xyz;
    gl_Position = uViewProj * vec4(p, 1.0);
    // Layer images are stored top row first; +v is the splat's "up".
    vTex = vec2(0.5 + 0.5 * uv.x, 0.5 - 0.5 * uv.y);
    vDensity = aCenterDensity.w;
    vLayers = vec3(float(aLayers.x), float(aLayers.y), aBlend);
    vColor = aColor.rgb;
#if FOG
#if FOG_PER_SPLAT
    vFogF = splatfx_fog_transmittance(vec3(0.0), aCenterDensity.xyz - uFogEye);
#else
    vFogRel = p - uFogEye;
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

void main() {
    vec4 t = texture(uLayers, vec3(vTex, vLayers.x));
#if CROSSFADE
    if (vLayers.z > 0.0) t = mix(t, texture(uLayers, vec3(vTex, vLayers.y)), vLayers.z);
#endif
    // Opacity from optical depth: alpha = 1 - 2^(-density * detail).
    float a = 1.0 - exp2(-vDensity * t.a);
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
