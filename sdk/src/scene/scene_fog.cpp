// The scene's fog, only the terms a view can see (docs/fog.md, "Terms out of
// view"): each term's optical depth is bounded over the frustum's box, the
// smallest are dropped while their bounds sum under FogCullDesc's depth.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "splatfx/scene.hpp"

namespace splatfx {

Status Scene::setFogCulling(const FogCullDesc& desc) {
    if (!(std::isfinite(desc.maxSkippedDepth) && desc.maxSkippedDepth >= 0.0))
        return makeError("FogCullDesc.maxSkippedDepth must be finite and >= 0 (an optical depth; 0 drops only terms that add nothing), got " +
                         std::to_string(desc.maxSkippedDepth));
    mFogCull = desc;
    return {};
}

std::shared_ptr<const Fog> Scene::fogForView(const Camera& camera, double timeSec) {
    mCounters.fogTermsDrawn = mCounters.fogTermsSkipped = 0;
    mCounters.fogSkipped = false;
    if (!mFog) return nullptr;
    const std::size_t n = mFog->desc().terms.size();
    mCounters.fogTermsDrawn = n;
    const FogCullDesc& cull = mFogCull;
    if (!cull.enabled || n == 0) return mFog;
    // The frustum's world box, from the 8 corners of clip space, and the
    // longest segment inside it (its diagonal).
    const glm::mat4 inv = glm::inverse(camera.proj * camera.view);
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    double farthest = 0.0;
    const glm::dvec3 eye(camera.eye());
    for (int i = 0; i < 8; ++i) {
        const glm::vec4 c = inv * glm::vec4(i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, i & 4 ? 1.0f : -1.0f, 1.0f);
        const glm::dvec3 p = glm::dvec3(glm::vec3(c) / c.w);
        lo = glm::min(lo, p), hi = glm::max(hi, p);
        farthest = std::max(farthest, glm::length(p - eye));
    }
    if (!(std::isfinite(lo.x) && std::isfinite(lo.y) && std::isfinite(lo.z) && std::isfinite(hi.x) && std::isfinite(hi.y) && std::isfinite(hi.z)))
        return mFog; // a degenerate camera: nothing can be bounded
    const double diagonal = glm::length(hi - lo);
    std::vector<double> bound(n);
    for (std::size_t i = 0; i < n; ++i) bound[i] = mFog->termDepthBound(i, timeSec, lo, hi, diagonal);
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return bound[a] < bound[b]; });
    std::vector<bool> keep(n, true);
    double dropped = 0.0;
    std::size_t skipped = 0;
    for (std::size_t i : order) {
        if (!(dropped + bound[i] <= cull.maxSkippedDepth)) break;
        dropped += bound[i];
        keep[i] = false;
        ++skipped;
    }
    // A far cut-off inside the view fogs it fully there whatever the terms: keep the fog whole.
    const double far = mFog->desc().farDistanceWorld;
    const bool cutOffInView = far > 0.0 && farthest > far;
    if (skipped == 0 || (skipped == n && cutOffInView)) return mFog;
    mCounters.fogTermsSkipped = skipped;
    mCounters.fogTermsDrawn = n - skipped;
    if (skipped == n) {
        mCounters.fogSkipped = true; // no fog in view: the frame has none, and no fog pass runs
        return nullptr;
    }
    if (keep != mFogKeep || !mFogView) {
        auto culled = mFog->withTerms(keep);
        // A kept set that fails validation is remembered as the full fog, so it is not retried every frame.
        mFogView = culled ? std::make_shared<const Fog>(std::move(*culled)) : mFog;
        mFogKeep = std::move(keep);
    }
    if (mFogView == mFog) {
        ++mCounters.fogCullFallbacks;
        mCounters.fogTermsSkipped = 0;
        mCounters.fogTermsDrawn = n;
    }
    return mFogView;
}

} // namespace splatfx
