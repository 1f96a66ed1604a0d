// Fog of the host's opaque image (fog_pass.hpp).
#include "fog_pass.hpp"

#include <algorithm>
#include <cassert>
#include <string>

#include <epoxy/gl.h>

#include <glm/gtc/type_ptr.hpp>

#include "context_check.hpp"
#include "saved_state.hpp"
#include "splatfx/gl/program.hpp"

namespace splatfx::gl::detail {
namespace {

// One triangle covering the viewport.
constexpr const char* kFullscreenVertex = R"(#version 450 core
void main() {
    vec2 p = vec2(float((gl_VertexID & 1) * 4 - 1), float((gl_VertexID & 2) * 2 - 1));
    gl_Position = vec4(p, 0.0, 1.0);
}
)";

// After "#version", the MODE define and fogGlsl()'s source.
constexpr const char* kFogFragment = R"(
layout(binding = 0) uniform sampler2D uDepth; // host depth, framebuffer-sized
uniform mat4 uInvRel;  // NDC -> world relative to the eye (inverse projection, then the view's rotation)
uniform vec2 uOrigin;  // viewport origin, framebuffer pixels
uniform vec2 uSize;    // viewport size, pixels

// The point behind window position xy at window depth d, relative to the eye.
// False for NaN or a depth outside [0, 1] (fully fogged, as Fog::transmittance does).
bool hostPoint(vec2 xy, float d, out vec3 rel) {
    rel = vec3(0.0);
    if (isnan(d) || !(d >= 0.0 && d <= 1.0)) return false;
    vec2 ndc = (xy - uOrigin) / uSize * 2.0 - 1.0;
    vec4 h = uInvRel * vec4(ndc, 2.0 * d - 1.0, 1.0); // d = 1 (sky): the far-plane point
    rel = h.xyz / h.w;
    return !(any(isnan(rel)) || any(isinf(rel)));
}
const float kInvalidDistance = 3.0e38;
float hostDistance(vec2 xy, float d) {
    vec3 rel;
    return hostPoint(xy, d, rel) ? length(rel) : kInvalidDistance;
}
float hostTransmittance(vec2 xy, float d, out float dist) {
    vec3 rel;
    if (!hostPoint(xy, d, rel)) {
        dist = kInvalidDistance;
        return 0.0;
    }
    dist = length(rel);
    if (splatfx_fog_far > 0.0 && dist > splatfx_fog_far) return 0.0; // sec. 4.2: no evaluation
    return splatfx_fog_transmittance(vec3(0.0), rel);
}

#if MODE == 0 // per pixel, blended into the host colour
layout(location = 0) out vec4 oColor;
void main() {
    float dist;
    float f = hostTransmittance(gl_FragCoord.xy, texelFetch(uDepth, ivec2(gl_FragCoord.xy), 0).r, dist);
    oColor = vec4((1.0 - f) * splatfx_fog_colour, 1.0 - f); // premultiplied: dst' = (1 - f) C_fog + f dst
}
#elif MODE == 1 // reduced: (f, distance) at the full-resolution pixel under each fog texel's centre
uniform vec2 uFogSize;
layout(location = 0) out vec2 oFog;
void main() {
    vec2 xy = uOrigin + gl_FragCoord.xy / uFogSize * uSize;
    ivec2 pix = ivec2(floor(xy));
    float dist;
    float f = hostTransmittance(vec2(pix) + 0.5, texelFetch(uDepth, pix, 0).r, dist);
    oFog = vec2(f, dist);
}
#else // reduced: depth-aware (joint bilinear) upsampling, blended into the host colour
layout(binding = 1) uniform sampler2D uFog;
uniform vec2 uFogSize;
uniform float uThreshold;
layout(location = 0) out vec4 oColor;
void main() {
    float dist = hostDistance(gl_FragCoord.xy, texelFetch(uDepth, ivec2(gl_FragCoord.xy), 0).r);
    vec2 g = (gl_FragCoord.xy - uOrigin) / uSize * uFogSize - 0.5;
    ivec2 g0 = ivec2(floor(g));
    vec2 a = g - vec2(g0);
    ivec2 last = ivec2(uFogSize) - 1;
    float wsum = 0.0, fsum = 0.0, best = 3.4e38, fbest = 0.0;
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            vec2 s = texelFetch(uFog, clamp(g0 + ivec2(i, j), ivec2(0), last), 0).rg;
            float w = (i == 0 ? 1.0 - a.x : a.x) * (j == 0 ? 1.0 - a.y : a.y);
            float diff = abs(s.y - dist);
            // Neighbours on the same surface (relative distance within the threshold) are interpolated;
            // when none is, the one nearest in distance is taken (no fog bleeding across silhouettes).
            if (diff <= uThreshold * dist) {
                wsum += w;
                fsum += w * s.x;
            }
            if (diff < best) {
                best = diff;
                fbest = s.x;
            }
        }
    float f = wsum > 1e-6 ? fsum / wsum : fbest;
    oColor = vec4((1.0 - f) * splatfx_fog_colour, 1.0 - f);
}
#endif
)";

} // namespace

