// Effect presets for the scenes of King et al. 1999 (sec. 5).
#include "splatfx/presets.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include <glm/gtc/matrix_transform.hpp>

#include "splatfx/shapes.hpp"

namespace splatfx::presets {
namespace {

// The caller's set (loaded by the caller: presets read no files), or turbulence.
Result<TextureSet> setOrTurbulence(const std::optional<TextureSet>& given, const TurbulenceDesc& fallback, bool keepColor) {
    if (!given) return TextureSet::turbulence(fallback);
    if (given->layers.empty() || given->size < 1) return makeError("the texture set has no textures");
    TextureSet set = *given;
    if (!keepColor) set.color = false;
    return set;
}

// Keys name a set by what makes it, so a preset finds a set an earlier one
// registered without building it again. %.9g prints a float exactly (9
// significant digits round-trip binary32), so distinct parameters give
// distinct keys.
std::string turbulenceKey(const TurbulenceDesc& t) {
    // A field added to TurbulenceDesc must be added to the key too, or sets
    // that differ in it would be taken for one another.
    static_assert(sizeof(TurbulenceDesc) == 7 * 4, "turbulenceKey must name every TurbulenceDesc field");
    char buf[256];
    std::snprintf(buf, sizeof buf, "turbulence(count=%d,size=%d,seed=%u,octaves=%d,baseFrequency=%.9g,loopRadius=%.9g,contrast=%.9g)", t.count,
                  t.size, t.seed, t.octaves, double(t.baseFrequency), double(t.loopRadius), double(t.contrast));
    return buf;
}

// A preset's texture set before it is registered: found in Materials by its
// key, or built and waiting for registerSet (so a preset that fails later
// registers nothing).
struct PendingSet {
    std::optional<std::uint32_t> id;
    TextureSet set;
    std::string key;
};

// A given set is shared by content (no key); a procedural one by its parameters.
Result<PendingSet> resolveSet(const Materials& m, const std::optional<TextureSet>& given, const TurbulenceDesc& fallback, bool keepColor = false) {
    PendingSet p;
    if (!given) p.key = turbulenceKey(fallback);
    if (!p.key.empty()) p.id = m.findTextureSet(p.key);
    if (p.id) return p;
    Result<TextureSet> set = setOrTurbulence(given, fallback, keepColor);
    if (!set) return makeError(set.error());
    p.set = std::move(*set);
    return p;
}

Result<std::uint32_t> registerSet(Materials& m, const PendingSet& p) {
    if (p.id) return *p.id;
    if (p.key.empty()) return m.addTextureSet(p.set);
    return m.addTextureSet(p.set, p.key);
}

Status checkCount(const char* field, int n) {
    if (n < 1 || n > 256) return makeError(std::string(field) + " must be in [1, 256], got " + std::to_string(n));
    return {};
}

Status checkUnit(const char* field, float v) {
    if (!(v > 0.0f && v <= 1.0f)) return makeError(std::string(field) + " must be in (0, 1], got " + std::to_string(v));
    return {};
}

Status checkRate(const char* field, float v) {
    if (!(v >= 0.0f && std::isfinite(v))) return makeError(std::string(field) + " must be finite and >= 0, got " + std::to_string(v));
    return {};
}

// The desc's variation with its seed tied to the effect's seed, so effects
// with different seeds vary differently; fails naming the field.
Result<SplatVariation> seededVariation(const char* desc, SplatVariation v, std::uint32_t seed) {
    if (std::string e = checkSplatVariation(v, std::string(desc) + ".variation."); !e.empty()) return makeError(e);
    v.seed = hash32(v.seed ^ hash32(seed + 0x51a7u));
    return v;
}

EffectDesc gridDesc(const char* name, const Materials& m, const Motion& motion, std::uint32_t seed) {
    EffectDesc d;
    d.name = name;
    d.motion = motion;
    d.textures.seed = seed;
    d.footprintRadius = m.footprint().radius();
    return d;
}

glm::mat4 at(glm::vec3 p) { return glm::translate(glm::mat4(1.0f), p); }

Motion restingAt(const Motion& m, glm::vec3 position) {
    if (!m.keys().empty() || !m.isStatic()) return m;
    return Motion({Keyframe{.timeSec = 0.0, .pose = {.position = position}}});
}

} // namespace

Result<Effect> fire(Materials& materials, const FireDesc& d) {
    const Result<SplatVariation> variation = seededVariation("FireDesc", d.variation, d.seed);
    if (!variation) return makeError(variation.error());
    if (Status s = checkCount("FireDesc.textureCount", d.textureCount); !s) return makeError(s.error());
    if (Status s = checkUnit("FireDesc.opacity", d.opacity); !s) return makeError(s.error());
    if (Status s = checkRate("FireDesc.texturesPerSec", d.texturesPerSec); !s) return makeError(s.error());
    Result<Grid> grid = Grid::box(d.dims, d.spacing);
    if (!grid) return makeError("FireDesc.dims/spacing: " + grid.error());
    // Sparse, sharp detail (contrast 2.5) reads as licking flames through the
    // ~20 splats that overlap on each pixel; plain turbulence averages to a haze.
    Result<PendingSet> set = resolveSet(materials, d.textureSet, {.count = d.textureCount, .size = 32, .seed = d.textureSeed, .contrast = 2.5f});
    if (!set) return makeError("FireDesc.textureSet: " + set.error());

    for (Voxel& v : grid->voxels) v.opacity = d.opacity * flameOpacity(v.cell, grid->dims, 1.0f);
    grid->colorByHeight(); // sec. 2 step 4: height stands in for temperature
    grid->transform = at(d.position);

    EffectDesc e = gridDesc("fire", materials, d.motion, d.seed);
    e.textures.propagation = {.mode = Propagation::Fixed, .direction = {0, 1, 0}, .stepsPerSec = d.propagationStepsPerSec, .offset = 1};
    e.textures.cycling = {.mode = Cycling::Ordered, .texturesPerSec = d.texturesPerSec, .rateJitter = 0.2f};
    const Result<std::uint32_t> setId = registerSet(materials, *set);
    if (!setId) return makeError("FireDesc.textureSet: " + setId.error());
    const std::uint32_t tableId = materials.addColorTable(ColorTable::fire());
    e.layers = {{.style = {.textureSet = *setId, .colorTable = tableId, .textured = true, .crossfade = d.crossfade, .variation = *variation}}};
    return Effect::fromGrid(std::move(*grid), std::move(e));
}

namespace {

// Obstacles are given in world placement, like the host's geometry; the
// message names the entry ("SmokeDesc.obstacles[2]: ObstacleDesc.size ...").
Status addObstacles(FluidSolver& solver, const std::vector<Obstacle>& obstacles, const char* descName) {
    for (std::size_t i = 0; i < obstacles.size(); ++i)
        if (Status st = solver.addObstacle(obstacles[i]); !st)
            return makeError(std::string(descName) + ".obstacles[" + std::to_string(i) + "]: " + st.error());
    return {};
}

} // namespace

Result<Effect> smoke(Materials& materials, const SmokeDesc& d) {
    const Result<SplatVariation> variation = seededVariation("SmokeDesc", d.variation, d.seed);
    if (!variation) return makeError(variation.error());
    if (Status s = checkCount("SmokeDesc.textureCount", d.textureCount); !s) return makeError(s.error());
    if (Status s = checkRate("SmokeDesc.texturesPerSec", d.texturesPerSec); !s) return makeError(s.error());
    if (!(d.sourceRadius > 0.0f)) return makeError("SmokeDesc.sourceRadius must be > 0");
    if (Status s = checkRate("SmokeDesc.dissipation", d.dissipation); !s) return makeError(s.error());
    FluidSolverDesc sd{.dims = d.dims,
                       .spacing = d.spacing,
                       .transform = at(d.position),
                       .buoyancy = 3.0f,
                       .windWorld = d.windWorld,
                       .windCoupling = glm::length(d.windWorld) > 0.0f ? 0.6f : 0.0f,
                       .velocityDamping = 0.3f,
                       .densityDissipation = d.dissipation,
                       .temperatureDissipation = 0.6f,
                       .substeps = d.substeps};
    Result<FluidSolver> solver = FluidSolver::create(sd);
    if (!solver) return makeError("SmokeDesc: " + solver.error());
    Result<PendingSet> set = resolveSet(materials, d.textureSet, {.count = d.textureCount, .size = 32, .seed = d.textureSeed, .baseFrequency = 2.0f});
    if (!set) return makeError("SmokeDesc.textureSet: " + set.error());
    solver->addEmitter({.desc = {.offset = d.sourceOffset, .radius = d.sourceRadius, .density = 1.0f, .temperature = 1.0f, .rate = 6.0f},
                        .motion = restingAt(d.sourceMotion, d.position)});
    if (Status st = addObstacles(*solver, d.obstacles, "SmokeDesc"); !st) return makeError(st.error());

    EffectDesc e = gridDesc("smoke", materials, Motion{}, d.seed);
    e.textures.propagation = {.mode = Propagation::Velocity, .offset = 1};
    e.textures.cycling = {.mode = Cycling::Ordered, .texturesPerSec = d.texturesPerSec, .rateJitter = 0.3f};
    e.sparse = {.opacityPerDensity = 0.5f, .minOpacity = 0.02f, .color = ColorSource::Height, .stretchPerSpeed = 0.15f, .maxStretch = 0.8f};
    const Result<std::uint32_t> setId = registerSet(materials, *set);
    if (!setId) return makeError("SmokeDesc.textureSet: " + setId.error());
    const std::uint32_t tableId = materials.addColorTable(ColorTable::smoke());
    e.layers = {{.style = {.textureSet = *setId, .colorTable = tableId, .textured = true, .crossfade = true, .variation = *variation}}};
    return Effect::fromSolver(std::move(*solver), std::move(e));
}

Result<Effect> steam(Materials& materials, const SteamDesc& d) {
    const Result<SplatVariation> variation = seededVariation("SteamDesc", d.variation, d.seed);
    if (!variation) return makeError(variation.error());
    if (Status s = checkCount("SteamDesc.textureCount", d.textureCount); !s) return makeError(s.error());
    if (Status s = checkUnit("SteamDesc.opacity", d.opacity); !s) return makeError(s.error());
    if (Status s = checkRate("SteamDesc.texturesPerSec", d.texturesPerSec); !s) return makeError(s.error());
    Result<Grid> grid = Grid::box(d.dims, d.spacing);
    if (!grid) return makeError("SteamDesc.dims/spacing: " + grid.error());
    Result<PendingSet> set = resolveSet(materials, d.textureSet, {.count = d.textureCount, .size = 32, .seed = d.textureSeed});
    if (!set) return makeError("SteamDesc.textureSet: " + set.error());
    for (Voxel& v : grid->voxels) {
        const float h = v.cell.y / float(std::max(d.dims.y - 1, 1));
        v.opacity = d.opacity * (1.0f - h) * (1.0f - h) + 0.02f * (1.0f - h);
    }
    grid->transform = at(d.position);

    EffectDesc e = gridDesc("steam", materials, d.motion, d.seed);
    e.textures.propagation = {.mode = Propagation::Fixed, .direction = {0, 1, 0}, .stepsPerSec = d.propagationStepsPerSec, .offset = 1};
    e.textures.cycling = {.mode = Cycling::Ordered, .texturesPerSec = d.texturesPerSec, .rateJitter = 0.25f};
    const Result<std::uint32_t> setId = registerSet(materials, *set);
    if (!setId) return makeError("SteamDesc.textureSet: " + setId.error());
    const std::uint32_t tableId = materials.addColorTable(ColorTable::steam());
    e.layers = {{.style = {.textureSet = *setId, .colorTable = tableId, .textured = true, .crossfade = true, .variation = *variation}}};
    return Effect::fromGrid(std::move(*grid), std::move(e));
}

Result<Effect> gas(Materials& materials, const GasDesc& d) {
    const Result<SplatVariation> variation = seededVariation("GasDesc", d.variation, d.seed);
    if (!variation) return makeError(variation.error());
    if (Status s = checkCount("GasDesc.textureCount", d.textureCount); !s) return makeError(s.error());
    if (!(d.opacity > 0.0f && d.opacity <= 1.0f)) return makeError("GasDesc.opacity must be in (0, 1]");
    if (Status s = checkRate("GasDesc.texturesPerSec", d.texturesPerSec); !s) return makeError(s.error());
    Result<Grid> lattice = Grid::box(glm::ivec3(1), d.spacing); // spacing checked by the grid's own rules
    if (!lattice) return makeError("GasDesc.spacing: " + lattice.error());
    if (glm::any(glm::lessThan(d.dims, glm::ivec3(1)))) return makeError("GasDesc.dims must be at least 1 on every axis");
    lattice->dims = d.dims;
    lattice->voxels.clear();
    lattice->transform = at(d.position); // lattices are centred on x and z (Grid::localPosition): the base centre
    Result<PendingSet> set = resolveSet(materials, d.textureSet, {.count = d.textureCount, .size = 32, .seed = d.textureSeed});
    if (!set) return makeError("GasDesc.textureSet: " + set.error());

    EffectDesc e = gridDesc("gas", materials, d.motion, d.seed);
    e.textures.cycling = {.mode = Cycling::Ordered, .texturesPerSec = d.texturesPerSec, .rateJitter = 0.25f};
    const Result<std::uint32_t> setId = registerSet(materials, *set);
    if (!setId) return makeError("GasDesc.textureSet: " + setId.error());
    const std::uint32_t tableId = materials.addColorTable(ColorTable::steam());
    e.layers = {{.style = {.textureSet = *setId, .colorTable = tableId, .textured = true, .crossfade = true, .opacityScale = d.opacity, .variation = *variation}}};
    return Effect::fromProceduralGas(d.gas, std::move(*lattice), std::move(e));
}

Result<Effect> dust(Materials& materials, const DustDesc& d) {
    const Result<SplatVariation> variation = seededVariation("DustDesc", d.variation, d.seed);
    if (!variation) return makeError(variation.error());
    if (Status s = checkCount("DustDesc.textureCount", d.textureCount); !s) return makeError(s.error());
    if (!(d.sourceRadius > 0.0f)) return makeError("DustDesc.sourceRadius must be > 0");
    if (Status s = checkRate("DustDesc.settle", d.settle); !s) return makeError(s.error());
    if (Status s = checkRate("DustDesc.dissipation", d.dissipation); !s) return makeError(s.error());
    FluidSolverDesc sd{.dims = d.dims,
                       .spacing = d.spacing,
                       .transform = at(d.position),
                       .buoyancy = 1.2f,
                       .weight = d.settle,
                       .windWorld = d.windWorld,
                       .windCoupling = glm::length(d.windWorld) > 0.0f ? 0.5f : 0.0f,
                       .velocityDamping = 0.8f,
                       .densityDissipation = d.dissipation,
                       .temperatureDissipation = 1.5f};
    Result<FluidSolver> solver = FluidSolver::create(sd);
    if (!solver) return makeError("DustDesc: " + solver.error());
    Result<PendingSet> set = resolveSet(materials, d.textureSet, {.count = d.textureCount, .size = 32, .seed = d.textureSeed, .baseFrequency = 2.5f});
    if (!set) return makeError("DustDesc.textureSet: " + set.error());
    solver->addEmitter({.desc = {.offset = d.sourceOffset, .radius = d.sourceRadius, .density = 1.0f, .temperature = 0.6f, .rate = 5.0f},
                        .motion = restingAt(d.sourceMotion, d.position)});
    if (Status st = addObstacles(*solver, d.obstacles, "DustDesc"); !st) return makeError(st.error());

    EffectDesc e = gridDesc("dust", materials, Motion{}, d.seed);
    e.textures.propagation = {.mode = Propagation::Velocity, .offset = 1};
    e.textures.cycling = {.mode = Cycling::Ordered, .texturesPerSec = 3.0f, .rateJitter = 0.3f};
    e.sparse = {.opacityPerDensity = 0.5f, .minOpacity = 0.02f, .color = ColorSource::Density};
    const Result<std::uint32_t> setId = registerSet(materials, *set);
    if (!setId) return makeError("DustDesc.textureSet: " + setId.error());
    const std::uint32_t tableId = materials.addColorTable(ColorTable::dust());
    e.layers = {{.style = {.textureSet = *setId, .colorTable = tableId, .textured = true, .crossfade = true, .variation = *variation}}};
    return Effect::fromSolver(std::move(*solver), std::move(e));
}

Result<Effect> fireToSmoke(Materials& materials, const FireToSmokeDesc& d) {
    const Result<SplatVariation> variation = seededVariation("FireToSmokeDesc", d.variation, d.seed);
    if (!variation) return makeError(variation.error());
    if (!(d.split > 0.0f && d.split < 1.0f)) return makeError("FireToSmokeDesc.split must be in (0, 1), got " + std::to_string(d.split));
    if (!(d.blend >= 0.0f && d.blend < 1.0f)) return makeError("FireToSmokeDesc.blend must be in [0, 1), got " + std::to_string(d.blend));
    if (Status s = checkRate("FireToSmokeDesc.texturesPerSec", d.texturesPerSec); !s) return makeError(s.error());
    Result<Grid> grid = Grid::box(d.dims, d.spacing);
    if (!grid) return makeError("FireToSmokeDesc.dims/spacing: " + grid.error());
    Result<PendingSet> fireSet = resolveSet(materials, d.fireTextureSet, {.count = 8, .size = 32, .seed = d.textureSeed});
    if (!fireSet) return makeError("FireToSmokeDesc.fireTextureSet: " + fireSet.error());
    Result<PendingSet> smokeSet =
        resolveSet(materials, d.smokeTextureSet, {.count = 8, .size = 32, .seed = d.textureSeed + 1, .baseFrequency = 2.0f});
    if (!smokeSet) return makeError("FireToSmokeDesc.smokeTextureSet: " + smokeSet.error());

    // Flame below the split; above it a plume that widens and thins.
    for (Voxel& v : grid->voxels) {
        const float h = v.cell.y / float(std::max(d.dims.y - 1, 1));
        if (h < d.split) {
            v.opacity = 0.55f * flameOpacity(v.cell, grid->dims, d.split * 1.6f);
        } else {
            const float u = (h - d.split) / (1.0f - d.split);
            const float rx = (v.cell.x - 0.5f * (d.dims.x - 1)) / (0.5f * d.dims.x);
            const float rz = (v.cell.z - 0.5f * (d.dims.z - 1)) / (0.5f * d.dims.z);
            const float r = std::sqrt(rx * rx + rz * rz);
            const float width = 0.45f + 0.55f * u;
            v.opacity = 0.35f * (1.0f - 0.7f * u) * std::clamp((width - r) / 0.3f + 0.3f, 0.0f, 1.0f);
        }
    }
    grid->transform = at(d.position);

    EffectDesc e = gridDesc("fireToSmoke", materials, d.motion, d.seed);
    e.textures.propagation = {.mode = Propagation::Fixed, .direction = {0, 1, 0}, .stepsPerSec = d.propagationStepsPerSec, .offset = 1};
    e.textures.cycling = {.mode = Cycling::Ordered, .texturesPerSec = d.texturesPerSec, .rateJitter = 0.2f};
    // sec. 2 step 4: "mixing effects, such as smoke and fire, can be achieved
    // with multiple color tables and differing texture sets".
    const Result<std::uint32_t> fireId = registerSet(materials, *fireSet);
    if (!fireId) return makeError("FireToSmokeDesc.fireTextureSet: " + fireId.error());
    const Result<std::uint32_t> smokeId = registerSet(materials, *smokeSet);
    if (!smokeId) return makeError("FireToSmokeDesc.smokeTextureSet: " + smokeId.error());
    const std::uint32_t fireLut = materials.addColorTable(ColorTable::fire());
    const std::uint32_t smokeLut = materials.addColorTable(ColorTable::smoke());
    e.layers = {
        {.style = {.textureSet = *fireId, .colorTable = fireLut, .textured = true, .crossfade = true, .variation = *variation},
         .heightFrom = 0.0f,
         .heightTo = d.split,
         .blend = d.blend,
         .remapColor = true},
        {.style = {.textureSet = *smokeId, .colorTable = smokeLut, .textured = true, .crossfade = true, .variation = *variation},
         .heightFrom = d.split,
         .heightTo = 1.0f,
         .blend = d.blend,
         .remapColor = true},
    };
    return Effect::fromGrid(std::move(*grid), std::move(e));
}

TextureSet proceduralFaces(int count, int size, std::uint32_t seed) {
    TextureSet set;
    set.size = size;
    set.color = false;
    for (int i = 0; i < count; ++i) {
        auto rnd = [&](std::uint32_t salt) { return hashUnit(hashCell({i, 0, 0}, seed, salt)); };
        const float headW = 0.55f + 0.12f * rnd(1), headH = 0.75f + 0.1f * rnd(2);
        const float eyeX = 0.2f + 0.08f * rnd(3), eyeY = -0.15f - 0.1f * rnd(4), eyeR = 0.09f + 0.06f * rnd(5);
        const float mouthY = 0.35f + 0.1f * rnd(6), mouthW = 0.12f + 0.15f * rnd(7), mouthH = 0.05f + 0.12f * rnd(8);
        const float tilt = 0.3f * (rnd(9) - 0.5f);
        std::vector<float> px(std::size_t(size) * size * 4);
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                // Row 0 is the top of the splat; v grows downwards.
                float u = (x + 0.5f) / size * 2.0f - 1.0f, v = (y + 0.5f) / size * 2.0f - 1.0f;
                const float cu = std::cos(tilt) * u - std::sin(tilt) * v, cv = std::sin(tilt) * u + std::cos(tilt) * v;
                u = cu, v = cv;
                auto ellipse = [](float a, float b) { return a * a + b * b; };
                const float head = ellipse(u / headW, v / headH);
                float a = std::clamp((1.0f - head) / 0.25f, 0.0f, 1.0f);
                const float eye =
                    std::min(ellipse((u - eyeX) / eyeR, (v - eyeY) / (1.3f * eyeR)), ellipse((u + eyeX) / eyeR, (v - eyeY) / (1.3f * eyeR)));
                const float mouth = ellipse(u / mouthW, (v - mouthY) / mouthH);
                a *= std::clamp((std::min(eye, mouth) - 0.6f) / 0.4f, 0.08f, 1.0f);
                float* p = &px[(std::size_t(y) * size + x) * 4];
                p[0] = p[1] = p[2] = 1.0f;
                p[3] = a;
            }
        set.layers.push_back(std::move(px));
    }
    return set;
}

