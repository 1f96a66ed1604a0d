// splatfx/depth_convention.hpp: how the host's projection and depth buffer map distance to depth.
//
// OpenGL's default maps the near plane to clip z = -w (window depth 0) and
// the far plane to +w (window depth 1). Most engines instead draw with
// glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE) (clip z in [0, w]), a reversed
// projection (near at window depth 1, far at 0, depth test GL_GREATER) and
// often no far plane, into a 32-bit float depth buffer. A Camera carries its
// convention (Camera::depth); every pass that reads or compares the host's
// depth goes through depthUnprojection() of that camera, and splatfx's own
// geometry is drawn with the camera's projection and the depth test the
// convention implies (GL_GEQUAL when reversed). It does not call
// glClipControl: that state is the host's (gl::depthConventionOfContext() reads it).
//
//   splatfx::DepthConvention dc{.clip = splatfx::ClipDepth::ZeroToOne, .reversed = true, .infiniteFar = true};
//   auto cam = splatfx::Camera::lookAt(eye, target, up, fovY, size, 0.1f, 1000.0f, dc); // the host's own projection
//   auto view = splatfx::depthUnprojection(cam).viewDepth(windowDepth);                   // distance along forward
//
// Threading: plain values and pure functions.
#pragma once

#include <string>

#include <glm/glm.hpp>

namespace splatfx {

struct Camera;

// The clip-space depth range, as glClipControl's depth mode sets it.
enum class ClipDepth {
    MinusOneToOne, // GL_NEGATIVE_ONE_TO_ONE, OpenGL's default: window depth = (ndc z + 1) / 2
    ZeroToOne,     // GL_ZERO_TO_ONE (Direct3D, Vulkan, most engines): window depth = ndc z
};

struct DepthConvention {
    ClipDepth clip = ClipDepth::MinusOneToOne; // default: OpenGL's
    // The near plane at window depth 1 and the far plane at 0: depth tests
    // GL_GEQUAL, depth cleared to 0. Default false.
    bool reversed = false;
    // No far plane: Camera::lookAt / perspectiveProjection build the limit of
    // the projection as far goes to infinity (the sky is then at window depth
    // 0 reversed, 1 otherwise, at infinite distance). Reading depth does not
    // need it: the unprojection follows the projection matrix. Default false.
    bool infiniteFar = false;

    double nearNdc() const { return reversed ? 1.0 : clip == ClipDepth::ZeroToOne ? 0.0 : -1.0; }
    double farNdc() const { return reversed ? (clip == ClipDepth::ZeroToOne ? 0.0 : -1.0) : 1.0; }
    double nearWindow() const { return reversed ? 1.0 : 0.0; } // the depth clear value is farWindow()
    double farWindow() const { return reversed ? 0.0 : 1.0; }
    double ndcFromWindow(double windowDepth) const { return clip == ClipDepth::ZeroToOne ? windowDepth : 2.0 * windowDepth - 1.0; }
    bool operator==(const DepthConvention&) const = default;
};

// "[-1,1]", "[0,1] reversed", "[0,1] reversed infinite far", ... (tools, notes).
std::string describe(const DepthConvention& convention);

// The perspective projection of `convention` (OpenGL's view space, looking
// down -z): glm::perspective for the default, its reversed and [0, 1] forms
// otherwise; farPlane is ignored with infiniteFar. fovY in radians.
glm::mat4 perspectiveProjection(float fovY, float aspect, float nearPlane, float farPlane, const DepthConvention& convention = {});

// The convention a projection matrix follows under a clip range: reversed
// when window depth falls with distance, infinite far when a perspective
// matrix maps infinite distance exactly onto the far end (as
// perspectiveProjection and glm::infinitePerspective build it).
DepthConvention conventionOfProjection(const glm::mat4& proj, ClipDepth clip);

// Window depth -> view depth (distance along the view direction), for every
// convention: the one function each pass that reads the host depth uses (the
// GL passes get its two numbers as a uniform: host_depth.glsl).
// Perspective: 1 / view depth is affine in window depth, so it is the blend
// (1 - d) ends.x + d ends.y of its values at d = 0 and 1; both are >= 0 and
// nothing cancels, so it stays precise at any far / near ratio (at the far
// end it gives 1 / far exactly, 0 with no far plane), where a 4x4 inverse
// projection subtracts two terms of size 1 / (2 near). Orthographic: view
// depth itself is affine, ends holds its values at d = 0 and 1.
struct DepthUnprojection {
    bool perspective = true;
    glm::dvec2 ends{0.0}; // perspective: 1 / view depth at window depth 0 and 1; orthographic: view depth there
    // +inf for the sky under an infinite far plane; NaN for NaN.
    double viewDepth(double windowDepth) const {
        const double m = (1.0 - windowDepth) * ends.x + windowDepth * ends.y;
        return perspective ? 1.0 / m : m;
    }
};
// From camera.proj's (float) entries in double: the depths the GPU wrote
// follow those entries, so the far plane is the one they imply.
DepthUnprojection depthUnprojection(const Camera& camera);

} // namespace splatfx