FogPass::~FogPass() {
    if (!contextIsCurrent()) return;
    for (Prog* p : {&mFull, &mLow, &mUp})
        if (p->id) glDeleteProgram(p->id);
    if (mVao) glDeleteVertexArrays(1, &mVao);
    if (mFbo) glDeleteFramebuffers(1, &mFbo);
    if (mTexture) glDeleteTextures(1, &mTexture);
    if (mSampler) glDeleteSamplers(1, &mSampler);
}

Status FogPass::build(const Fog& fog) {
    auto glsl = fogGlsl(fog);
    if (!glsl) return makeError("fog pass: " + glsl.error());
    if (glsl->source == mSource) return {};
    for (Prog* p : {&mFull, &mLow, &mUp})
        if (p->id) glDeleteProgram(p->id), *p = {};
    mSource.clear();
    const char* modes[3] = {"#define MODE 0\n", "#define MODE 1\n", "#define MODE 2\n"};
    Prog* progs[3] = {&mFull, &mLow, &mUp};
    for (int m = 0; m < 3; ++m) {
        auto linked = linkProgram({kFullscreenVertex}, {"#version 450 core\n", modes[m], glsl->source.c_str(), kFogFragment}, "fog pass");
        if (!linked) return makeError(linked.error());
        Prog& p = *progs[m];
        p.id = *linked;
        p.uInvRel = glGetUniformLocation(p.id, "uInvRel");
        p.uOrigin = glGetUniformLocation(p.id, "uOrigin");
        p.uSize = glGetUniformLocation(p.id, "uSize");
        p.uParams = glGetUniformLocation(p.id, glsl->uniformName.c_str());
        p.uColour = glGetUniformLocation(p.id, "splatfx_fog_colour");
        p.uFar = glGetUniformLocation(p.id, "splatfx_fog_far");
        p.uFogSize = glGetUniformLocation(p.id, "uFogSize");
        p.uThreshold = glGetUniformLocation(p.id, "uThreshold");
    }
    if (!mVao) glCreateVertexArrays(1, &mVao);
    if (!mSampler) {
        // texelFetch on the host's depth: a sampler without mipmaps keeps the
        // texture complete whatever filter the host left on it.
        glCreateSamplers(1, &mSampler);
        glSamplerParameteri(mSampler, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glSamplerParameteri(mSampler, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glSamplerParameteri(mSampler, GL_TEXTURE_COMPARE_MODE, GL_NONE);
    }
    mSource = glsl->source;
    return {};
}

Status FogPass::draw(const Fog& fog, double timeSec, const Camera& camera, const PassTarget& target) {
    if (fog.empty()) return {};
    const glm::ivec2 textureSize = mAskedSize;
    const float depthThreshold = mDepthThreshold;
    if (Status s = build(fog); !s) return s;
    const bool reduced = textureSize.x > 0 && textureSize.y > 0;
    if (reduced && textureSize != mTextureSize) {
        if (mTexture) glDeleteTextures(1, &mTexture);
        if (!mFbo) glCreateFramebuffers(1, &mFbo);
        glCreateTextures(GL_TEXTURE_2D, 1, &mTexture);
        glTextureStorage2D(mTexture, 1, GL_RG32F, textureSize.x, textureSize.y); // distance needs float range
        glNamedFramebufferTexture(mFbo, GL_COLOR_ATTACHMENT0, mTexture, 0);
        mTextureSize = textureSize;
    }

    // NDC -> world relative to the eye, in double: inverse(view) = [R^T | eye],
    // so dropping its translation gives positions relative to the eye directly.
    const glm::dmat4 invView = glm::inverse(glm::dmat4(camera.view));
    const glm::dmat4 rot{glm::dmat3(invView)};
    const glm::mat4 invRel(rot * glm::inverse(glm::dmat4(camera.proj)));
    const glm::dvec3 eye(camera.eye());
    mParams = fog.glslParameters(timeSec, eye);
    const glm::dvec3 col = fog.desc().colour;

    SavedState saved;
    saved.save({.texture2DUnits = 2, .scissor = false});
    GLint hostSampler[2] = {0, 0};
    for (int u = 0; u < 2; ++u) {
        glActiveTexture(GL_TEXTURE0 + u);
        glGetIntegerv(GL_SAMPLER_BINDING, &hostSampler[u]);
    }
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glDisable(GL_CULL_FACE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glBindVertexArray(mVao);
    glBindTextureUnit(0, target.depthTexture);
    glBindSampler(0, mSampler);
    glBindSampler(1, mSampler);

    auto common = [&](const Prog& p) {
        glUseProgram(p.id);
        glUniformMatrix4fv(p.uInvRel, 1, GL_FALSE, glm::value_ptr(invRel));
        glUniform2f(p.uOrigin, float(target.x), float(target.y));
        glUniform2f(p.uSize, float(target.width), float(target.height));
        glUniform4fv(p.uParams, GLsizei(mParams.size()), glm::value_ptr(mParams[0]));
        glUniform3f(p.uColour, float(col.x), float(col.y), float(col.z));
        glUniform1f(p.uFar, float(fog.desc().farDistanceWorld));
        if (p.uFogSize >= 0) glUniform2f(p.uFogSize, float(textureSize.x), float(textureSize.y));
        if (p.uThreshold >= 0) glUniform1f(p.uThreshold, std::max(depthThreshold, 0.0f));
    };

    if (reduced) {
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, mFbo);
        glViewport(0, 0, textureSize.x, textureSize.y);
        glDisable(GL_BLEND);
        common(mLow);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target.framebuffer);
    glViewport(target.x, target.y, target.width, target.height);
    glEnable(GL_BLEND);
    // The fog as a premultiplied layer ((1 - f) C_fog, 1 - f) over the host
    // image: dst' = (1 - f) C_fog + f dst, eq. 5, with no copy of the colour.
    glBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glBlendEquationSeparate(GL_FUNC_ADD, GL_FUNC_ADD);
    if (reduced) {
        glBindTextureUnit(1, mTexture);
        common(mUp);
    } else {
        common(mFull);
    }
    glDrawArrays(GL_TRIANGLES, 0, 3);

    for (int u = 0; u < 2; ++u) glBindSampler(GLuint(u), GLuint(hostSampler[u]));
    saved.restore();
    return {};
}

// ---- As a pass of the frame (passes/pass.hpp) ----

void FogPass::prepare(const FramePlan&, const Frame&) {
    mDrawn = false;
    mError.clear();
}

void FogPass::execute(const PlanStep& step, StepContext& context) {
    assert(step.kind == StepKind::HostFog && context.plan.fog);
    (void)step;
    const Status s = draw(*context.plan.fog, context.plan.timeSec, context.frame.camera(), context.plan.target);
    mDrawn = bool(s);
    if (!s) mError = s.error();
}

void FogPass::report(FrameRenderStats& stats) const {
    stats.fog.host = mDrawn;
    if (!mError.empty()) stats.fog.error = mError;
}

} // namespace splatfx::gl::detail
