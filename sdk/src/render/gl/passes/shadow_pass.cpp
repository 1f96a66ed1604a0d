#include "shadow_pass.hpp"

#include <algorithm>
#include <array>
#include <string>

#include <epoxy/gl.h>
#include <glm/gtc/type_ptr.hpp>

namespace splatfx::gl::detail {

ShadowPass::~ShadowPass() {
    for (Slot& slot : mSlots)
        if (slot.texture) glDeleteTextures(1, &slot.texture);
}

bool ShadowPass::uploadTable(std::size_t k, const FrameShadow& shadow) {
    Slot& slot = mSlots[k];
    const bool valid = shadow.valid && shadow.dims.x > 0 && shadow.dims.y > 0 && shadow.dims.z > 0 &&
                       shadow.depth.size() == std::size_t(shadow.dims.x) * std::size_t(shadow.dims.y) * std::size_t(shadow.dims.z);
    if (slot.uploadedOnce && shadow.version == slot.version) return false;
    const bool wasValid = slot.valid;
    const glm::ivec3 dims = valid ? shadow.dims : glm::ivec3(1);
    if (!slot.texture || dims != slot.dims) {
        if (slot.texture) glDeleteTextures(1, &slot.texture);
        glCreateTextures(GL_TEXTURE_3D, 1, &slot.texture);
        glTextureStorage3D(slot.texture, 1, GL_R32F, dims.x, dims.y, dims.z);
        // As docs/lighting.md, "For a GL pass": linear filtering, clamped.
        glTextureParameteri(slot.texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTextureParameteri(slot.texture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) glTextureParameteri(slot.texture, wrap, GL_CLAMP_TO_EDGE);
        slot.dims = dims;
    }
    const float zero = 0.0f;
    // Floats are 4-byte rows whatever the host's unpack alignment; keep the host's setting.
    GLint alignment = 4;
    glGetIntegerv(GL_UNPACK_ALIGNMENT, &alignment);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage3D(slot.texture, 0, 0, 0, 0, dims.x, dims.y, dims.z, GL_RED, GL_FLOAT, valid ? shadow.depth.data() : &zero);
    glPixelStorei(GL_UNPACK_ALIGNMENT, alignment);
    slot.valid = valid;
    slot.light = valid ? shadow.light : -1;
    slot.worldToTable = valid ? shadow.worldToTable : glm::mat4(1.0f);
    slot.lightInTable = valid ? shadow.lightInTable : glm::vec4(0.0f, -1.0f, 0.0f, 0.0f);
    slot.version = shadow.version;
    slot.uploadedOnce = true;
    return valid || wasValid; // a placeholder for a slot never filled is not a table
}

void ShadowPass::bind() {
    GLint active = 0;
    glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
    for (std::size_t k = 0; k < mSlots.size(); ++k) {
        glActiveTexture(GLenum(GL_TEXTURE0 + mUnit - int(k)));
        glGetIntegerv(GL_TEXTURE_BINDING_3D, &mSlots[k].savedBinding);
    }
    glActiveTexture(GLenum(active));
    for (std::size_t k = 0; k < mSlots.size(); ++k) glBindTextureUnit(GLuint(mUnit - int(k)), mSlots[k].texture);
}

void ShadowPass::unbind() {
    GLint active = 0;
    glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
    for (std::size_t k = 0; k < mSlots.size(); ++k) {
        glActiveTexture(GLenum(GL_TEXTURE0 + mUnit - int(k)));
        glBindTexture(GL_TEXTURE_3D, GLuint(mSlots[k].savedBinding));
    }
    glActiveTexture(GLenum(active));
}

ShadowBinding ShadowPass::binding() const {
    const Slot& s0 = mSlots[0];
    ShadowBinding b{.valid = s0.valid,
                    .textureUnit = mUnit,
                    .texture = s0.texture,
                    .worldToTable = s0.worldToTable,
                    .lightInTable = s0.lightInTable,
                    .light = s0.light,
                    .emittedLights = mEmitted,
                    .emittedGrid = mEmittedGrid};
    for (std::size_t k = 1; k < mSlots.size(); ++k) {
        const Slot& s = mSlots[k];
        b.slots[k - 1] = {.valid = s.valid, .light = s.light, .textureUnit = mUnit - int(k), .texture = s.texture, .worldToTable = s.worldToTable, .lightInTable = s.lightInTable};
    }
    return b;
}

void ShadowPass::execute(const PlanStep& step, StepContext& context) {
    if (step.kind == StepKind::UploadShadow) {
        for (std::size_t k = 0; k < mSlots.size(); ++k)
            if (uploadTable(k, context.frame.shadows()[k])) ++mUploads;
        const std::vector<EmittedLight>& lights = context.frame.emittedLights();
        mEmitted.assign(lights.begin(), lights.begin() + std::min<std::ptrdiff_t>(std::ptrdiff_t(lights.size()), kMaxEmittedLights));
        mEmittedGrid = context.frame.emittedGrid();
        bind();
    } else {
        unbind();
    }
}

void ShadowPass::report(FrameRenderStats& stats) const {
    stats.shadow.uploads = mUploads;
    stats.shadow.tables = 0;
    for (const Slot& s : mSlots) stats.shadow.tables += s.valid ? 1 : 0;
}

} // namespace splatfx::gl::detail

namespace splatfx::gl {

void setShadowUniforms(unsigned program, const ShadowBinding& b) {
    glProgramUniform1i(program, glGetUniformLocation(program, "splatfx_shadowTable"), b.textureUnit);
    glProgramUniformMatrix4fv(program, glGetUniformLocation(program, "splatfx_worldToTable"), 1, GL_FALSE, glm::value_ptr(b.worldToTable));
    glProgramUniform4fv(program, glGetUniformLocation(program, "splatfx_shadowLight"), 1, glm::value_ptr(b.lightInTable));
    int index[kMaxShadowLights] = {b.valid ? b.light : -1};
    for (std::size_t k = 1; k < std::size_t(kMaxShadowLights); ++k) {
        const ShadowSlotBinding& s = b.slots[k - 1];
        const std::string n = std::to_string(k);
        glProgramUniform1i(program, glGetUniformLocation(program, ("splatfx_shadowTable" + n).c_str()), s.textureUnit);
        glProgramUniformMatrix4fv(program, glGetUniformLocation(program, ("splatfx_worldToTable" + n).c_str()), 1, GL_FALSE, glm::value_ptr(s.worldToTable));
        glProgramUniform4fv(program, glGetUniformLocation(program, ("splatfx_shadowLight" + n).c_str()), 1, glm::value_ptr(s.lightInTable));
        index[k] = s.valid ? s.light : -1;
    }
    glProgramUniform1iv(program, glGetUniformLocation(program, "splatfx_shadowLightIndex"), kMaxShadowLights, index);
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
    const EmittedGrid& g = b.emittedGrid;
    const std::size_t nodes = std::size_t(std::max(g.dims.x, 0)) * std::size_t(std::max(g.dims.y, 0)) * std::size_t(std::max(g.dims.z, 0));
    const bool grid = nodes > 0 && nodes <= std::size_t(kMaxEmittedGridNodes) && g.nodes.size() == nodes;
    std::array<float, kMaxEmittedGridNodes * 18> packed{};
    for (std::size_t i = 0; grid && i < nodes; ++i)
        for (std::size_t k = 0; k < 6; ++k)
            for (int c = 0; c < 3; ++c) packed[(i * 6 + k) * 3 + std::size_t(c)] = g.nodes[i][k][c];
    const glm::ivec3 dims = grid ? g.dims : glm::ivec3(0);
    glProgramUniform3iv(program, glGetUniformLocation(program, "splatfx_emittedGridDims"), 1, glm::value_ptr(dims));
    glProgramUniform3fv(program, glGetUniformLocation(program, "splatfx_emittedGridMin"), 1, glm::value_ptr(g.boxMin));
    glProgramUniform3fv(program, glGetUniformLocation(program, "splatfx_emittedGridMax"), 1, glm::value_ptr(g.boxMax));
    glProgramUniform3fv(program, glGetUniformLocation(program, "splatfx_emittedGridCentre"), 1, glm::value_ptr(g.centre));
    glProgramUniform4fv(program, glGetUniformLocation(program, "splatfx_emittedGrid"), kMaxEmittedGridNodes * 18 / 4, packed.data());
}

} // namespace splatfx::gl
