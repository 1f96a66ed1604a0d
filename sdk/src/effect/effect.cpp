// An effect's three scales of motion (King et al. 1999, sec. 3) and its layers.
#include "splatfx/effect.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace splatfx {
namespace {

constexpr int kMaxCatchUpSteps = 4096; // propagation steps per step() call; beyond it the state is all seeded anyway

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

} // namespace

Status Effect::checkDesc(const EffectDesc& d) {
    const std::string at = "effect '" + d.name + "': ";
    for (std::size_t i = 0; i < d.layers.size(); ++i) {
        const EffectLayer& l = d.layers[i];
        const std::string li = at + "layers[" + std::to_string(i) + "].";
        if (!(l.heightFrom >= 0.0f && l.heightFrom <= 1.0f)) return makeError(li + "heightFrom must be in [0, 1]");
        if (!(l.heightTo >= l.heightFrom && l.heightTo <= 1.0f)) return makeError(li + "heightTo must be in [heightFrom, 1]");
        if (!(l.blend >= 0.0f && l.blend <= 1.0f)) return makeError(li + "blend must be in [0, 1]");
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
    if (!(d.footprintRadius > 0.0f && std::isfinite(d.footprintRadius)))
        return makeError(at + "footprintRadius must be positive and finite");
    if (!(d.growth.softnessCells > 0.0f)) return makeError(at + "growth.softnessCells must be > 0");
    const SparseOutputDesc& s = d.sparse;
    if (!(s.opacityPerDensity >= 0.0f) || !(s.minOpacity >= 0.0f) || !(s.temperatureRange > 0.0f) || !(s.maxStretch >= 0.0f) ||
        !(s.stretchPerSpeed >= 0.0f))
        return makeError(at + "sparse: opacityPerDensity, minOpacity, stretchPerSpeed, maxStretch must be >= 0 and "
                              "temperatureRange > 0");
    return {};
}

Result<Effect> Effect::fromGrid(Grid base, EffectDesc desc) {
    if (Status s = checkDesc(desc); !s) return makeError(s.error());
    if (Status s = base.validate(); !s) return makeError("effect '" + desc.name + "': base grid: " + s.error());
    Effect e;
    e.mDesc = std::move(desc);
    e.mLayers = e.mDesc.layers.empty() ? std::vector<EffectLayer>{EffectLayer{}} : e.mDesc.layers;
    e.mBase = std::move(base);
    if (!e.mBase.voxels.empty()) {
        e.mLatticeLoY = e.mLatticeHiY = e.mBase.voxels[0].cell.y;
        glm::ivec3 lo = e.mBase.voxels[0].cell, hi = lo;
        for (const Voxel& v : e.mBase.voxels) lo = glm::min(lo, v.cell), hi = glm::max(hi, v.cell);
        e.mLatticeLoY = lo.y;
        e.mLatticeHiY = hi.y;
        // Growth distances from the origin, in cells.
        const GrowthDesc& g = e.mDesc.growth;
        const glm::vec3 origin = g.originAtCentre ? glm::vec3(0.5f * (lo.x + hi.x), float(lo.y), 0.5f * (lo.z + hi.z))
                                                  : g.originCells;
        // The lattice never changes after construction: bounds() reuses this box.
        for (const Voxel& v : e.mBase.voxels) {
            e.mBaseBox.extend(e.mBase.localPosition(v.cell));
            e.mBaseMaxStretch = std::max(e.mBaseMaxStretch, glm::length(v.stretch));
        }
        for (const Voxel& v : e.mBase.voxels) {
            const float dist = glm::length(glm::vec3(v.cell) - origin);
            e.mGrowthDistance.push_back(dist);
            e.mGrowthMax = std::max(e.mGrowthMax, dist);
        }
    }
    e.rebuildTextureDynamics();
    e.update(0.0);
    e.mCounters = {};
    return e;
}

Result<Effect> Effect::fromSolver(FluidSolver solver, EffectDesc desc) {
    if (Status s = checkDesc(desc); !s) return makeError(s.error());
    if (!desc.motion.isStatic())
        return makeError("effect '" + desc.name + "': desc.motion must be at rest for a solver effect; attach the motion to "
                         "its emitters (the material then trails behind the moving object)");
    if (desc.textures.propagation.mode == Propagation::Fixed) {
        const glm::ivec3 d = desc.textures.propagation.direction;
        if (glm::any(glm::greaterThan(glm::abs(d), solver.dims())))
            return makeError("effect '" + desc.name + "': textures.propagation.direction is longer than the solver grid");
    }
    Effect e;
    e.mDesc = std::move(desc);
    e.mLayers = e.mDesc.layers.empty() ? std::vector<EffectLayer>{EffectLayer{}} : e.mDesc.layers;
    e.mLatticeLoY = 0;
    e.mLatticeHiY = solver.dims().y - 1;
    e.mPropagator = TexturePropagator(solver.dims(), e.mDesc.textures.seed);
    e.mTime = solver.time();
    e.mSolver.emplace(std::move(solver));
    e.step(0.0);
    e.mCounters = {};
    return e;
}

void Effect::setToggles(const DynamicsToggles& t) {
    mDesc.enabled = t;
    if (isStateless()) rebuildTextureDynamics();
}

void Effect::rebuildTextureDynamics() {
    TextureDynamicsDesc td = mDesc.textures;
    if (!mDesc.enabled.global || td.propagation.mode == Propagation::Velocity) td.propagation.mode = Propagation::None;
    if (!mDesc.enabled.local) td.cycling.mode = Cycling::None;
    mTexDyn = TextureDynamics(mBase, td);
}

void Effect::update(double t) {
    assert(isStateless() && "Effect::update: a solver effect advances with step(dtSec)");
    assert(std::isfinite(t) && t >= 0.0 && "Effect::update: timeSec must be finite and >= 0");
    mTime = t;
    // Object dynamics (sec. 3.1): pose, fades and growth of the coarse grid.
    const Pose pose = mDesc.motion.sample(mDesc.enabled.object ? t : 0.0);
    mGrid.dims = mBase.dims;
    mGrid.spacing = mBase.spacing;
    mGrid.transform = pose.matrix() * mBase.transform;
    mGrid.voxels.clear();
    const bool growing = pose.growth < 1.0f;
    for (std::size_t i = 0; i < mBase.voxels.size(); ++i) {
        Voxel v = mBase.voxels[i];
        float o = v.opacity * pose.opacity;
        if (growing) o *= growthFactor(mGrowthDistance[i], mGrowthMax, pose.growth, mDesc.growth.softnessCells);
        v.opacity = std::clamp(o, 0.0f, 1.0f);
        if (v.opacity <= 0.0f) continue; // sparse: faded or not yet grown
        // Global and local dynamics (sec. 3.2, 3.3), straight from (cell, t, seed).
        const TextureSample s = mTexDyn.sample(i, t);
        v.texture = s.texture;
        v.phase = s.phase;
        mGrid.voxels.push_back(v);
    }
    ++mCounters.updates;
    mCounters.voxelsUpdated += mBase.voxels.size();
    splitLayers();
}

void Effect::step(double dt) {
    assert(std::isfinite(dt) && dt >= 0.0 && "Effect::step: dtSec must be finite and >= 0");
    if (isStateless()) return update(mTime + dt);
    FluidSolver& s = *mSolver;
    if (mDesc.enabled.object) {
        s.step(dt);
        mCounters.stepsSimulated += std::uint64_t(s.desc().substeps);
        mCounters.voxelsUpdated += std::uint64_t(s.desc().substeps) * s.density().size();
    }
    mTime += dt;
    s.toGrid(mGrid, mDesc.sparse);

    // Occupancy: which cells hold material now (the lattice propagation walks).
    std::vector<std::uint8_t> occupied(s.density().size(), 0);
    for (const Voxel& v : mGrid.voxels) occupied[s.cellIndex(v.cell)] = 1;

    const PropagationDesc& p = mDesc.textures.propagation;
    if (mDesc.enabled.global && p.mode == Propagation::Fixed) {
        const std::int64_t target = propagationStep(mTime, p);
        int budget = kMaxCatchUpSteps;
        while (mPropagator.steps() < target && budget-- > 0) {
            mPropagator.stepFixed(p.direction, p.offset, occupied);
            ++mCounters.propagationSteps;
        }
    } else if (mDesc.enabled.global && p.mode == Propagation::Velocity && dt > 0.0) {
        // Follow the solver's flow (sec. 3.2 generalised from "the voxel below").
        std::vector<glm::vec3> vel = s.cellVelocities();
        for (glm::vec3& v : vel) v /= s.desc().spacing;
        mPropagator.advanceFlow(vel, occupied, dt, p.offset);
        ++mCounters.propagationSteps;
    }
    const bool local = mDesc.enabled.local;
    for (Voxel& v : mGrid.voxels) {
        TextureSample c = local ? cycleSample(v.cell, mTime, mDesc.textures.cycling, mDesc.textures.seed) : TextureSample{};
        v.texture = mPropagator.index(v.cell) + c.texture;
        v.phase = c.phase;
    }
    ++mCounters.updates;
    splitLayers();
}

void Effect::splitLayers() {
    mLayerGrids.resize(mLayers.size());
    const float span = float(std::max(mLatticeHiY - mLatticeLoY, 1));
    for (std::size_t li = 0; li < mLayers.size(); ++li) {
        const EffectLayer& l = mLayers[li];
        Grid& g = mLayerGrids[li];
        g.dims = mGrid.dims;
        g.spacing = mGrid.spacing;
        g.transform = mGrid.transform;
        g.voxels.clear();
        const bool whole = l.heightFrom <= 0.0f && l.heightTo >= 1.0f && !l.remapColor;
        if (whole) {
            g.voxels = mGrid.voxels;
            continue;
        }
        const float bandSpan = std::max(l.heightTo - l.heightFrom, 1e-6f);
        for (const Voxel& v : mGrid.voxels) {
            const float h = float(v.cell.y - mLatticeLoY) / span;
            const float w = layerWeight(l, h);
            if (w <= 0.0f) continue;
            Voxel out = v;
            out.opacity = v.opacity * w;
            if (l.remapColor) out.colorCoord = std::clamp((h - l.heightFrom) / bandSpan, 0.0f, 1.0f);
            g.voxels.push_back(out);
        }
    }
}

std::size_t Effect::emit(SplatBuilder& builder, const Materials& materials, const EmitOptions& options) const {
    assert(materials.footprint().radius() <= mDesc.footprintRadius * (1.0f + 1e-5f) &&
           "Effect::emit: the materials' footprint is wider than EffectDesc::footprintRadius; bounds() would be wrong");
    const std::size_t before = builder.splats().size();
    for (std::size_t i = 0; i < mLayers.size(); ++i) {
        SplatStyle style = mLayers[i].style;
        assert((!style.textured || style.textureSet < materials.setCount()) && "Effect::emit: layer texture set not in materials");
        assert(style.colorTable < materials.colorTableCount() && "Effect::emit: layer colour table not in materials");
        style.textured = style.textured && options.textured;
        style.opacityScale *= options.opacityScale;
        builder.add(mLayerGrids[i], materials, style);
    }
    return builder.splats().size() - before;
}

float Effect::kernelNormBound(const Grid& g, float maxStretch) const {
    // The builder's kernel matrix is M = (motion) * mat3(base) * diag(spacing) * (I + k s s^T)
    // with |s| = 1, k = |stretch|; a splat's ellipse axes reach at most R times
    // its largest singular value. sigma(B)^2 is bounded by the largest
    // absolute row sum of B^T B (exact for a rotation times a uniform scale);
    // sigma(diag(spacing) (I + k s s^T)) <= max(spacing) * (1 + k).
    const glm::mat3 b(g.transform);
    const glm::mat3 btb = glm::transpose(b) * b;
    float rowSum = 0.0f;
    for (int r = 0; r < 3; ++r) rowSum = std::max(rowSum, std::abs(btb[0][r]) + std::abs(btb[1][r]) + std::abs(btb[2][r]));
    const float spMax = std::max({g.spacing.x, g.spacing.y, g.spacing.z});
    return std::sqrt(rowSum) * spMax * (1.0f + maxStretch);
}

Aabb Effect::bounds(double t0, double t1) const {
    if (t1 < t0) std::swap(t0, t1);
    Aabb local;
    Grid frame; // spacing and base transform of the lattice
    float maxStretch = 0.0f;
    if (isStateless()) {
        local = mBaseBox;
        maxStretch = mBaseMaxStretch;
        frame.spacing = mBase.spacing;
        frame.transform = mBase.transform;
        frame.dims = mBase.dims;
    } else {
        const FluidSolver& s = *mSolver;
        local.extend(s.localPosition({0, 0, 0}));
        local.extend(s.localPosition(s.dims() - 1));
        frame.spacing = s.desc().spacing;
        frame.transform = s.desc().transform;
        maxStretch = mDesc.sparse.stretchPerSpeed > 0.0f ? mDesc.sparse.maxStretch : 0.0f;
    }
    if (local.empty()) return {};
    // Object space: the base transform's image of the local box (its corners bound it).
    Aabb object;
    for (int c = 0; c < 8; ++c) object.extend(glm::vec3(frame.transform * glm::vec4(local.corner(c), 1.0f)));
    Aabb world;
    float scale = 1.0f;
    if (isStateless() && mDesc.enabled.object) {
        world = mDesc.motion.sweep(object, t0, t1);
        scale = mDesc.motion.maxScale(t0, t1);
    } else {
        const Pose p = isStateless() ? mDesc.motion.sample(0.0) : Pose{};
        const glm::mat4 m = p.matrix();
        for (int c = 0; c < 8; ++c) world.extend(glm::vec3(m * glm::vec4(object.corner(c), 1.0f)));
        scale = std::max({p.scale.x, p.scale.y, p.scale.z});
    }
    // Splat extent: the builder's R times the kernel's largest axis.
    const float extent = mDesc.footprintRadius * scale * kernelNormBound(frame, maxStretch);
    // A little slack for float rounding in the builder's matrix products.
    return world.expanded(extent * (1.0f + 1e-4f) + 1e-5f);
}

} // namespace splatfx
