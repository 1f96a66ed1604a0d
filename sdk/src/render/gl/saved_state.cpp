#include "saved_state.hpp"

#include <algorithm>

namespace splatfx::gl::detail {

void SavedState::save(const SavedStateDesc& desc) {
    mDesc = desc;
    mDesc.texture2DUnits = std::clamp(desc.texture2DUnits, 0, kMaxTexture2DUnits);
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &mDrawFbo);
    glGetIntegerv(GL_CURRENT_PROGRAM, &mProgram);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &mVao);
    glGetIntegerv(GL_ARRAY_BUFFER_BINDING, &mArrayBuffer);
    glGetIntegerv(GL_ACTIVE_TEXTURE, &mActiveTexture);
    glGetIntegerv(GL_VIEWPORT, mViewport);
    for (int u = 0; u < mDesc.texture2DUnits; ++u) {
        glActiveTexture(GLenum(GL_TEXTURE0 + u));
        glGetIntegerv(GL_TEXTURE_BINDING_2D, &mTex2D[u]);
    }
    glActiveTexture(GL_TEXTURE0);
    glGetIntegerv(GL_TEXTURE_BINDING_2D_ARRAY, &mTexArray0); // restore() sets the active unit back
    mBlend = glIsEnabled(GL_BLEND);
    mDepthTest = glIsEnabled(GL_DEPTH_TEST);
    mCull = glIsEnabled(GL_CULL_FACE);
    glGetBooleanv(GL_DEPTH_WRITEMASK, &mDepthMask);
    glGetBooleanv(GL_COLOR_WRITEMASK, mColorMask);
    glGetIntegerv(GL_BLEND_SRC_RGB, &mBlendFunc[0]);
    glGetIntegerv(GL_BLEND_DST_RGB, &mBlendFunc[1]);
    glGetIntegerv(GL_BLEND_SRC_ALPHA, &mBlendFunc[2]);
    glGetIntegerv(GL_BLEND_DST_ALPHA, &mBlendFunc[3]);
    glGetIntegerv(GL_BLEND_EQUATION_RGB, &mBlendEquation[0]);
    glGetIntegerv(GL_BLEND_EQUATION_ALPHA, &mBlendEquation[1]);
    glGetIntegerv(GL_DEPTH_FUNC, &mDepthFunc);
    if (mDesc.scissor) {
        mScissor = glIsEnabled(GL_SCISSOR_TEST);
        glGetIntegerv(GL_SCISSOR_BOX, mScissorBox);
    }
}

void SavedState::restore() const {
    auto set = [](GLenum cap, GLboolean on) { on ? glEnable(cap) : glDisable(cap); };
    // glIs* is false for a deleted name (and for 0, which is bound as 0 anyway).
    auto alive = [](GLint name, GLboolean isAlive) { return isAlive ? GLuint(name) : 0u; };
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, alive(mDrawFbo, glIsFramebuffer(GLuint(mDrawFbo))));
    glUseProgram(alive(mProgram, glIsProgram(GLuint(mProgram))));
    glBindVertexArray(alive(mVao, glIsVertexArray(GLuint(mVao))));
    glBindBuffer(GL_ARRAY_BUFFER, alive(mArrayBuffer, glIsBuffer(GLuint(mArrayBuffer))));
    glViewport(mViewport[0], mViewport[1], mViewport[2], mViewport[3]);
    for (int u = 0; u < mDesc.texture2DUnits; ++u) {
        glActiveTexture(GLenum(GL_TEXTURE0 + u));
        glBindTexture(GL_TEXTURE_2D, alive(mTex2D[u], glIsTexture(GLuint(mTex2D[u]))));
    }
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D_ARRAY, alive(mTexArray0, glIsTexture(GLuint(mTexArray0))));
    glActiveTexture(GLenum(mActiveTexture));
    set(GL_BLEND, mBlend);
    set(GL_DEPTH_TEST, mDepthTest);
    set(GL_CULL_FACE, mCull);
    glDepthMask(mDepthMask);
    glColorMask(mColorMask[0], mColorMask[1], mColorMask[2], mColorMask[3]);
    glBlendFuncSeparate(GLenum(mBlendFunc[0]), GLenum(mBlendFunc[1]), GLenum(mBlendFunc[2]), GLenum(mBlendFunc[3]));
    glBlendEquationSeparate(GLenum(mBlendEquation[0]), GLenum(mBlendEquation[1]));
    glDepthFunc(GLenum(mDepthFunc));
    if (mDesc.scissor) {
        set(GL_SCISSOR_TEST, mScissor);
        glScissor(mScissorBox[0], mScissorBox[1], mScissorBox[2], mScissorBox[3]);
    }
}

} // namespace splatfx::gl::detail
