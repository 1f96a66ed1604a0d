// Fog of the host's opaque image (issue 14, item 2; Biri et al. 2002 sec. 4),
// private to the GL backend and owned by gl::FrameRenderer.
//
// Reads the host depth texture, unprojects each pixel to its world position
// relative to the eye (hostUnprojection: precise at any far / near, and no
// large absolute coordinate reaches the shader), evaluates the transmittance f
// from the eye to it with fogGlsl()'s closed forms and blends
// C = f C_in + (1 - f) C_fog (eq. 5) into the host colour as a premultiplied
// "over" layer ((1 - f) C_fog, 1 - f) with (ONE, ONE_MINUS_SRC_ALPHA): no copy
// of the colour, no feedback loop. The depth texture is only sampled (no depth
// test, no depth writes), as every engine's deferred fog does.
//  * the far plane's depth (sky; 1, or 0 reversed): the far-plane point (fully
//    fogged beyond the cut-off, and always under an infinite far plane);
//  * NaN or outside [0, 1]: fully fogged (as Fog::transmittance for invalid input);
//  * beyond FogDesc::farDistanceWorld: fully fogged, no evaluation (sec. 4.2).
// At full resolution (one evaluation per pixel) or into a reduced fog texture
// (the paper's Table 1) holding (f, distance) per texel, upsampled with joint
// bilinear weights that drop neighbours at another depth.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/camera.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/result.hpp"
#include "pass.hpp"
#include "render/gl/program_library.hpp"

namespace splatfx::gl::detail {

// How fog_pass.frag turns a pixel and its window depth into a world position
// relative to the eye (see there): precise at any far / near ratio.
struct HostUnprojection {
    glm::mat3 ray{0.0f};       // (ndc.x, ndc.y, 1) -> the point at view depth 1 (perspective) or at d = 0
    glm::vec3 depthAxis{0.0f}; // orthographic: from d = 0 to d = 1
    glm::vec3 depthMap{0.0f};  // host_depth.glsl's uHostDepthMap (hostDepthMap(camera))
};
HostUnprojection hostUnprojection(const Camera& camera);

class FogPass final : public Pass {
public:
    // textureSize (0, 0): per pixel; else the reduced fog texture's size.
    // depthThreshold: relative distance difference still one surface when upsampling.
    FogPass(glm::ivec2 textureSize, float depthThreshold, Programs programs)
        : mPrograms(std::move(programs)), mAskedSize(textureSize), mDepthThreshold(depthThreshold) {}
    FogPass(const FogPass&) = delete;
    FogPass& operator=(const FogPass&) = delete;
    ~FogPass();

    // Expects a single-sampled host depth in the target.
    Status draw(const Fog& fog, double timeSec, const Camera& camera, const PassTarget& target);

    void prepare(const FramePlan& plan, const Frame& frame) override;
    void execute(const PlanStep& step, StepContext& context) override; // HostFog
    void report(FrameRenderStats& stats) const override;

private:
    Status build(const Fog& fog);
    Programs mPrograms;
    // Per pixel; reduced: evaluate into the texture; upsample and blend (MODE 0, 1, 2).
    const ProgramLibrary::Program* mModes[3] = {};
    std::uint64_t mFogKey = 0; // Fog::glslKey() the programs were built for
    unsigned mVao = 0, mFbo = 0, mTexture = 0, mSampler = 0;
    glm::ivec2 mTextureSize{0};
    std::vector<glm::vec4> mParams;
    const std::vector<glm::vec4>* mFrameParams = nullptr; // the plan's, while a step runs
    glm::ivec2 mAskedSize{0};
    float mDepthThreshold = 0.05f;
    bool mDrawn = false;
    std::string mError;
};

} // namespace splatfx::gl::detail
