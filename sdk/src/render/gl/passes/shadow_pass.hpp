// The frame's shadow on the scene: uploads Frame::shadow() as a 3D
// texture when its version changed, and binds it for the host's hooks, so a
// host surface shader with shadowGlsl() samples the gas's shadow.
// Private to gl; a pass of FrameRenderer (steps UploadShadow and UnbindShadow).
#pragma once

#include <cstdint>
#include <vector>

#include "splatfx/frame.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "pass.hpp"

namespace splatfx::gl::detail {

class ShadowPass final : public Pass {
public:
    explicit ShadowPass(int textureUnit) : mUnit(textureUnit) {}
    ShadowPass(const ShadowPass&) = delete;
    ShadowPass& operator=(const ShadowPass&) = delete;
    ~ShadowPass();

    // Uploads the frame's shadow if it changed since the last upload (an
    // invalid shadow becomes a 1^3 zero-depth table: splatfx_shadow() = 1).
    // Returns whether it uploaded.
    bool uploadTable(const FrameShadow& shadow);
    // Binds the table to the unit (saving what was bound there) / restores it.
    void bind();
    void unbind();
    ShadowBinding binding() const;

    void execute(const PlanStep& step, StepContext& context) override; // UploadShadow, UnbindShadow
    void report(FrameRenderStats& stats) const override;

private:
    int mUnit;
    unsigned mTexture = 0;
    std::uint64_t mVersion = 0;
    bool mUploadedOnce = false, mValid = false;
    glm::ivec3 mDims{0};
    glm::mat4 mWorldToTable{1.0f};
    glm::vec4 mLight{0.0f, -1.0f, 0.0f, 0.0f};
    int mSavedBinding = 0;
    std::uint64_t mUploads = 0;
    std::vector<EmittedLight> mEmitted; // the last frame's, at most kMaxEmittedLights
};

} // namespace splatfx::gl::detail
