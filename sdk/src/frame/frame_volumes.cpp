// [clouds, issue 17] One back-to-front sequence of splat and tetrahedron batches.
#include <algorithm>
#include <cmath>
#include <limits>

#include "splatfx/frame.hpp"

namespace splatfx {

void interleaveBackToFront(const std::vector<Splat>& splats, const std::vector<FrameVolume>& volumes, const Camera& camera,
                           std::vector<DrawBatch>& out) {
    out.clear();
    bool anyTets = false;
    for (const FrameVolume& v : volumes) anyTets |= v.table && !v.lod.tets.empty();
    if (!anyTets) { // the common case: no merge
        if (!splats.empty()) out.push_back({DrawBatch::Kind::Splats, 0, 0, std::uint32_t(splats.size())});
        return;
    }
    const glm::vec3 eye = camera.eye(), fwd = camera.forward();
    const bool persp = camera.perspective();
    // Keys as the splats' depth (splats.hpp): eye distance, or distance along
    // forward for an orthographic camera. A tetrahedron's key is the suffix
    // maximum of its list's centroid keys: the list's order is an exact
    // visibility order we must keep, and the suffix maximum is the smallest
    // non-increasing key at or above every centroid key.
    std::vector<std::vector<float>> keys(volumes.size());
    for (std::size_t v = 0; v < volumes.size(); ++v) {
        const auto& tets = volumes[v].lod.tets;
        if (!volumes[v].table) continue; // not drawn
        auto& k = keys[v];
        k.resize(tets.size());
        float running = -std::numeric_limits<float>::infinity();
        for (std::size_t i = tets.size(); i-- > 0;) {
            const auto& p = tets[i].position;
            const glm::vec3 c = 0.25f * (p[0] + p[1] + p[2] + p[3]) - eye;
            float key = persp ? glm::length(c) : glm::dot(c, fwd);
            if (!std::isfinite(key)) key = running; // keep the order; never poison the merge
            running = std::max(running, key);
            k[i] = running;
        }
    }
    // K+1-way merge by the head keys, farthest first; runs from one list become one batch.
    const std::size_t lists = volumes.size() + 1; // list 0: splats; list v+1: volume v
    std::vector<std::size_t> head(lists, 0);
    auto size = [&](std::size_t l) { return l == 0 ? splats.size() : keys[l - 1].size(); };
    auto key = [&](std::size_t l) { return l == 0 ? splats[head[0]].depth : keys[l - 1][head[l]]; };
    for (;;) {
        std::size_t best = lists;
        float bestKey = 0.0f;
        for (std::size_t l = 0; l < lists; ++l) {
            if (head[l] >= size(l)) continue;
            const float k = key(l);
            if (best == lists || k > bestKey) {
                best = l;
                bestKey = k;
            }
        }
        if (best == lists) break;
        const DrawBatch::Kind kind = best == 0 ? DrawBatch::Kind::Splats : DrawBatch::Kind::Tetrahedra;
        const std::uint32_t volume = best == 0 ? 0u : std::uint32_t(best - 1);
        if (!out.empty() && out.back().kind == kind && out.back().volume == volume && out.back().end == head[best]) ++out.back().end;
        else out.push_back({kind, volume, std::uint32_t(head[best]), std::uint32_t(head[best] + 1)});
        ++head[best];
    }
    if (out.empty() && !splats.empty()) out.push_back({DrawBatch::Kind::Splats, 0, 0, std::uint32_t(splats.size())});
}

} // namespace splatfx
