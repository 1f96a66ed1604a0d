// Fog of the host's opaque image (fog_pass.hpp).
#include "fog_pass.hpp"

#include <algorithm>
#include <cassert>
#include <string>

#include <epoxy/gl.h>

#include <glm/gtc/type_ptr.hpp>

#include "render/gl/context_check.hpp"
#include "render/gl/fog_state.hpp"
#include "render/gl/host_depth.hpp"
#include "render/gl/over_state.hpp"
#include "render/gl/saved_state.hpp"

namespace splatfx::gl::detail {

HostUnprojection hostUnprojection(const Camera& camera) {
    // In double from the projection's own (float) entries, in the camera's
    // depth convention. inverse(view) = [R^T | eye], so its rotation alone
    // takes view space to eye-relative world.
    const DepthConvention& dc = camera.depth;
    const glm::dmat4 invProj = glm::inverse(glm::dmat4(camera.proj));
    const glm::dmat3 rot(glm::inverse(glm::dmat4(camera.view)));
    auto viewPoint = [&](double x, double y, double z) {
        const glm::dvec4 h = invProj * glm::dvec4(x, y, z, 1.0);
        return glm::dvec3(h) / h.w;
    };
    HostUnprojection u;
    if (camera.perspective()) {
        // The pixel's ray at view depth 1 is affine in ndc.xy; the inverse view
        // depth is affine in the window depth d (1/z = (P22 - P23 z_ndc) / P32).
        // (The near plane's points: finite in every convention.)
        const double zNear = dc.nearNdc();
        auto unitDepth = [&](double x, double y) {
            const glm::dvec3 p = viewPoint(x, y, zNear);
            return p / -p.z;
        };
        const glm::dvec3 o = unitDepth(0.0, 0.0);
        u.ray = glm::mat3(rot * glm::dmat3(unitDepth(1.0, 0.0) - o, unitDepth(0.0, 1.0) - o, o));
    } else {
        const double z0 = dc.ndcFromWindow(0.0), z1 = dc.ndcFromWindow(1.0);
        const glm::dvec3 o = viewPoint(0.0, 0.0, z0);
        u.ray = glm::mat3(rot * glm::dmat3(viewPoint(1.0, 0.0, z0) - o, viewPoint(0.0, 1.0, z0) - o, o));
        u.depthAxis = glm::vec3(rot * (viewPoint(0.0, 0.0, z1) - o));
    }
    u.depthMap = hostDepthMap(camera); // 1 / view depth (perspective): the one unprojection of every pass
    return u;
}

FogPass::~FogPass() {
    if (!contextIsCurrent()) return;
    if (mVao) glDeleteVertexArrays(1, &mVao);
    if (mFbo) glDeleteFramebuffers(1, &mFbo);
    if (mTexture) glDeleteTextures(1, &mTexture);
    if (mSampler) glDeleteSamplers(1, &mSampler);
}

Status FogPass::build(const Fog& fog) {
    if (fog.glslKey() == mFogKey) return {}; // the same structure: the same programs
    auto glsl = fogGlsl(fog);
    if (!glsl) return makeError("fog pass: " + glsl.error());
    mPrograms->release(glsl::ProgramId::FogPass, [](const glsl::ProgramKey&) { return true; });
    mFogKey = 0;
    for (int m = 0; m < 3; ++m) {
        auto p = mPrograms->get({glsl::ProgramId::FogPass, {m}, fog.glslKey()}, {.fog = glsl->source});
        if (!p) return makeError(p.error());
        mModes[m] = *p;
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
    mFogKey = fog.glslKey();
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

    const HostUnprojection unproject = hostUnprojection(camera);
    const glm::dvec3 eye(camera.eye());
    if (!mFrameParams) mParams = fog.glslParameters(timeSec, eye);
    const std::span<const glm::vec4> params = mFrameParams ? std::span<const glm::vec4>(*mFrameParams) : mParams;

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

    auto common = [&](const ProgramLibrary::Program& p) {
        using namespace glsl::fog_pass;
        glUseProgram(p.id);
        glUniformMatrix3fv(p.uniform(Ray), 1, GL_FALSE, glm::value_ptr(unproject.ray));
        glUniform3fv(p.uniform(DepthAxis), 1, glm::value_ptr(unproject.depthAxis));
        glUniform3fv(p.uniform(HostDepthMap), 1, glm::value_ptr(unproject.depthMap));
        glUniform2f(p.uniform(Origin), float(target.x), float(target.y));
        glUniform2f(p.uniform(Size), float(target.width), float(target.height));
        setFogUniforms(p.id, {.params = p.uniform(FogParams), .colour = p.uniform(FogColour), .far = p.uniform(FogFar)}, fog, params);
        if (p.uniform(FogSize) >= 0) glUniform2f(p.uniform(FogSize), float(textureSize.x), float(textureSize.y));
        if (p.uniform(Threshold) >= 0) glUniform1f(p.uniform(Threshold), std::max(depthThreshold, 0.0f));
    };

    if (reduced) {
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, mFbo);
        glViewport(0, 0, textureSize.x, textureSize.y);
        glDisable(GL_BLEND);
        common(*mModes[1]);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    // The fog as a premultiplied layer ((1 - f) C_fog, 1 - f) over the host
    // image: dst' = (1 - f) C_fog + f dst, eq. 5, with no copy of the colour.
    setOverState(target.framebuffer, target, DepthTest::Off);
    if (reduced) {
        glBindTextureUnit(1, mTexture);
        common(*mModes[2]);
    } else {
        common(*mModes[0]);
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
    mFrameParams = &context.plan.fogParameters;
    const Status s = draw(*context.plan.fog, context.plan.timeSec, context.frame.camera(), context.plan.target);
    mFrameParams = nullptr;
    mDrawn = bool(s);
    if (!s) mError = s.error();
}

void FogPass::report(FrameRenderStats& stats) const {
    stats.fog.host = mDrawn;
    if (!mError.empty()) stats.fog.error = mError;
}

} // namespace splatfx::gl::detail
