// Effect: the value type around one of the SDK's effect kinds
// (grid_effect.cpp, solver_effect.cpp, sequence_effect.cpp; their shared code in effect_body.cpp).
// It only forwards: no function here branches on the kind.
#include "splatfx/effect.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "effect_body.hpp"
#include "splat/color_table_entry.hpp"

namespace splatfx {

Effect::Effect(std::unique_ptr<detail::EffectBody> body) : mBody(std::move(body)) {}
Effect::Effect(const Effect& other) : EffectKind(other), mBody(other.mBody->clone()) {}
Effect& Effect::operator=(const Effect& other) {
    if (this != &other) mBody = other.mBody->clone();
    return *this;
}
Effect::Effect(Effect&&) noexcept = default;
Effect& Effect::operator=(Effect&&) noexcept = default;
Effect::~Effect() = default;

Result<Effect> Effect::fromGrid(Grid base, EffectDesc desc) {
    if (Status s = detail::EffectBody::checkDesc(desc); !s) return makeError(s.error());
    if (Status s = base.validate(); !s) return makeError("effect '" + desc.name + "': base grid: " + s.error());
    return Effect(detail::makeGridBody(std::move(base), std::move(desc)));
}

Result<Effect> Effect::fromSolver(FluidSolver solver, EffectDesc desc) {
    if (Status s = detail::EffectBody::checkDesc(desc); !s) return makeError(s.error());
    auto body = detail::makeSolverBody(std::move(solver), std::move(desc));
    if (!body) return makeError(body.error());
    return Effect(std::move(*body));
}

Result<Effect> Effect::fromProceduralGas(ProceduralGasDesc gas, Grid lattice, EffectDesc desc) {
    if (Status s = detail::EffectBody::checkDesc(desc); !s) return makeError(s.error());
    auto body = detail::makeGasBody(std::move(gas), std::move(lattice), std::move(desc));
    if (!body) return makeError(body.error());
    return Effect(std::move(*body));
}

Result<Effect> Effect::fromSequence(GridSequence sequence, EffectDesc desc) {
    if (Status s = detail::EffectBody::checkDesc(desc); !s) return makeError(s.error());
    auto body = detail::makeSequenceBody(std::move(sequence), std::move(desc));
    if (!body) return makeError(body.error());
    return Effect(std::move(*body));
}

Result<Effect> Effect::fromParticles(ParticleEmitterDesc emitter, EffectDesc desc) {
    if (Status s = detail::EffectBody::checkDesc(desc); !s) return makeError(s.error());
    auto body = detail::makeParticleBody(std::move(emitter), std::move(desc));
    if (!body) return makeError(body.error());
    return Effect(std::move(*body));
}

Status Effect::setParticles(std::span<const Particle> particles) { return mBody->setParticles(particles); }

bool Effect::isStateless() const { return mBody->stateless(); }
void Effect::update(double timeSec) { mBody->update(timeSec); }
void Effect::step(double dtSec) { mBody->step(dtSec); }
double Effect::time() const { return mBody->time; }

const Grid& Effect::grid() const { return mBody->grid; }
std::size_t Effect::layerCount() const { return mBody->layerGrids.size(); }
const Grid& Effect::layerGrid(std::size_t i) const { return mBody->layerGrids.at(i); }
const EffectLayer& Effect::layer(std::size_t i) const { return mBody->layers.at(i); }

std::size_t Effect::emit(SplatBuilder& builder, const Materials& materials, const EmitOptions& options) const {
    return mBody->emit(builder, materials, options);
}
EmitResult Effect::emit(const EmitContext& context) { return {.splats = emit(context.splats, context.materials, context.draw)}; }

bool Effect::lightingDensity(const Materials& materials, const EmitOptions& draw, Grid& out) const {
    // The light sees the opacity the splats are drawn with (style and draw
    // scales, table alpha), so the self-shadow matches the splats' own optical depth.
    if (!mBody->lit()) return false;
    const Grid& whole = grid();
    out.dims = whole.dims;
    out.spacing = whole.spacing;
    out.transform = whole.transform;
    out.voxels.clear();
    for (std::size_t li = 0; li < layerCount(); ++li) {
        const SplatStyle& style = layer(li).style;
        const ColorTable* table = style.colorTable < materials.colorTableCount() ? &materials.colorTable(style.colorTable) : nullptr;
        const float scale = style.opacityScale * draw.opacityScale;
        const float k = std::isfinite(scale) ? std::max(scale, 0.0f) : 0.0f;
        for (Voxel v : layerGrid(li).voxels) {
            if (!std::isfinite(v.opacity) || !std::isfinite(v.colorCoord)) continue;
            v.opacity = std::clamp(v.opacity * k, 0.0f, 1.0f) * detail::colorTableEntry(table, v.colorCoord).a;
            if (v.opacity > 0.0f) out.voxels.push_back(v);
        }
    }
    return true;
}

Aabb Effect::bounds(double t0, double t1) const { return mBody->bounds(t0, t1); }
bool Effect::alive(double timeSec, const AliveHints& hints) const { return mBody->alive(timeSec, hints); }
AdvanceResult Effect::advanceTo(double timeSec, const AdvanceContext& context) { return mBody->advanceTo(timeSec, context); }
std::uint64_t Effect::costCells() const { return mBody->costCells(); }

const EffectCounters& Effect::counters() const { return mBody->counters; }
const EffectDesc& Effect::desc() const { return mBody->desc; }
void Effect::setToggles(const DynamicsToggles& toggles) {
    mBody->desc.enabled = toggles;
    mBody->togglesChanged();
}
Status Effect::setSplatVariation(const SplatVariation& variation) {
    if (std::string e = checkSplatVariation(variation, "effect '" + mBody->desc.name + "': variation."); !e.empty()) return makeError(e);
    for (EffectLayer& l : mBody->layers) l.style.variation = variation;
    for (EffectLayer& l : mBody->desc.layers) l.style.variation = variation;
    return {};
}
FluidSolver* Effect::solver() { return mBody->solver(); }
const FluidSolver* Effect::solver() const { return mBody->solver(); }
const TextureDynamics& Effect::textureDynamics() const { return mBody->textureDynamics(); }

} // namespace splatfx
