// The mixed scheduling level (issue 24 item 4), shared by
// `splatfx-bench scheduling --mixed` and tests/scene/mixed_level_gl_test.cpp:
// every kind a Scene holds (grid, solver and procedural-gas effects, LOD
// clouds, ground fog layers, the scene fog's terms; lit and shadow-casting
// effects under a sun), a few in front of the camera and one lit plume out of
// view whose shadow falls into it, the rest spread around and far away.
// Public API only; deterministic (every item seeded by its index).
#pragma once

#include <cmath>
#include <functional>
#include <string>

#include <glm/glm.hpp>

#include "splatfx/presets.hpp"
#include "splatfx/scene.hpp"
#include "splatfx/volume.hpp"

namespace bench {

// Effects, clouds and layers are simulated and drawn up to this far (world units).
inline constexpr float kMixedRange = 150.0f;
// Items 0..kMixedInView-1 are in front of the camera or shadow it; the rest are spread around.
inline constexpr int kMixedInView = 7;

inline splatfx::Camera mixedCamera(glm::ivec2 size) {
    return splatfx::Camera::lookAt({0, 6, 40}, {0, 4, 0}, {0, 1, 0}, glm::radians(50.0f), size, 0.1f, 1000.0f);
}

// The sun: travelling along +x and down, so a plume left of the view shadows the ground in it.
inline splatfx::Light mixedSun() { return splatfx::Light::directional({1.0f, -1.0f, 0.2f}, glm::vec3(1.0f), 1.2f); }

// The lighting every lit item gets: low albedo, self-shadowed by a small table, casting on the scene.
inline splatfx::EffectLighting mixedLighting() {
    return {.enabled = true, .gas = {.albedo = 0.7f, .ambient = glm::vec3(0.25f)}, .selfShadow = splatfx::SelfShadow::Table, .tableDims = glm::ivec3(16)};
}

// Where item i stands, and which kind it is: 0 fire, 1 steam, 2 smoke solver (lit),
// 3 fire to smoke, 4 procedural gas (lit), 5 clouds, 6 ground fog.
struct MixedItem {
    int kind = 0;
    glm::vec3 at{0.0f};
};

inline MixedItem mixedItem(int i, int count) {
    switch (i) { // in view, left to right; one cloud deck behind; ground fog under them; the plume out of view
    case 0: return {0, {-9.0f, 0.0f, 0.0f}};
    case 1: return {2, {-4.0f, 0.0f, 2.0f}};
    case 2: return {4, {2.0f, 0.0f, 4.0f}};
    case 3: return {1, {7.0f, 0.0f, 0.0f}};
    case 4: return {5, {-20.0f, 18.0f, -40.0f}};
    case 5: return {6, {-20.0f, -1.0f, -20.0f}};
    case 6: return {2, {-42.0f, 14.0f, 6.0f}}; // left of the view, high: its shadow falls into it
    default: break;
    }
    // Golden-angle spread as the 1000-effect level: beyond the range inside the view wedge, elsewhere
    // 60 to 400 units away (culled by range or by the frustum). Clouds and ground fog are rarer.
    const float angle = std::fmod(2.399963f * float(i), 6.2831853f) - 3.1415927f; // 0 = straight ahead (-z)
    const bool ahead = std::abs(angle) < 1.0f;
    const float r = ahead ? kMixedRange + 20.0f + 250.0f * float(i) / float(count) : 60.0f + 340.0f * float(i) / float(count);
    const glm::vec3 at{r * std::sin(angle), 0.0f, 40.0f - r * std::cos(angle)};
    const int kind = i % 40 == 7 ? 5 : i % 40 == 27 ? 6 : i % 5; // kinds 0..4, a cloud and a fog layer per 40
    return {kind, at};
}

// Adds item i to `scene`. `name` is the item's name in both scenes the bench compares.
inline splatfx::Status addMixedItem(splatfx::Scene& scene, splatfx::Materials& m, int i, int count) {
    const MixedItem it = mixedItem(i, count);
    const std::uint32_t seed = std::uint32_t(i + 1);
    const std::string name = "item " + std::to_string(i);
    splatfx::EffectOptions o{.name = name, .rangeWorld = kMixedRange};
    splatfx::Result<splatfx::Effect> e = splatfx::makeError("no effect");
    switch (it.kind) {
    case 0: e = splatfx::presets::fire(m, {.position = it.at, .seed = seed}); break;
    case 1: e = splatfx::presets::steam(m, {.position = it.at, .seed = seed}); break;
    case 2:
        e = splatfx::presets::smoke(m, {.dims = {6, 12, 6}, .position = it.at, .seed = seed});
        o.lighting = mixedLighting();
        break;
    case 3: e = splatfx::presets::fireToSmoke(m, {.position = it.at, .seed = seed}); break;
    case 4:
        e = splatfx::presets::gas(m, {.dims = {12, 12, 12}, .spacing = glm::vec3(0.25f), .position = it.at, .seed = seed});
        o.lighting = mixedLighting();
        break;
    case 5: {
        splatfx::CloudDesc cd;
        cd.dims = {17, 17, 9};
        cd.seed = seed;
        auto field = splatfx::makeCloudVolume(cd);
        if (!field) return splatfx::makeError(name + ": " + field.error());
        auto vol = splatfx::LodVolume::create(*field, {.originWorld = it.at, .spacingWorld = 2.0f});
        auto tf = splatfx::makeCloudTransfer({.maxExtinctionPerWorld = 0.5f});
        if (!vol || !tf) return splatfx::makeError(name + ": " + (vol ? tf.error() : vol.error()));
        const float longest = std::sqrt(3.0f) * float(1 << vol->rootLevel()) * vol->spacingWorld();
        auto table = splatfx::PreIntegrationTable::create(*tf, {.maxLengthWorld = longest});
        if (!table) return splatfx::makeError(name + ": " + table.error());
        scene.add(std::move(*vol), std::move(*tf), std::move(*table), o);
        return {};
    }
    default: {
        splatfx::GroundFogDesc d;
        d.dims = {17, 17};
        d.originWorld = it.at;
        d.spacingWorld = 2.5f;
        for (int z = 0; z < 17; ++z)
            for (int x = 0; x < 17; ++x) {
                d.terrainHeight.push_back(it.at.y + 0.8f * std::sin(0.7f * float(x)) * std::cos(0.5f * float(z)));
                d.fogTop.push_back(it.at.y + 1.2f);
            }
        auto fog = splatfx::GroundFog::create(d);
        auto tf = splatfx::makeGroundFogTransfer({0.85f, 0.88f, 0.92f}, 0.4f);
        if (!fog || !tf) return splatfx::makeError(name + ": " + (fog ? tf.error() : fog.error()));
        auto table = splatfx::PreIntegrationTable::create(*tf, {.scalarResolution = 32, .lengthResolution = 64, .maxLengthWorld = 12.0f});
        if (!table) return splatfx::makeError(name + ": " + table.error());
        scene.add(std::move(*fog), std::move(*tf), std::move(*table), o);
        return {};
    }
    }
    if (!e) return splatfx::makeError(name + ": " + e.error());
    scene.add(std::move(*e), o);
    return {};
}

// The scene fog: a thin haze, two potentials in view, and one per 10 items far around the level.
inline splatfx::FogDesc mixedFog(int count) {
    splatfx::FogDesc d;
    d.colour = {0.6, 0.62, 0.66};
    d.terms.push_back(splatfx::FogTerm::constant(0.002));
    d.terms.push_back(splatfx::FogTerm::point(0.05, {-6.0, 1.0, 0.0}, 1.0, 0.5));
    d.terms.push_back(splatfx::FogTerm::sphere(0.04, {5.0, 0.0, -6.0}, 3.0, 1.0, 1.0));
    for (int i = kMixedInView; i < count; i += 10) {
        const MixedItem it = mixedItem(i, count);
        d.terms.push_back(splatfx::FogTerm::point(0.05, glm::dvec3(it.at) + glm::dvec3(3000.0, 0.0, 3000.0) * double(i % 2), 1.0, 4.0));
    }
    return d;
}

// Fills `scene` with the items `keep(i)` accepts, the sun and the scene shadow; no fog.
inline splatfx::Status buildMixedLevel(splatfx::Scene& scene, splatfx::Materials& m, int count, const std::function<bool(int)>& keep) {
    for (int i = 0; i < count; ++i)
        if (keep(i))
            if (splatfx::Status s = addMixedItem(scene, m, i, count); !s) return s;
    if (auto l = scene.addLight(mixedSun()); !l) return splatfx::makeError(l.error());
    scene.setSceneShadow({.dims = glm::ivec3(32)});
    return {};
}

} // namespace bench