Result<Effect> ghosts(Materials& materials, const GhostsDesc& d) {
    const Result<SplatVariation> variation = seededVariation("GhostsDesc", d.variation, d.seed);
    if (!variation) return makeError(variation.error());
    if (!(d.headRadiusCells >= 1.0f && d.headRadiusCells <= 64.0f))
        return makeError("GhostsDesc.headRadiusCells must be in [1, 64], got " + std::to_string(d.headRadiusCells));
    if (d.plumeCells < 0 || d.plumeCells > 256) return makeError("GhostsDesc.plumeCells must be in [0, 256], got " + std::to_string(d.plumeCells));
    if (Status s = checkCount("GhostsDesc.textureCount", d.textureCount); !s) return makeError(s.error());
    if (Status s = checkUnit("GhostsDesc.opacity", d.opacity); !s) return makeError(s.error());
    if (Status s = checkRate("GhostsDesc.texturesPerSec", d.texturesPerSec); !s) return makeError(s.error());
    PendingSet set;
    if (!d.textureSet) {
        set.key = "faces(count=" + std::to_string(d.textureCount) + ",size=32,seed=" + std::to_string(d.textureSeed) + ")";
        set.id = materials.findTextureSet(set.key);
        if (!set.id) set.set = proceduralFaces(d.textureCount, 32, d.textureSeed);
    } else {
        // Faces keep their colour; the set is shared by content.
        if (d.textureSet->layers.empty() || d.textureSet->size < 1) return makeError("GhostsDesc.textureSet: the texture set has no textures");
        set.set = *d.textureSet;
    }

    // A head-sized ball of voxels with a thinning column of faces above it.
    const int r = int(std::floor(d.headRadiusCells));
    const glm::ivec3 dims{2 * r + 1, 2 * r + 1 + d.plumeCells, 2 * r + 1};
    std::vector<float> opacity(std::size_t(dims.x) * dims.y * dims.z, 0.0f);
    std::size_t i = 0;
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x, ++i) {
                const glm::vec3 p = glm::vec3(x - r, y - r, z - r);
                const float head = glm::length(p) / d.headRadiusCells;
                if (head <= 1.0f) {
                    opacity[i] = d.opacity * (0.6f + 0.4f * head); // faces cloud the surface more than the core
                } else if (y > r && d.plumeCells > 0) {
                    const float u = float(y - r) / float(r + d.plumeCells);
                    const float width = d.headRadiusCells * (1.0f - 0.6f * u);
                    if (glm::length(glm::vec2(p.x, p.z)) <= width) opacity[i] = d.opacity * (1.0f - u) * (1.0f - u);
                }
            }
    Result<Grid> grid = Grid::fromDense(dims, opacity, d.spacing);
    if (!grid) return makeError("GhostsDesc: " + grid.error());
    grid->transform = at(d.position);

    EffectDesc e = gridDesc("ghosts", materials, Motion{}, d.seed);
    e.textures.propagation = {.mode = Propagation::Fixed, .direction = {0, 1, 0}, .stepsPerSec = d.propagationStepsPerSec, .offset = 1};
    // sec. 5.3 / Fig. 10: faces chosen at random (sec. 3.3's surprising result).
    e.textures.cycling = {.mode = Cycling::Random, .texturesPerSec = d.texturesPerSec, .rateJitter = 0.4f};
    const Result<std::uint32_t> setId = registerSet(materials, set);
    if (!setId) return makeError("GhostsDesc.textureSet: " + setId.error());
    const std::uint32_t tableId = materials.addColorTable(
        ColorTable::gradient({{0.0f, {0.75f, 0.85f, 1.0f, 1.0f}}, {0.6f, {0.7f, 0.8f, 1.0f, 0.8f}}, {1.0f, {0.6f, 0.7f, 0.9f, 0.0f}}}));
    e.layers = {{.style = {.textureSet = *setId, .colorTable = tableId, .textured = true, .crossfade = false, .variation = *variation}}};
    return Effect::fromGrid(std::move(*grid), std::move(e));
}

