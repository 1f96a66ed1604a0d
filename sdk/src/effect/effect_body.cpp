// What the kinds of Effect share: desc checks, the layers' height split
// (EffectLayer), emit, the splat extent of bounds, and the stateless kinds'
// stepping and swept bounds.
#include "effect_body.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace splatfx::detail {
namespace {

// Weight of a layer at normalized height h (see EffectLayer).
float layerWeight(const EffectLayer& l, float h) {
    const float b = std::max(l.blend, 0.0f);
    float w = 1.0f;
    if (l.heightFrom > 0.0f) {
        if (b > 0.0f) w *= std::clamp((h - (l.heightFrom - 0.5f * b)) / b, 0.0f, 1.0f);
        else w *= h >= l.heightFrom ? 1.0f : 0.0f;
    }
    if (l.heightTo < 1.0f) {
        if (b > 0.0f) w *= std::clamp(((l.heightTo + 0.5f * b) - h) / b, 0.0f, 1.0f);
        else w *= h < l.heightTo ? 1.0f : 0.0f; // a voxel exactly on a hard split goes to the upper layer
    }
    return w;
}

// Bound on the largest axis of one splat's kernel for a lattice with this
// transform and spacing, per unit footprint radius.
float kernelNormBound(const glm::mat4& transform, glm::vec3 spacing, float maxStretch) {
    // The builder's kernel matrix is M = (motion) * mat3(base) * diag(spacing) * (I + k s s^T)
    // with |s| = 1, k = |stretch|; a splat's ellipse axes reach at most R times
    // its largest singular value. sigma(B)^2 is bounded by the largest
    // absolute row sum of B^T B (exact for a rotation times a uniform scale);
    // sigma(diag(spacing) (I + k s s^T)) <= max(spacing) * (1 + k).
    const glm::mat3 b(transform);
    const glm::mat3 btb = glm::transpose(b) * b;
    float rowSum = 0.0f;
    for (int r = 0; r < 3; ++r) rowSum = std::max(rowSum, std::abs(btb[0][r]) + std::abs(btb[1][r]) + std::abs(btb[2][r]));
    const float spMax = std::max({spacing.x, spacing.y, spacing.z});
    return std::sqrt(rowSum) * spMax * (1.0f + maxStretch);
}

} // namespace

Status EffectBody::checkDesc(const EffectDesc& d) {
    const std::string at = "effect '" + d.name + "': ";
    for (std::size_t i = 0; i < d.layers.size(); ++i) {
        const EffectLayer& l = d.layers[i];
        const std::string li = at + "layers[" + std::to_string(i) + "].";
        if (!(l.heightFrom >= 0.0f && l.heightFrom <= 1.0f)) return makeError(li + "heightFrom must be in [0, 1]");
        if (!(l.heightTo >= l.heightFrom && l.heightTo <= 1.0f)) return makeError(li + "heightTo must be in [heightFrom, 1]");
        if (!(l.blend >= 0.0f && l.blend <= 1.0f)) return makeError(li + "blend must be in [0, 1]");
        if (std::string e = checkSplatVariation(l.style.variation, li + "style.variation."); !e.empty()) return makeError(e);
    }
    const PropagationDesc& p = d.textures.propagation;
    if (p.mode != Propagation::None && !(p.stepsPerSec > 0.0f && std::isfinite(p.stepsPerSec)))
        return makeError(at + "textures.propagation.stepsPerSec must be positive and finite, got " + std::to_string(p.stepsPerSec));
    if (p.mode == Propagation::Fixed && p.direction == glm::ivec3(0))
        return makeError(at + "textures.propagation.direction must be non-zero for Propagation::Fixed");
    const CyclingDesc& c = d.textures.cycling;
    if (!(c.texturesPerSec >= 0.0f && std::isfinite(c.texturesPerSec)))
        return makeError(at + "textures.cycling.texturesPerSec must be finite and >= 0");
    if (!(c.rateJitter >= 0.0f && c.rateJitter < 1.0f)) return makeError(at + "textures.cycling.rateJitter must be in [0, 1)");
    if (!(d.footprintRadius > 0.0f && std::isfinite(d.footprintRadius))) return makeError(at + "footprintRadius must be positive and finite");
    if (!(d.growth.softnessCells > 0.0f)) return makeError(at + "growth.softnessCells must be > 0");
    const SparseOutputDesc& s = d.sparse;
    if (!(s.opacityPerDensity >= 0.0f) || !(s.minOpacity >= 0.0f) || !(s.temperatureRange > 0.0f) || !(s.maxStretch >= 0.0f) ||
        !(s.stretchPerSpeed >= 0.0f))
        return makeError(at + "sparse: opacityPerDensity, minOpacity, stretchPerSpeed, maxStretch must be >= 0 and "
                              "temperatureRange > 0");
    return {};
}

void EffectBody::init(EffectDesc d, int loY, int hiY) {
    desc = std::move(d);
    layers = desc.layers.empty() ? std::vector<EffectLayer>{EffectLayer{}} : desc.layers;
    latticeLoY = loY;
    latticeHiY = hiY;
}

