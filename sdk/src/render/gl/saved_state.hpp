// The host GL state the backend's passes change, saved before and put back
// after (RendererDesc::restoreState), for gl::Renderer and gl::ScaledRenderer
// alike (private).
//
// restore() never rebinds a name the host has deleted in the meantime
// (programs, vertex arrays, buffers, textures, framebuffers): a host may
// delete its own objects while they are still bound, and once ours replaced
// them the names are gone, so rebinding would be a GL error. Such a binding
// is restored as 0.
#pragma once

#include <epoxy/gl.h>

namespace splatfx::gl::detail {

struct SavedStateDesc {
    int texture2DUnits = 0; // units 0..n-1 whose GL_TEXTURE_2D binding the caller changes; default 0
    bool scissor = false;   // the caller changes the scissor test and box; default false
};

class SavedState {
public:
    static constexpr int kMaxTexture2DUnits = 4;

    // Also saves the GL_TEXTURE_2D_ARRAY binding of unit 0 (the splats'
    // texture layers), the active unit, framebuffer, viewport, program,
    // vertex array, array buffer, blend, depth, cull and colour-mask state.
    void save(const SavedStateDesc& desc);
    void restore() const;

private:
    SavedStateDesc mDesc;
    GLint mDrawFbo = 0, mProgram = 0, mVao = 0, mArrayBuffer = 0, mActiveTexture = 0;
    GLint mViewport[4] = {};
    GLint mTexArray0 = 0, mTex2D[kMaxTexture2DUnits] = {};
    GLboolean mBlend = 0, mDepthTest = 0, mDepthMask = 0, mCull = 0, mScissor = 0;
    GLboolean mColorMask[4] = {};
    GLint mBlendFunc[4] = {}, mBlendEquation[2] = {}, mDepthFunc = 0;
    GLint mScissorBox[4] = {};
};

} // namespace splatfx::gl::detail
