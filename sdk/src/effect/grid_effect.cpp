// The stateless kind of Effect: a base grid moved by a Motion, revealed by
// growth, textured by TextureDynamics (King et al. 1999, sec. 3.1-3.3), all a
// pure function of (voxel, t, seed): frame t is computed directly, so a
// skipped frame costs nothing and a returning effect needs no catch-up.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "effect_body.hpp"

namespace splatfx::detail {
namespace {

class GridBody final : public StatelessBody {
public:
    GridBody(Grid base, EffectDesc d) : mBase(std::move(base)) {
        int loY = 0, hiY = 0;
        glm::ivec3 lo{0}, hi{0};
        if (!mBase.voxels.empty()) {
            lo = hi = mBase.voxels[0].cell;
            for (const Voxel& v : mBase.voxels) lo = glm::min(lo, v.cell), hi = glm::max(hi, v.cell);
            loY = lo.y;
            hiY = hi.y;
        }
        init(std::move(d), loY, hiY);
        if (!mBase.voxels.empty()) {
            // Growth distances from the origin, in cells.
            const GrowthDesc& g = desc.growth;
            const glm::vec3 origin = g.originAtCentre ? glm::vec3(0.5f * (lo.x + hi.x), float(lo.y), 0.5f * (lo.z + hi.z)) : g.originCells;
            // The lattice never changes after construction: bounds() reuses this box.
            for (const Voxel& v : mBase.voxels) {
                mBaseBox.extend(mBase.localPosition(v.cell));
                mBaseMaxStretch = std::max(mBaseMaxStretch, glm::length(v.stretch));
            }
            for (const Voxel& v : mBase.voxels) {
                const float dist = glm::length(glm::vec3(v.cell) - origin);
                mGrowthDistance.push_back(dist);
                mGrowthMax = std::max(mGrowthMax, dist);
            }
        }
        rebuildTextureDynamics();
        update(0.0);
        counters = {};
    }

    std::unique_ptr<EffectBody> clone() const override { return std::make_unique<GridBody>(*this); }
    const TextureDynamics& textureDynamics() const override { return mTexDyn; }
    void togglesChanged() override { rebuildTextureDynamics(); }
    std::uint64_t costCells() const override { return mBase.voxels.size(); }

    void update(double t) override {
        assert(t >= 0.0 && t <= kMaxTimeSec && "Effect::update: timeSec must be in [0, kMaxTimeSec]");
        time = t;
        // Object dynamics (sec. 3.1): pose, fades and growth of the coarse grid.
        const Pose pose = desc.motion.sample(desc.enabled.object ? t : 0.0);
        grid.dims = mBase.dims;
        grid.spacing = mBase.spacing;
        grid.transform = pose.matrix() * mBase.transform;
        grid.voxels.clear();
        const bool growing = pose.growth < 1.0f;
        for (std::size_t i = 0; i < mBase.voxels.size(); ++i) {
            Voxel v = mBase.voxels[i];
            float o = v.opacity * pose.opacity;
            if (growing) o *= growthFactor(mGrowthDistance[i], mGrowthMax, pose.growth, desc.growth.softnessCells);
            v.opacity = std::clamp(o, 0.0f, 1.0f);
            if (v.opacity <= 0.0f) continue; // sparse: faded or not yet grown
            // Global and local dynamics (sec. 3.2, 3.3), straight from (cell, t, seed).
            const TextureSample s = mTexDyn.sample(i, t);
            v.texture = s.texture;
            v.phase = s.phase;
            grid.voxels.push_back(v);
        }
        ++counters.updates;
        counters.voxelsUpdated += mBase.voxels.size();
        splitLayers();
    }

    // Material is present unless the object's fade or growth is at zero now.
    bool alive(double t, const AliveHints&) const override {
        const Pose pose = desc.motion.sample(t);
        return pose.opacity > 0.0f && pose.growth > 0.0f;
    }

    Aabb bounds(double t0, double t1) const override { return sweptBounds(mBaseBox, mBase.transform, mBase.spacing, mBaseMaxStretch, t0, t1); }

private:
    void rebuildTextureDynamics() {
        TextureDynamicsDesc td = desc.textures;
        if (!desc.enabled.global || td.propagation.mode == Propagation::Velocity) td.propagation.mode = Propagation::None;
        if (!desc.enabled.local) td.cycling.mode = Cycling::None;
        mTexDyn = TextureDynamics(mBase, td);
    }

    Grid mBase;                         // the t = 0 material
    Aabb mBaseBox;                      // local box of the lattice points
    float mBaseMaxStretch = 0.0f;       // largest voxel stretch
    std::vector<float> mGrowthDistance; // per base voxel, cells
    float mGrowthMax = 0.0f;
    TextureDynamics mTexDyn;
};

} // namespace

std::unique_ptr<EffectBody> makeGridBody(Grid base, EffectDesc desc) { return std::make_unique<GridBody>(std::move(base), std::move(desc)); }

} // namespace splatfx::detail
