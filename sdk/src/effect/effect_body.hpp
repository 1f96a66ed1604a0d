// The inside of an Effect: what every kind shares (desc, layers, the
// current grid and its height split into layers, emit, the splat-extent part
// of bounds) and the virtual functions each kind implements
// (grid_effect.cpp, gas_effect.cpp, sequence_effect.cpp: StatelessBody;
// solver_effect.cpp: stateful).
// Private to the SDK: the public extension point is EffectKind.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "splatfx/effect.hpp"
#include "splatfx/particles.hpp"
#include "splatfx/procedural_gas.hpp"

namespace splatfx::detail {

class EffectBody {
public:
    virtual ~EffectBody() = default;
    virtual std::unique_ptr<EffectBody> clone() const = 0;

    virtual bool stateless() const = 0;
    virtual void update(double timeSec) = 0;
    virtual void step(double dtSec) = 0;
    virtual AdvanceResult advanceTo(double timeSec, const AdvanceContext& context) = 0;
    virtual bool alive(double timeSec, const AliveHints& hints) const = 0;
    virtual Aabb bounds(double t0, double t1) const = 0;
    virtual std::uint64_t costCells() const = 0;
    // After desc.enabled changed.
    virtual void togglesChanged() {}
    virtual FluidSolver* solver() { return nullptr; }
    virtual const TextureDynamics& textureDynamics() const = 0;

    // Shared by both kinds.
    static Status checkDesc(const EffectDesc& desc);
    // Takes the desc, its layers (one default layer when none) and the
    // lattice rows the height bands are measured over.
    void init(EffectDesc d, int latticeLoY, int latticeHiY);
    // grid -> layerGrids by the layers' height bands (EffectLayer).
    void splitLayers();
    // Every layer's grid through the builder; the particle kind draws its particles instead.
    virtual std::size_t emit(SplatBuilder& builder, const Materials& materials, const EmitOptions& options) const;
    // Whether the scene's lights see the kind (lightingDensity): particles are drawn unlit.
    virtual bool lit() const { return true; }
    // Host particles (Effect::setParticles): only the particle kind takes them.
    virtual Status setParticles(std::span<const Particle> particles);
    // The world box `world` (lattice points, motion included) grown by the
    // largest splat: footprint radius times the kernel's largest axis for a
    // lattice with this transform and spacing, scaled by `motionScale`.
    Aabb withSplatExtent(const Aabb& world, float motionScale, const glm::mat4& transform, glm::vec3 spacing, float maxStretch) const;
    // The corners of `box` through `m`.
    static Aabb transformBox(const Aabb& box, const glm::mat4& m);

    EffectDesc desc;
    std::vector<EffectLayer> layers;
    Grid grid;                    // the whole effect now
    std::vector<Grid> layerGrids; // grid split by layers
    int latticeLoY = 0, latticeHiY = 0;
    double time = 0.0;
    EffectCounters counters;
};

// A kind whose frame t is a pure function of t (grid, gas, sequence): a step
// is the evaluation of a later time, and frames may be evaluated in any order.
class StatelessBody : public EffectBody {
public:
    bool stateless() const final { return true; }
    void step(double dtSec) override;
    AdvanceResult advanceTo(double timeSec, const AdvanceContext& context) override;

protected:
    // Bounds over [t0, t1] of the lattice points in `localBox` (lattice-local),
    // placed by `latticeTransform` and swept by the desc's motion (frozen at
    // t = 0 when object dynamics are off), grown by the largest splat.
    Aabb sweptBounds(const Aabb& localBox, const glm::mat4& latticeTransform, glm::vec3 spacing, float maxStretch, double t0, double t1) const;
};

std::unique_ptr<EffectBody> makeGridBody(Grid base, EffectDesc desc);
Result<std::unique_ptr<EffectBody>> makeSolverBody(FluidSolver solver, EffectDesc desc);
Result<std::unique_ptr<EffectBody>> makeGasBody(ProceduralGasDesc gas, Grid lattice, EffectDesc desc);
Result<std::unique_ptr<EffectBody>> makeParticleBody(ParticleEmitterDesc emitter, EffectDesc desc); // particle_effect.cpp
Result<std::unique_ptr<EffectBody>> makeSequenceBody(GridSequence sequence, EffectDesc desc); // sequence_effect.cpp

} // namespace splatfx::detail