void EffectBody::splitLayers() {
    layerGrids.resize(layers.size());
    const float span = float(std::max(latticeHiY - latticeLoY, 1));
    for (std::size_t li = 0; li < layers.size(); ++li) {
        const EffectLayer& l = layers[li];
        Grid& g = layerGrids[li];
        g.dims = grid.dims;
        g.spacing = grid.spacing;
        g.transform = grid.transform;
        g.voxels.clear();
        const bool whole = l.heightFrom <= 0.0f && l.heightTo >= 1.0f && !l.remapColor;
        if (whole) {
            g.voxels = grid.voxels;
            continue;
        }
        const float bandSpan = std::max(l.heightTo - l.heightFrom, 1e-6f);
        for (const Voxel& v : grid.voxels) {
            const float h = float(v.cell.y - latticeLoY) / span;
            const float w = layerWeight(l, h);
            if (w <= 0.0f) continue;
            Voxel out = v;
            out.opacity = v.opacity * w;
            if (l.remapColor) out.colorCoord = std::clamp((h - l.heightFrom) / bandSpan, 0.0f, 1.0f);
            g.voxels.push_back(out);
        }
    }
}

std::size_t EffectBody::emit(SplatBuilder& builder, const Materials& materials, const EmitOptions& options) const {
    assert(materials.footprint().radius() <= desc.footprintRadius * (1.0f + 1e-5f) &&
           "Effect::emit: the materials' footprint is wider than EffectDesc::footprintRadius; bounds() would be wrong");
    const std::size_t before = builder.splats().size();
    for (std::size_t i = 0; i < layers.size(); ++i) {
        SplatStyle style = layers[i].style;
        style.textured = style.textured && options.textured;
        assert((!style.textured || style.textureSet < materials.setCount()) && "Effect::emit: layer texture set not in materials");
        assert(style.colorTable < materials.colorTableCount() && "Effect::emit: layer colour table not in materials");
        style.opacityScale *= options.opacityScale;
        builder.add(layerGrids[i], materials, style);
    }
    return builder.splats().size() - before;
}

Status EffectBody::setParticles(std::span<const Particle>) {
    return makeError("effect '" + desc.name + "': setParticles needs a particle effect (Effect::fromParticles)");
}

Aabb EffectBody::transformBox(const Aabb& box, const glm::mat4& m) {
    Aabb out;
    if (box.empty()) return out;
    for (int c = 0; c < 8; ++c) out.extend(glm::vec3(m * glm::vec4(box.corner(c), 1.0f)));
    return out;
}

Aabb EffectBody::withSplatExtent(const Aabb& world, float motionScale, const glm::mat4& transform, glm::vec3 spacing, float maxStretch) const {
    // Splat extent: the builder's R times the kernel's largest axis, times the
    // largest SplatVariation scale, plus the jitter's reach (at most
    // jitter * sqrt(3) cells, each at most the kernel's largest axis long).
    float maxScale = 1.0f, jitter = 0.0f;
    for (const EffectLayer& l : layers) {
        maxScale = std::max(maxScale, std::exp2(std::clamp(l.style.variation.scaleLog2, 0.0f, 1.0f)));
        jitter = std::max(jitter, std::clamp(l.style.variation.jitter, 0.0f, SplatVariation::kMaxJitter));
    }
    const float extent = motionScale * (desc.footprintRadius * maxScale * kernelNormBound(transform, spacing, maxStretch) +
                                        jitter * 1.7320508f * kernelNormBound(transform, spacing, 0.0f));
    // A little slack for float rounding in the builder's matrix products.
    return world.expanded(extent * (1.0f + 1e-4f) + 1e-5f);
}

void StatelessBody::step(double dtSec) {
    assert(std::isfinite(dtSec) && dtSec >= 0.0 && "Effect::step: dtSec must be finite and >= 0");
    update(time + dtSec);
}

// A pure function of time: evaluate t, nothing to catch up.
AdvanceResult StatelessBody::advanceTo(double timeSec, const AdvanceContext&) {
    update(timeSec);
    return {.steps = 1, .caughtUp = false};
}

Aabb StatelessBody::sweptBounds(const Aabb& localBox, const glm::mat4& latticeTransform, glm::vec3 spacing, float maxStretch, double t0,
                                double t1) const {
    if (t1 < t0) std::swap(t0, t1);
    if (localBox.empty()) return {};
    // Object space: the lattice transform's image of the local box (its corners bound it).
    const Aabb object = transformBox(localBox, latticeTransform);
    Aabb world;
    float scale = 1.0f;
    if (desc.enabled.object) {
        world = desc.motion.sweep(object, t0, t1);
        scale = desc.motion.maxScale(t0, t1);
    } else {
        const Pose p = desc.motion.sample(0.0);
        world = transformBox(object, p.matrix());
        scale = std::max({p.scale.x, p.scale.y, p.scale.z});
    }
    return withSplatExtent(world, scale, latticeTransform, spacing, maxStretch);
}

} // namespace splatfx::detail
