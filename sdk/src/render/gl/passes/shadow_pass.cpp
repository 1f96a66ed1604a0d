#include "shadow_pass.hpp"

#include <algorithm>

#include <epoxy/gl.h>
#include <glm/gtc/type_ptr.hpp>

namespace splatfx::gl::detail {

ShadowPass::~ShadowPass() {
    if (mTexture) glDeleteTextures(1, &mTexture);
}

bool ShadowPass::uploadTable(const FrameShadow& shadow) {
    const bool valid = shadow.valid && shadow.dims.x > 0 && shadow.dims.y > 0 && shadow.dims.z > 0 &&
                       shadow.depth.size() == std::size_t(shadow.dims.x) * std::size_t(shadow.dims.y) * std::size_t(shadow.dims.z);
    if (mUploadedOnce && shadow.version == mVersion) return false;
    const glm::ivec3 dims = valid ? shadow.dims : glm::ivec3(1);
    if (!mTexture || dims != mDims) {
        if (mTexture) glDeleteTextures(1, &mTexture);
        glCreateTextures(GL_TEXTURE_3D, 1, &mTexture);
        glTextureStorage3D(mTexture, 1, GL_R32F, dims.x, dims.y, dims.z);
        // As docs/lighting.md, "For a GL pass": linear filtering, clamped.
        glTextureParameteri(mTexture, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTextureParameteri(mTexture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) glTextureParameteri(mTexture, wrap, GL_CLAMP_TO_EDGE);
        mDims = dims;
    }
    const float zero = 0.0f;
    // Floats are 4-byte rows whatever the host's unpack alignment; keep the host's setting.
    GLint alignment = 4;
    glGetIntegerv(GL_UNPACK_ALIGNMENT, &alignment);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage3D(mTexture, 0, 0, 0, 0, dims.x, dims.y, dims.z, GL_RED, GL_FLOAT, valid ? shadow.depth.data() : &zero);
    glPixelStorei(GL_UNPACK_ALIGNMENT, alignment);
    mValid = valid;
    mWorldToTable = valid ? shadow.worldToTable : glm::mat4(1.0f);
    mLight = valid ? shadow.lightInTable : glm::vec4(0.0f, -1.0f, 0.0f, 0.0f);
    mVersion = shadow.version;
    mUploadedOnce = true;
    return true;
}

void ShadowPass::bind() {
    GLint active = 0;
    glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
    glActiveTexture(GLenum(GL_TEXTURE0 + mUnit));
    glGetIntegerv(GL_TEXTURE_BINDING_3D, &mSavedBinding);
    glActiveTexture(GLenum(active));
    glBindTextureUnit(GLuint(mUnit), mTexture);
}

void ShadowPass::unbind() {
    GLint active = 0;
    glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
    glActiveTexture(GLenum(GL_TEXTURE0 + mUnit));
    glBindTexture(GL_TEXTURE_3D, GLuint(mSavedBinding));
    glActiveTexture(GLenum(active));
}

ShadowBinding ShadowPass::binding() const {
    return {.valid = mValid, .textureUnit = mUnit, .texture = mTexture, .worldToTable = mWorldToTable, .lightInTable = mLight, .emittedLights = mEmitted};
}

void ShadowPass::execute(const PlanStep& step, StepContext& context) {
    if (step.kind == StepKind::UploadShadow) {
        if (uploadTable(context.frame.shadow())) ++mUploads;
        const std::vector<EmittedLight>& lights = context.frame.emittedLights();
        mEmitted.assign(lights.begin(), lights.begin() + std::min<std::ptrdiff_t>(std::ptrdiff_t(lights.size()), kMaxEmittedLights));
        bind();
    } else {
        unbind();
    }
}

void ShadowPass::report(FrameRenderStats& stats) const { stats.shadow.uploads = mUploads; }

} // namespace splatfx::gl::detail

namespace splatfx::gl {

void setShadowUniforms(unsigned program, const ShadowBinding& b) {
    glProgramUniform1i(program, glGetUniformLocation(program, "splatfx_shadowTable"), b.textureUnit);
    glProgramUniformMatrix4fv(program, glGetUniformLocation(program, "splatfx_worldToTable"), 1, GL_FALSE, glm::value_ptr(b.worldToTable));
    glProgramUniform4fv(program, glGetUniformLocation(program, "splatfx_shadowLight"), 1, glm::value_ptr(b.lightInTable));
    const int count = int(std::min<std::size_t>(b.emittedLights.size(), std::size_t(kMaxEmittedLights)));
    glm::vec4 position[kMaxEmittedLights]{};
    glm::vec3 intensity[kMaxEmittedLights]{}, plus[kMaxEmittedLights]{}, minus[kMaxEmittedLights]{};
    for (int i = 0; i < count; ++i) {
        position[i] = glm::vec4(b.emittedLights[i].position, b.emittedLights[i].radius);
        intensity[i] = b.emittedLights[i].intensity;
        plus[i] = b.emittedLights[i].escapePlus;
        minus[i] = b.emittedLights[i].escapeMinus;
    }
    glProgramUniform1i(program, glGetUniformLocation(program, "splatfx_emittedLightCount"), count);
    glProgramUniform4fv(program, glGetUniformLocation(program, "splatfx_emittedLightPosition"), kMaxEmittedLights, glm::value_ptr(position[0]));
    glProgramUniform3fv(program, glGetUniformLocation(program, "splatfx_emittedLightIntensity"), kMaxEmittedLights, glm::value_ptr(intensity[0]));
    glProgramUniform3fv(program, glGetUniformLocation(program, "splatfx_emittedLightEscapePlus"), kMaxEmittedLights, glm::value_ptr(plus[0]));
    glProgramUniform3fv(program, glGetUniformLocation(program, "splatfx_emittedLightEscapeMinus"), kMaxEmittedLights, glm::value_ptr(minus[0]));
}

} // namespace splatfx::gl
