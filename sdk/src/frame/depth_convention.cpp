// Depth conventions (depth_convention.hpp).
#include "splatfx/depth_convention.hpp"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/camera.hpp"

namespace splatfx {

std::string describe(const DepthConvention& c) {
    std::string s = c.clip == ClipDepth::ZeroToOne ? "[0,1]" : "[-1,1]";
    if (c.reversed) s += " reversed";
    if (c.infiniteFar) s += " infinite far";
    return s;
}

glm::mat4 perspectiveProjection(float fovY, float aspect, float nearPlane, float farPlane, const DepthConvention& c) {
    if (!c.reversed && !c.infiniteFar && c.clip == ClipDepth::MinusOneToOne) return glm::perspective(fovY, aspect, nearPlane, farPlane);
    // ndc z = (P22 z + P32) / -z at z = -depth: A + B / depth with A = -P22, B = P32.
    // Choose A, B so that depth near -> nearNdc and far -> farNdc (far = inf: A = farNdc).
    const double n = nearPlane, f = farPlane, zn = c.nearNdc(), zf = c.farNdc();
    double A, B;
    if (c.infiniteFar) {
        A = zf;
        B = (zn - zf) * n;
    } else {
        B = (zn - zf) * n * f / (f - n);
        A = zn - B / n;
    }
    const double t = std::tan(0.5 * double(fovY));
    glm::mat4 p(0.0f);
    p[0][0] = float(1.0 / (double(aspect) * t));
    p[1][1] = float(1.0 / t);
    p[2][2] = float(-A);
    p[2][3] = -1.0f;
    p[3][2] = float(B);
    return p;
}

DepthConvention conventionOfProjection(const glm::mat4& proj, ClipDepth clip) {
    DepthConvention c{.clip = clip};
    const bool persp = proj[3][3] == 0.0f;
    // d(ndc z)/d(depth): perspective sign(P32 / P23) (ndc = P22 / P23 - P32 / (P23 depth)); orthographic -P22.
    c.reversed = persp ? (proj[3][2] / proj[2][3] < 0.0f) : (proj[2][2] > 0.0f);
    c.infiniteFar = persp && proj[2][2] / proj[2][3] == float(c.farNdc());
    return c;
}

DepthUnprojection depthUnprojection(const Camera& camera) {
    const glm::dmat4 P(camera.proj);
    const DepthConvention& c = camera.depth;
    DepthUnprojection u;
    u.perspective = camera.perspective();
    if (u.perspective) {
        // 1 / depth = (P22 - P23 ndc) / P32.
        auto inverseDepth = [&](double window) { return (P[2][2] - P[2][3] * c.ndcFromWindow(window)) / P[3][2]; };
        u.ends = {inverseDepth(0.0), inverseDepth(1.0)};
    } else {
        // depth = (P32 - ndc) / P22.
        auto depth = [&](double window) { return (P[3][2] - c.ndcFromWindow(window)) / P[2][2]; };
        u.ends = {depth(0.0), depth(1.0)};
    }
    return u;
}

} // namespace splatfx