Result<Effect> embers(Materials& materials, const EmbersDesc& d) {
    const Result<SplatVariation> variation = seededVariation("EmbersDesc", d.variation, d.seed);
    if (!variation) return makeError(variation.error());
    if (Status s = checkCount("EmbersDesc.textureCount", d.textureCount); !s) return makeError(s.error());
    if (!(d.warmUpSec >= 0.0f) || !std::isfinite(d.warmUpSec)) return makeError("EmbersDesc.warmUpSec must be finite and >= 0");
    const ParticleEmitterDesc e{.position = d.position,
                                .halfExtent = d.halfExtent,
                                .ratePerSec = d.ratePerSec,
                                .startSec = -double(d.warmUpSec),
                                .velocity = d.velocity,
                                .velocitySpread = d.velocitySpread,
                                .lifetimeSec = d.lifetimeSec,
                                .lifetimeJitter = d.lifetimeJitter,
                                .acceleration = d.acceleration,
                                .dragPerSec = d.dragPerSec,
                                .wind = d.wind,
                                .sizeWorld = d.sizeWorld,
                                .sizeEndWorld = d.sizeEndWorld,
                                .opacity = d.opacity,
                                .fadeIn = 0.05f,
                                .fadeOut = 0.5f,
                                .colorFrom = 0.15f, // past the table's white base: embers glow yellow-orange, then redden and darken
                                .colorTo = 0.95f,
                                .texturesPerSec = d.texturesPerSec,
                                .stretchPerSpeed = d.stretchPerSpeed,
                                .maxStretch = 3.0f,
                                .seed = d.seed};
    if (std::string err = checkParticleEmitter(e, "EmbersDesc."); !err.empty()) return makeError(err);
    Result<PendingSet> set = resolveSet(materials, d.textureSet, {.count = d.textureCount, .size = 32, .seed = d.textureSeed, .contrast = 2.5f});
    if (!set) return makeError("EmbersDesc.textureSet: " + set.error());
    EffectDesc ed = gridDesc("embers", materials, d.motion, d.seed);
    const Result<std::uint32_t> setId = registerSet(materials, *set);
    if (!setId) return makeError("EmbersDesc.textureSet: " + setId.error());
    const std::uint32_t tableId = materials.addColorTable(ColorTable::fire());
    ed.layers = {{.style = {.textureSet = *setId, .colorTable = tableId, .textured = true, .crossfade = true, .variation = *variation}}};
    return Effect::fromParticles(e, std::move(ed));
}

} // namespace splatfx::presets
