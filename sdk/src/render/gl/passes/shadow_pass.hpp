// The frame's shadows on the scene: uploads each of Frame::shadows() as a 3D
// texture when its version changed, and binds it for the host's hooks, so a
// host surface shader with shadowGlsl() samples the gas's shadow.
// Private to gl; a pass of FrameRenderer (steps UploadShadow and UnbindShadow).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "splatfx/frame.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "pass.hpp"

namespace splatfx::gl::detail {

class ShadowPass final : public Pass {
public:
    // Slot k's table goes to unit firstUnit - k.
    explicit ShadowPass(int firstUnit) : mUnit(firstUnit) {}
    ShadowPass(const ShadowPass&) = delete;
    ShadowPass& operator=(const ShadowPass&) = delete;
    ~ShadowPass();

    // Uploads slot k's shadow if it changed since the last upload (an
    // invalid shadow becomes a 1^3 zero-depth table: splatfx_shadow() = 1).
    // Returns whether it uploaded a table or emptied one (not the placeholder of a slot never filled).
    bool uploadTable(std::size_t k, const FrameShadow& shadow);
    // Binds every slot's table to its unit (saving what was bound there) / restores them.
    void bind();
    void unbind();
    ShadowBinding binding() const;

    void execute(const PlanStep& step, StepContext& context) override; // UploadShadow, UnbindShadow
    void report(FrameRenderStats& stats) const override;

private:
    struct Slot {
        unsigned texture = 0;
        std::uint64_t version = 0;
        bool uploadedOnce = false, valid = false;
        int light = -1;
        glm::ivec3 dims{0};
        glm::mat4 worldToTable{1.0f};
        glm::vec4 lightInTable{0.0f, -1.0f, 0.0f, 0.0f};
        int savedBinding = 0;
    };
    int mUnit;
    std::array<Slot, kMaxShadowLights> mSlots{};
    std::uint64_t mUploads = 0;
    std::vector<EmittedLight> mEmitted; // the last frame's, at most kMaxEmittedLights
    EmittedGrid mEmittedGrid;           // the last frame's
};

} // namespace splatfx::gl::detail
