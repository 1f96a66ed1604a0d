// The particle kind of Effect (King et al. 1999, sec. 6: "splat locations,
// instead of a rectangular grid"): splats at the positions of a closed-form
// particle emitter (particles.hpp), plus any particles a host hands in.
// Stateless like the grid kind: frame t is the emitter evaluated at t, so
// skipped frames cost nothing and a step longer than a lifetime loses no
// particle's history. The particles go into the frame's one SplatBuilder, so
// they are sorted and cut with every grid's splats.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "effect_body.hpp"

namespace splatfx::detail {
namespace {

class ParticleBody final : public StatelessBody {
public:
    ParticleBody(ParticleEmitter emitter, ParticleEmitter frozenTextures, EffectDesc d)
        : mEmitter(std::move(emitter)), mStillTextures(std::move(frozenTextures)) {
        init(std::move(d), 0, 0);
        splitLayers(); // empty layer grids: grid() of a particle effect holds no voxels
        update(0.0);
        counters = {};
    }

    std::unique_ptr<EffectBody> clone() const override { return std::make_unique<ParticleBody>(*this); }
    const TextureDynamics& textureDynamics() const override { return mNoTextureDynamics; }
    std::uint64_t costCells() const override { return mEmitter.maxAlive() + mHost.size(); }
    bool lit() const override { return false; }

    void update(double t) override {
        assert(t >= 0.0 && t <= kMaxTimeSec && "Effect::update: timeSec must be in [0, kMaxTimeSec]");
        time = t;
        // Object dynamics off: the particles frozen at t = 0; local off: textures not cycling.
        const ParticleEmitter& e = desc.enabled.local ? mEmitter : mStillTextures;
        e.particlesAt(desc.enabled.object ? t : 0.0, mParticles);
        ++counters.updates;
        counters.voxelsUpdated += mParticles.size();
    }

    AdvanceResult advanceTo(double t, const AdvanceContext&) override {
        if (t == time && counters.updates > 0) return {};
        update(t);
        return {.steps = 1};
    }

    bool alive(double t, const AliveHints&) const override {
        if (!mHost.empty()) return true;
        const ParticleEmitterDesc& d = mEmitter.desc();
        const double te = desc.enabled.object ? t : 0.0;
        if (!(d.ratePerSec > 0.0f) || !(d.lifetimeSec > 0.0f)) return false;
        // Someone born in [te - lifetime, te] within [startSec, stopSec), and the emitter not faded out then.
        return te >= d.startSec && te - d.lifetimeSec < d.stopSec;
    }

    Aabb bounds(double t0, double t1) const override {
        Aabb centres = desc.enabled.object ? mEmitter.centerBounds(t0, t1) : mEmitter.centerBounds(0.0, 0.0);
        const ParticleEmitterDesc& d = mEmitter.desc();
        float reach = mEmitter.maxSizeWorld() * (1.0f + (d.stretchPerSpeed > 0.0f ? d.maxStretch : 0.0f));
        centres.extend(mHostCentres);
        reach = std::max(reach, mHostReach);
        if (centres.empty()) return {};
        // The builder's kernel is size * (I + s d d^T): largest axis size * (1 + s),
        // times the footprint radius and the largest SplatVariation scale.
        const float varScale = std::exp2(std::clamp(layers[0].style.variation.scaleLog2, 0.0f, 1.0f));
        const float extent = desc.footprintRadius * varScale * reach;
        return centres.expanded(extent * (1.0f + 1e-4f) + 1e-5f);
    }

    std::size_t emit(SplatBuilder& builder, const Materials& materials, const EmitOptions& options) const override {
        assert(materials.footprint().radius() <= desc.footprintRadius * (1.0f + 1e-5f) &&
               "Effect::emit: the materials' footprint is wider than EffectDesc::footprintRadius; bounds() would be wrong");
        const std::size_t before = builder.splats().size();
        ParticleStyle style{.splat = layers[0].style, .stretchPerSpeed = mEmitter.desc().stretchPerSpeed, .maxStretch = mEmitter.desc().maxStretch};
        style.splat.textured = style.splat.textured && options.textured;
        assert((!style.splat.textured || style.splat.textureSet < materials.setCount()) && "Effect::emit: texture set not in materials");
        style.splat.opacityScale *= options.opacityScale;
        builder.add(mParticles, materials, style);
        builder.add(mHost, materials, style);
        return builder.splats().size() - before;
    }

    Status setParticles(std::span<const Particle> particles) override {
        if (particles.size() > kMaxParticles)
            return makeError("effect '" + desc.name + "': setParticles: " + std::to_string(particles.size()) + " particles exceed kMaxParticles (" +
                             std::to_string(kMaxParticles) + ")");
        mHost.assign(particles.begin(), particles.end());
        // Their box now, for bounds(): the builder drops the non-finite ones, so they do not count.
        mHostCentres = {};
        mHostReach = 0.0f;
        const ParticleEmitterDesc& d = mEmitter.desc();
        for (const Particle& p : mHost) {
            const float speed = glm::length(p.velocity);
            if (!std::isfinite(p.position.x) || !std::isfinite(p.position.y) || !std::isfinite(p.position.z) || !(p.sizeWorld > 0.0f) ||
                !std::isfinite(p.sizeWorld) || !std::isfinite(speed))
                continue;
            mHostCentres.extend(p.position);
            const float stretch = d.stretchPerSpeed > 0.0f ? std::min(speed * d.stretchPerSpeed, d.maxStretch) : 0.0f;
            mHostReach = std::max(mHostReach, p.sizeWorld * (1.0f + stretch));
        }
        return {};
    }

private:
    ParticleEmitter mEmitter, mStillTextures; // the second with texturesPerSec = 0 (local dynamics off)
    std::vector<Particle> mParticles;         // the emitter's, at `time`
    std::vector<Particle> mHost;              // setParticles
    Aabb mHostCentres;
    float mHostReach = 0.0f; // largest size * (1 + stretch) of a host particle
    TextureDynamics mNoTextureDynamics{};
};

} // namespace

Result<std::unique_ptr<EffectBody>> makeParticleBody(ParticleEmitterDesc emitter, EffectDesc desc) {
    const std::string at = "effect '" + desc.name + "': ";
    if (desc.layers.size() > 1) return makeError(at + "layers: a particle effect draws with one layer, got " + std::to_string(desc.layers.size()));
    Result<ParticleEmitter> e = ParticleEmitter::create(emitter, desc.motion);
    if (!e) return makeError(at + "emitter." + e.error());
    ParticleEmitterDesc still = emitter;
    still.texturesPerSec = 0.0f;
    Result<ParticleEmitter> s = ParticleEmitter::create(still, desc.motion);
    if (!s) return makeError(at + "emitter." + s.error());
    return std::unique_ptr<EffectBody>(std::make_unique<ParticleBody>(std::move(*e), std::move(*s), std::move(desc)));
}

} // namespace splatfx::detail
