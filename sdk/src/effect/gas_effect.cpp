// The procedural-gas kind of Effect (Ebert & Parent 1990): a turbulent
// density that is a pure function of (world position, time, desc), sampled
// into a fixed lattice at every update (procedural_gas.hpp). Stateless like
// the grid kind: frame t is computed directly, so skipped frames cost
// nothing; its voxels change every update, so lighting's shadow tables see
// new density each frame (they rebuild only when it actually differs).
// Texture choice is the local dynamics' stateless cycling (King et al. 1999
// sec. 3.3) per cell; there is no propagation: the gas's motion is in the density.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "effect_body.hpp"
#include "splatfx/procedural_gas.hpp"

namespace splatfx::detail {
namespace {

class GasBody final : public StatelessBody {
public:
    GasBody(ProceduralGasDesc gas, Grid lattice, EffectDesc d) : mGas(std::move(gas)), mLattice(std::move(lattice)) {
        mLattice.voxels.clear();
        init(std::move(d), 0, mLattice.dims.y - 1);
        update(0.0);
        counters = {};
    }

    std::unique_ptr<EffectBody> clone() const override { return std::make_unique<GasBody>(*this); }
    const TextureDynamics& textureDynamics() const override { return mNoTextureDynamics; }
    std::uint64_t costCells() const override {
        return std::uint64_t(mLattice.dims.x) * std::uint64_t(mLattice.dims.y) * std::uint64_t(mLattice.dims.z);
    }

    void update(double t) override {
        assert(t >= 0.0 && t <= kMaxTimeSec && "Effect::update: timeSec must be in [0, kMaxTimeSec]");
        time = t;
        // Object dynamics move the lattice through the gas's world (the gas is
        // defined in world coordinates): what is sampled is what the pose covers.
        const Pose pose = desc.motion.sample(desc.enabled.object ? t : 0.0);
        Grid placed = mLattice;
        placed.transform = pose.matrix() * mLattice.transform;
        // The gas's own motion is object dynamics too: switched off, it freezes at t = 0.
        Result<Grid> g = sampleProceduralGas(mGas, placed, desc.enabled.object ? t : 0.0);
        grid = g ? std::move(*g) : placed; // the desc was validated at creation: only a non-finite t fails
        const bool local = desc.enabled.local;
        for (Voxel& v : grid.voxels) {
            v.opacity = std::clamp(v.opacity * pose.opacity, 0.0f, 1.0f);
            const TextureSample c = local ? cycleSample(v.cell, t, desc.textures.cycling, desc.textures.seed) : TextureSample{};
            v.texture = c.texture;
            v.phase = c.phase;
        }
        std::erase_if(grid.voxels, [](const Voxel& v) { return !(v.opacity > 0.0f); });
        ++counters.updates;
        counters.voxelsUpdated += costCells();
        splitLayers();
    }

    // Sampling the turbulence is this kind's whole cost: a frame already at t is not sampled again.
    AdvanceResult advanceTo(double t, const AdvanceContext&) override {
        if (t == time && counters.updates > 0) return {};
        update(t);
        return {.steps = 1};
    }

    bool alive(double t, const AliveHints&) const override {
        const Pose pose = desc.motion.sample(desc.enabled.object ? t : 0.0);
        return pose.opacity > 0.0f;
    }

    Aabb bounds(double t0, double t1) const override {
        // Every sampled cell is a lattice point: the lattice box under the motion bounds them.
        Aabb local;
        local.extend(mLattice.localPosition({0, 0, 0}));
        local.extend(mLattice.localPosition(mLattice.dims - 1));
        return sweptBounds(local, mLattice.transform, mLattice.spacing, 0.0f, t0, t1);
    }

private:
    ProceduralGasDesc mGas;
    Grid mLattice;                        // dims, spacing and transform only
    TextureDynamics mNoTextureDynamics{}; // no base voxels to precompute for
};

} // namespace

Result<std::unique_ptr<EffectBody>> makeGasBody(ProceduralGasDesc gas, Grid lattice, EffectDesc desc) {
    if (Status s = validateProceduralGas(gas); !s) return makeError("effect '" + desc.name + "': gas." + s.error());
    if (glm::any(glm::lessThanEqual(lattice.dims, glm::ivec3(0)))) return makeError("effect '" + desc.name + "': the gas lattice has no cells");
    const std::uint64_t cells = std::uint64_t(lattice.dims.x) * std::uint64_t(lattice.dims.y) * std::uint64_t(lattice.dims.z);
    if (cells > kMaxVoxels)
        return makeError("effect '" + desc.name + "': the gas lattice has " + std::to_string(cells) + " cells, over kMaxVoxels (" +
                         std::to_string(kMaxVoxels) + ")");
    return std::unique_ptr<EffectBody>(std::make_unique<GasBody>(std::move(gas), std::move(lattice), std::move(desc)));
}

} // namespace splatfx::detail
