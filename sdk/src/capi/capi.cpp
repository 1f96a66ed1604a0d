// splatfx_c.h, the GL-free half: errors, materials, texture sets, the scene and its presets, cameras, frames.
#include <cmath>
#include <cstdio>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

#include "capi/capi_internal.hpp"
#include "grid/number_text.hpp"
#include "splatfx/presets.hpp"
#include "splatfx/scene_file.hpp"
#include "splatfx/texture_set_io.hpp"

using namespace splatfx;
using namespace splatfx::capi;
using grid_detail::str;

namespace {

// Viewport sides the C API accepts: GL 4.5 guarantees 16384 as GL_MAX_VIEWPORT_DIMS.
constexpr std::int32_t kMaxViewportSide = 16384;

std::optional<Outcome> checkFinite(const std::string& field, float v) {
    if (!std::isfinite(v)) return invalid(field + " is " + str(v) + "; expected a finite number");
    return std::nullopt;
}
std::optional<Outcome> checkFinite3(const std::string& field, const float v[3]) {
    for (int i = 0; i < 3; ++i)
        if (auto bad = checkFinite(field + "[" + std::to_string(i) + "]", v[i])) return bad;
    return std::nullopt;
}
glm::vec3 vec3Of(const float v[3]) { return {v[0], v[1], v[2]}; }
glm::ivec3 ivec3Of(const std::int32_t v[3]) { return {v[0], v[1], v[2]}; }
void store3(float out[3], glm::vec3 v) {
    out[0] = v.x;
    out[1] = v.y;
    out[2] = v.z;
}
void store3(std::int32_t out[3], glm::ivec3 v) {
    out[0] = v.x;
    out[1] = v.y;
    out[2] = v.z;
}

std::optional<Outcome> setTextureSet(const std::string& field, const splatfx_texture_set* given, std::optional<TextureSet>& out) {
    if (!given) return std::nullopt;
    if (auto bad = checkHandle(given, Magic::TextureSet, field.c_str(), "splatfx_texture_set")) return bad;
    out = given->value;
    return std::nullopt;
}

// A C keyframe track to a Motion; Motion::create checks the keys (its message names the key and field).
std::optional<Outcome> toMotion(const std::string& field, const splatfx_keyframe* keys, std::uint32_t count, Motion& out) {
    if (count == 0) return std::nullopt;
    if (!keys) return invalid(field + "_keys is NULL but " + field + "_key_count is " + std::to_string(count));
    constexpr std::uint32_t kMaxKeys = 1u << 20; // a track, not a baked simulation: 10^6 keys is already hours at 240 Hz
    if (count > kMaxKeys) return invalid(field + "_key_count is " + std::to_string(count) + "; expected at most " + std::to_string(kMaxKeys));
    std::vector<Keyframe> track;
    track.reserve(count);
    for (std::uint32_t i = 0; i < count; ++i) {
        const splatfx_keyframe& k = keys[i];
        const std::string at = field + "_keys[" + std::to_string(i) + "]";
        if (!std::isfinite(k.time_sec)) return invalid(at + ".time_sec is " + str(float(k.time_sec)) + "; expected a finite number");
        if (k.easing != SPLATFX_EASING_LINEAR && k.easing != SPLATFX_EASING_SMOOTH && k.easing != SPLATFX_EASING_STEP)
            return invalid(at + ".easing is " + std::to_string(int(k.easing)) + "; expected a splatfx_easing value");
        Keyframe key;
        key.timeSec = k.time_sec;
        key.pose.position = vec3Of(k.position);
        key.pose.rotation = glm::quat(k.rotation[0], k.rotation[1], k.rotation[2], k.rotation[3]);
        key.pose.scale = vec3Of(k.scale);
        key.pose.opacity = k.opacity;
        key.pose.growth = k.growth;
        key.easing = k.easing == SPLATFX_EASING_SMOOTH ? Easing::Smooth : k.easing == SPLATFX_EASING_STEP ? Easing::Step : Easing::Linear;
        track.push_back(key);
    }
    Result<Motion> motion = Motion::create(std::move(track));
    if (!motion) return invalid(field + ": " + motion.error());
    out = std::move(*motion);
    return std::nullopt;
}

std::optional<Outcome> toEffectOptions(const splatfx_effect_options* given, EffectOptions& out) {
    splatfx_effect_options o;
    splatfx_effect_options_init(&o);
    if (given) o = *given;
    if (!(o.range_world > 0.0f)) // NaN fails too; +inf is "no limit"
        return invalid("options.range_world is " + str(o.range_world) + "; expected > 0 (INFINITY: no limit)");
    if (!(o.opacity_scale >= 0.0f && o.opacity_scale <= 1000.0f))
        return invalid("options.opacity_scale is " + str(o.opacity_scale) + "; expected a number in [0, 1000]");
    out.name = o.name ? o.name : "";
    out.rangeWorld = o.range_world;
    out.enabled = o.enabled != 0;
    out.draw.textured = o.textured != 0;
    out.draw.opacityScale = o.opacity_scale;
    return std::nullopt;
}

// A scene's effects index the materials they were built with.
std::optional<Outcome> checkSceneMaterials(const splatfx_scene& scene, const splatfx_materials& materials) {
    if (!scene.hasMaterials) return std::nullopt;
    const std::shared_ptr<int> own = scene.materials.lock();
    if (own == materials.identity) return std::nullopt;
    return invalid(own ? "materials are not the ones this scene's effects were built with (their texture sets and colour "
                         "tables are registered there); use one splatfx_materials per scene"
                       : "the materials this scene's effects were built with were destroyed");
}

// The shared tail of every splatfx_scene_add_<preset>: check the handles, build, add.
template <class Build>
Outcome addPreset(splatfx_scene* scene, splatfx_materials* materials, const splatfx_effect_options* options, std::uint32_t* outId, Build&& build) {
    if (auto bad = checkHandle(scene, Magic::Scene, "scene", "splatfx_scene")) return *bad;
    if (auto bad = checkHandle(materials, Magic::Materials, "materials", "splatfx_materials")) return *bad;
    if (auto bad = checkSceneMaterials(*scene, *materials)) return *bad;
    EffectOptions opts;
    if (auto bad = toEffectOptions(options, opts)) return *bad;
    Outcome failed;
    std::optional<Effect> effect = build(materials->value, failed);
    if (!effect) return failed;
    scene->effects.push_back(scene->value.add(std::move(*effect), std::move(opts)));
    scene->materials = materials->identity;
    scene->hasMaterials = true;
    if (outId) *outId = std::uint32_t(scene->effects.size() - 1);
    return success();
}

std::optional<Effect> fromResult(Result<Effect> r, Outcome& failed) {
    if (!r) {
        failed = invalid(r.error());
        return std::nullopt;
    }
    return std::move(*r);
}

std::optional<Outcome> checkCamera(const splatfx_camera& c, const std::string& param) {
    for (int i = 0; i < 16; ++i) {
        if (auto bad = checkFinite(param + ".view[" + std::to_string(i) + "]", c.view[i])) return bad;
        if (auto bad = checkFinite(param + ".proj[" + std::to_string(i) + "]", c.proj[i])) return bad;
    }
    for (int i = 0; i < 2; ++i)
        if (c.viewport[i] < 1 || c.viewport[i] > kMaxViewportSide)
            return invalid(param + ".viewport[" + std::to_string(i) + "] is " + std::to_string(c.viewport[i]) + "; expected a size in [1, " +
                           std::to_string(kMaxViewportSide) + "] pixels");
    // The eye and the frustum come from the inverses: a singular matrix has neither.
    const double dv = glm::determinant(glm::dmat4(glm::make_mat4(c.view)));
    if (!(std::abs(dv) > 1e-12) || !std::isfinite(dv))
        return invalid(param + ".view is singular (determinant " + str(float(dv)) + "); expected an invertible world-to-view matrix");
    const double dp = glm::determinant(glm::dmat4(glm::make_mat4(c.proj)));
    if (!(std::abs(dp) > 0.0) || !std::isfinite(dp))
        return invalid(param + ".proj is singular (determinant " + str(float(dp)) + "); expected an invertible projection");
    return std::nullopt;
}

Camera toCamera(const splatfx_camera& c) {
    return Camera::fromMatrices(glm::make_mat4(c.view), glm::make_mat4(c.proj), {c.viewport[0], c.viewport[1]});
}

// ---- presets ----
//
// Each preset's C fields are listed once (FireFields and the others below); the list drives
// both directions: desc_init copies the C++ descriptor's defaults out
// (DefaultsOut), add copies the C fields in (FieldsIn), checking that every
// float is finite and every handle valid. The presets validate their own
// ranges (messages name the C++ field, FireDesc.textureCount for
// texture_count); the C layer adds what the C++ types cannot carry wrong.

// C++ defaults into a C desc.
struct DefaultsOut {
    void operator()(const char*, std::int32_t (&c)[3], glm::ivec3 d) { store3(c, d); }
    void operator()(const char*, float (&c)[3], glm::vec3 d) { store3(c, d); }
    void operator()(const char*, const splatfx_texture_set*& c, const std::optional<TextureSet>&) { c = nullptr; }
    template <class C, class D>
    void operator()(const char*, C& c, const D& d) {
        c = C(d);
    }
    void motion(const char*, const splatfx_keyframe*& keys, std::uint32_t& count, const Motion&) { keys = nullptr, count = 0; }
};

// A C desc into its C++ descriptor; the first bad field is kept in `bad`.
struct FieldsIn {
    std::optional<Outcome> bad;
    static std::string field(const char* name) { return std::string("desc.") + name; }
    void operator()(const char*, const std::int32_t (&c)[3], glm::ivec3& d) { d = ivec3Of(c); }
    void operator()(const char* name, const float (&c)[3], glm::vec3& d) {
        if (!bad) bad = checkFinite3(field(name), c);
        d = vec3Of(c);
    }
    void operator()(const char* name, const splatfx_texture_set* const& c, std::optional<TextureSet>& d) {
        if (!bad) bad = setTextureSet(field(name), c, d);
    }
    template <class C, class D>
    void operator()(const char* name, const C& c, D& d) {
        if constexpr (std::is_floating_point_v<C>)
            if (!bad) bad = checkFinite(field(name), c);
        d = D(c);
    }
    void motion(const char* name, const splatfx_keyframe* const& keys, const std::uint32_t& count, Motion& d) {
        if (!bad) bad = toMotion(field(name), keys, count, d);
    }
};

// <Preset>Fields{}(v, c, d) visits every C field of one preset with its C++
// counterpart; C and D are the C and C++ descs, either of them const.
struct FireFields {
    template <class V, class C, class D>
    void operator()(V& v, C& c, D& d) const {
        v("dims", c.dims, d.dims), v("spacing", c.spacing, d.spacing), v("position", c.position, d.position);
        v("texture_set", c.texture_set, d.textureSet), v("texture_count", c.texture_count, d.textureCount);
        v("opacity", c.opacity, d.opacity), v("propagation_steps_per_sec", c.propagation_steps_per_sec, d.propagationStepsPerSec);
        v("textures_per_sec", c.textures_per_sec, d.texturesPerSec), v("crossfade", c.crossfade, d.crossfade);
        v.motion("motion", c.motion_keys, c.motion_key_count, d.motion);
        v("seed", c.seed, d.seed), v("texture_seed", c.texture_seed, d.textureSeed);
    }
};
struct SmokeFields {
    template <class V, class C, class D>
    void operator()(V& v, C& c, D& d) const {
        v("dims", c.dims, d.dims), v("spacing", c.spacing, d.spacing), v("position", c.position, d.position);
        v("source_offset", c.source_offset, d.sourceOffset), v("source_radius", c.source_radius, d.sourceRadius);
        v("wind_world", c.wind_world, d.windWorld), v("dissipation", c.dissipation, d.dissipation);
        v("texture_set", c.texture_set, d.textureSet), v("texture_count", c.texture_count, d.textureCount);
        v("textures_per_sec", c.textures_per_sec, d.texturesPerSec), v("substeps", c.substeps, d.substeps);
        v.motion("source_motion", c.source_motion_keys, c.source_motion_key_count, d.sourceMotion);
        v("seed", c.seed, d.seed), v("texture_seed", c.texture_seed, d.textureSeed);
    }
};
struct SteamFields {
    template <class V, class C, class D>
    void operator()(V& v, C& c, D& d) const {
        v("dims", c.dims, d.dims), v("spacing", c.spacing, d.spacing), v("position", c.position, d.position);
        v("texture_set", c.texture_set, d.textureSet), v("texture_count", c.texture_count, d.textureCount);
        v("opacity", c.opacity, d.opacity), v("propagation_steps_per_sec", c.propagation_steps_per_sec, d.propagationStepsPerSec);
        v("textures_per_sec", c.textures_per_sec, d.texturesPerSec);
        v.motion("motion", c.motion_keys, c.motion_key_count, d.motion);
        v("seed", c.seed, d.seed), v("texture_seed", c.texture_seed, d.textureSeed);
    }
};
struct DustFields {
    template <class V, class C, class D>
    void operator()(V& v, C& c, D& d) const {
        v("dims", c.dims, d.dims), v("spacing", c.spacing, d.spacing), v("position", c.position, d.position);
        v("source_offset", c.source_offset, d.sourceOffset), v("source_radius", c.source_radius, d.sourceRadius);
        v("wind_world", c.wind_world, d.windWorld), v("settle", c.settle, d.settle), v("dissipation", c.dissipation, d.dissipation);
        v("texture_set", c.texture_set, d.textureSet), v("texture_count", c.texture_count, d.textureCount);
        v.motion("source_motion", c.source_motion_keys, c.source_motion_key_count, d.sourceMotion);
        v("seed", c.seed, d.seed), v("texture_seed", c.texture_seed, d.textureSeed);
    }
};
struct FireToSmokeFields {
    template <class V, class C, class D>
    void operator()(V& v, C& c, D& d) const {
        v("dims", c.dims, d.dims), v("spacing", c.spacing, d.spacing), v("position", c.position, d.position);
        v("split", c.split, d.split), v("blend", c.blend, d.blend);
        v("fire_texture_set", c.fire_texture_set, d.fireTextureSet), v("smoke_texture_set", c.smoke_texture_set, d.smokeTextureSet);
        v("propagation_steps_per_sec", c.propagation_steps_per_sec, d.propagationStepsPerSec);
        v("textures_per_sec", c.textures_per_sec, d.texturesPerSec);
        v.motion("motion", c.motion_keys, c.motion_key_count, d.motion);
        v("seed", c.seed, d.seed), v("texture_seed", c.texture_seed, d.textureSeed);
    }
};
struct GhostsFields {
    template <class V, class C, class D>
    void operator()(V& v, C& c, D& d) const {
        v("head_radius_cells", c.head_radius_cells, d.headRadiusCells), v("plume_cells", c.plume_cells, d.plumeCells);
        v("spacing", c.spacing, d.spacing), v("position", c.position, d.position);
        v("texture_set", c.texture_set, d.textureSet), v("texture_count", c.texture_count, d.textureCount);
        v("opacity", c.opacity, d.opacity), v("textures_per_sec", c.textures_per_sec, d.texturesPerSec);
        v("propagation_steps_per_sec", c.propagation_steps_per_sec, d.propagationStepsPerSec);
        v("seed", c.seed, d.seed), v("texture_seed", c.texture_seed, d.textureSeed);
    }
};

struct EmbersFields {
    template <class V, class C, class D>
    void operator()(V& v, C& c, D& d) const {
        v("position", c.position, d.position), v("half_extent", c.half_extent, d.halfExtent), v("rate_per_sec", c.rate_per_sec, d.ratePerSec);
        v("warm_up_sec", c.warm_up_sec, d.warmUpSec), v("lifetime_sec", c.lifetime_sec, d.lifetimeSec);
        v("lifetime_jitter", c.lifetime_jitter, d.lifetimeJitter), v("velocity", c.velocity, d.velocity);
        v("velocity_spread", c.velocity_spread, d.velocitySpread), v("acceleration", c.acceleration, d.acceleration);
        v("drag_per_sec", c.drag_per_sec, d.dragPerSec), v("wind", c.wind, d.wind), v("size_world", c.size_world, d.sizeWorld);
        v("size_end_world", c.size_end_world, d.sizeEndWorld), v("opacity", c.opacity, d.opacity);
        v("stretch_per_speed", c.stretch_per_speed, d.stretchPerSpeed), v("textures_per_sec", c.textures_per_sec, d.texturesPerSec);
        v("texture_set", c.texture_set, d.textureSet), v("texture_count", c.texture_count, d.textureCount);
        v.motion("motion", c.motion_keys, c.motion_key_count, d.motion);
        v("seed", c.seed, d.seed), v("texture_seed", c.texture_seed, d.textureSeed);
    }
};

template <class CDesc, class Desc, class Fields>
void initPresetDesc(CDesc* desc, Fields fields) {
    if (!desc) return;
    const Desc d{};
    DefaultsOut out;
    fields(out, *desc, d);
}

// The body of every splatfx_scene_add_<preset>: defaults, the caller's desc
// in, `extra` checks (a std::optional<Outcome>(const Desc&)), build, add.
template <class Desc, class CDesc, class Init, class Fields, class Build, class Extra>
splatfx_status addPresetC(const char* function, splatfx_error* error, splatfx_scene* scene, splatfx_materials* materials, const CDesc* desc,
                          const splatfx_effect_options* options, std::uint32_t* outId, Init init, Fields fields, Build build, Extra extra) {
    return guard(function, error, [&] {
        CDesc c;
        init(&c);
        if (desc) c = *desc;
        Desc d;
        FieldsIn in;
        fields(in, std::as_const(c), d);
        if (in.bad) return *in.bad;
        if (auto bad = extra(d)) return *bad;
        return addPreset(scene, materials, options, outId, [&](Materials& m, Outcome& failed) { return fromResult(build(m, d), failed); });
    });
}

constexpr auto kNoExtraCheck = [](const auto&) { return std::optional<Outcome>(); };

} // namespace

extern "C" {

uint32_t splatfx_c_api_version(void) { return SPLATFX_C_API_VERSION; }

// ---- [errors]

const char* splatfx_status_name(splatfx_status status) {
    switch (status) {
    case SPLATFX_OK: return "SPLATFX_OK";
    case SPLATFX_ERROR_INVALID_ARGUMENT: return "SPLATFX_ERROR_INVALID_ARGUMENT";
    case SPLATFX_ERROR_INVALID_STATE: return "SPLATFX_ERROR_INVALID_STATE";
    case SPLATFX_ERROR_NOT_FOUND: return "SPLATFX_ERROR_NOT_FOUND";
    case SPLATFX_ERROR_FILE: return "SPLATFX_ERROR_FILE";
    case SPLATFX_ERROR_GL: return "SPLATFX_ERROR_GL";
    case SPLATFX_ERROR_OUT_OF_MEMORY: return "SPLATFX_ERROR_OUT_OF_MEMORY";
    case SPLATFX_ERROR_INTERNAL: return "SPLATFX_ERROR_INTERNAL";
    case SPLATFX_STATUS_MAX_ENUM: break;
    }
    return "SPLATFX_ERROR_UNKNOWN_STATUS";
}

splatfx_error* splatfx_error_create(void) {
    auto* error = new (std::nothrow) splatfx_error();
    if (!error) return nullptr;
    try {
        registerHandle(error, Magic::Error);
    } catch (...) {
        delete error;
        return nullptr;
    }
    return error;
}
void splatfx_error_destroy(splatfx_error* error) { destroyHandle(error, Magic::Error); }
splatfx_status splatfx_error_status(const splatfx_error* error) {
    return isLive(error, Magic::Error) ? error->status : SPLATFX_ERROR_INVALID_ARGUMENT;
}
const char* splatfx_error_message(const splatfx_error* error) {
    if (!error) return "splatfx_error_message: error is NULL";
    if (!isLive(error, Magic::Error))
        return "splatfx_error_message: error is not a splatfx_error (it was destroyed, or is another handle or a stray pointer)";
    if (error->status != SPLATFX_OK && error->message.empty()) return "out of memory while writing the error message";
    return error->message.c_str();
}

// ---- [materials and texture sets]

void splatfx_materials_desc_init(splatfx_materials_desc* desc) {
    if (!desc) return;
    const MaterialsDesc d{};
    desc->layer_size = d.layerSize;
    desc->color_table_size = d.colorTableSize;
}

splatfx_status splatfx_materials_create(const splatfx_materials_desc* desc, splatfx_materials** out, splatfx_error* error) {
    return guard("splatfx_materials_create", error, [&] {
        if (!out) return invalid("out is NULL");
        *out = nullptr;
        splatfx_materials_desc d;
        splatfx_materials_desc_init(&d);
        if (desc) d = *desc;
        // Materials asserts these (a misuse in C++); here they are the caller's input.
        if (d.layer_size < 4 || d.layer_size > 1024)
            return invalid("desc.layer_size is " + std::to_string(d.layer_size) + "; expected texels in [4, 1024]");
        if (d.color_table_size < 2 || d.color_table_size > 65536)
            return invalid("desc.color_table_size is " + std::to_string(d.color_table_size) + "; expected entries in [2, 65536]");
        *out = listed(std::make_unique<splatfx_materials>(MaterialsDesc{.layerSize = d.layer_size, .colorTableSize = d.color_table_size}),
                      Magic::Materials);
        return success();
    });
}

void splatfx_materials_destroy(splatfx_materials* materials) { destroyHandle(materials, Magic::Materials); }

uint32_t splatfx_materials_layer_count(const splatfx_materials* materials) {
    return isLive(materials, Magic::Materials) ? materials->value.layerCount() : 0;
}

splatfx_status splatfx_texture_set_load(const char* folder, splatfx_texture_set** out, splatfx_error* error) {
    return guard("splatfx_texture_set_load", error, [&] {
        if (!out) return invalid("out is NULL");
        *out = nullptr;
        if (!folder) return invalid("folder is NULL");
        Result<TextureSet> set = loadTextureSet(folder);
        if (!set) return failure(SPLATFX_ERROR_FILE, set.error());
        *out = listed(std::make_unique<splatfx_texture_set>(splatfx_texture_set{Magic::TextureSet, std::move(*set)}), Magic::TextureSet);
        return success();
    });
}

void splatfx_texture_set_destroy(splatfx_texture_set* set) { destroyHandle(set, Magic::TextureSet); }

uint32_t splatfx_texture_set_count(const splatfx_texture_set* set) { return isLive(set, Magic::TextureSet) ? std::uint32_t(set->value.count()) : 0; }

// ---- [scene and presets]

splatfx_status splatfx_scene_create(splatfx_scene** out, splatfx_error* error) {
    return guard("splatfx_scene_create", error, [&] {
        if (!out) return invalid("out is NULL");
        *out = listed(std::make_unique<splatfx_scene>(), Magic::Scene);
        return success();
    });
}

void splatfx_scene_destroy(splatfx_scene* scene) { destroyHandle(scene, Magic::Scene); }

void splatfx_effect_options_init(splatfx_effect_options* options) {
    if (!options) return;
    const EffectOptions o{};
    options->name = nullptr;
    options->range_world = o.rangeWorld;
    options->enabled = o.enabled ? 1 : 0;
    options->textured = o.draw.textured ? 1 : 0;
    options->opacity_scale = o.draw.opacityScale;
}

void splatfx_keyframe_init(splatfx_keyframe* key) {
    if (!key) return;
    const Keyframe k{};
    key->time_sec = k.timeSec;
    store3(key->position, k.pose.position);
    key->rotation[0] = k.pose.rotation.w;
    key->rotation[1] = k.pose.rotation.x;
    key->rotation[2] = k.pose.rotation.y;
    key->rotation[3] = k.pose.rotation.z;
    store3(key->scale, k.pose.scale);
    key->opacity = k.pose.opacity;
    key->growth = k.pose.growth;
    key->easing = SPLATFX_EASING_LINEAR;
}

void splatfx_fire_desc_init(splatfx_fire_desc* desc) { initPresetDesc<splatfx_fire_desc, presets::FireDesc>(desc, FireFields{}); }
void splatfx_smoke_desc_init(splatfx_smoke_desc* desc) { initPresetDesc<splatfx_smoke_desc, presets::SmokeDesc>(desc, SmokeFields{}); }
void splatfx_steam_desc_init(splatfx_steam_desc* desc) { initPresetDesc<splatfx_steam_desc, presets::SteamDesc>(desc, SteamFields{}); }
void splatfx_dust_desc_init(splatfx_dust_desc* desc) { initPresetDesc<splatfx_dust_desc, presets::DustDesc>(desc, DustFields{}); }
void splatfx_fire_to_smoke_desc_init(splatfx_fire_to_smoke_desc* desc) {
    initPresetDesc<splatfx_fire_to_smoke_desc, presets::FireToSmokeDesc>(desc, FireToSmokeFields{});
}
void splatfx_ghosts_desc_init(splatfx_ghosts_desc* desc) { initPresetDesc<splatfx_ghosts_desc, presets::GhostsDesc>(desc, GhostsFields{}); }
void splatfx_embers_desc_init(splatfx_embers_desc* desc) { initPresetDesc<splatfx_embers_desc, presets::EmbersDesc>(desc, EmbersFields{}); }

splatfx_status splatfx_scene_add_fire(splatfx_scene* scene, splatfx_materials* materials, const splatfx_fire_desc* desc,
                                      const splatfx_effect_options* options, uint32_t* out_id, splatfx_error* error) {
    return addPresetC<presets::FireDesc>("splatfx_scene_add_fire", error, scene, materials, desc, options, out_id, splatfx_fire_desc_init,
                                         FireFields{}, presets::fire, kNoExtraCheck);
}

splatfx_status splatfx_scene_add_smoke(splatfx_scene* scene, splatfx_materials* materials, const splatfx_smoke_desc* desc,
                                       const splatfx_effect_options* options, uint32_t* out_id, splatfx_error* error) {
    // presets::smoke takes any substep count; the C layer bounds it like the scene files do.
    auto substeps = [](const presets::SmokeDesc& d) -> std::optional<Outcome> {
        if (d.substeps < 1 || d.substeps > 64)
            return invalid("desc.substeps is " + std::to_string(d.substeps) + "; expected solver substeps in [1, 64]");
        return std::nullopt;
    };
    return addPresetC<presets::SmokeDesc>("splatfx_scene_add_smoke", error, scene, materials, desc, options, out_id, splatfx_smoke_desc_init,
                                          SmokeFields{}, presets::smoke, substeps);
}

splatfx_status splatfx_scene_add_steam(splatfx_scene* scene, splatfx_materials* materials, const splatfx_steam_desc* desc,
                                       const splatfx_effect_options* options, uint32_t* out_id, splatfx_error* error) {
    return addPresetC<presets::SteamDesc>("splatfx_scene_add_steam", error, scene, materials, desc, options, out_id, splatfx_steam_desc_init,
                                          SteamFields{}, presets::steam, kNoExtraCheck);
}

splatfx_status splatfx_scene_add_dust(splatfx_scene* scene, splatfx_materials* materials, const splatfx_dust_desc* desc,
                                      const splatfx_effect_options* options, uint32_t* out_id, splatfx_error* error) {
    return addPresetC<presets::DustDesc>("splatfx_scene_add_dust", error, scene, materials, desc, options, out_id, splatfx_dust_desc_init,
                                         DustFields{}, presets::dust, kNoExtraCheck);
}

splatfx_status splatfx_scene_add_fire_to_smoke(splatfx_scene* scene, splatfx_materials* materials, const splatfx_fire_to_smoke_desc* desc,
                                               const splatfx_effect_options* options, uint32_t* out_id, splatfx_error* error) {
    return addPresetC<presets::FireToSmokeDesc>("splatfx_scene_add_fire_to_smoke", error, scene, materials, desc, options, out_id,
                                                splatfx_fire_to_smoke_desc_init, FireToSmokeFields{}, presets::fireToSmoke, kNoExtraCheck);
}

splatfx_status splatfx_scene_add_ghosts(splatfx_scene* scene, splatfx_materials* materials, const splatfx_ghosts_desc* desc,
                                        const splatfx_effect_options* options, uint32_t* out_id, splatfx_error* error) {
    return addPresetC<presets::GhostsDesc>("splatfx_scene_add_ghosts", error, scene, materials, desc, options, out_id, splatfx_ghosts_desc_init,
                                           GhostsFields{}, presets::ghosts, kNoExtraCheck);
}

splatfx_status splatfx_scene_add_embers(splatfx_scene* scene, splatfx_materials* materials, const splatfx_embers_desc* desc,
                                        const splatfx_effect_options* options, uint32_t* out_id, splatfx_error* error) {
    return addPresetC<presets::EmbersDesc>("splatfx_scene_add_embers", error, scene, materials, desc, options, out_id, splatfx_embers_desc_init,
                                           EmbersFields{}, presets::embers, kNoExtraCheck);
}

splatfx_status splatfx_scene_load_file(const char* path, splatfx_materials* materials, const uint32_t* seed, splatfx_scene** out,
                                       splatfx_error* error) {
    return guard("splatfx_scene_load_file", error, [&] {
        if (!out) return invalid("out is NULL");
        *out = nullptr;
        if (!path) return invalid("path is NULL");
        if (auto bad = checkHandle(materials, Magic::Materials, "materials", "splatfx_materials")) return *bad;
        SceneFileOptions options;
        if (seed) options.seed = *seed;
        Result<SceneFile> file = loadSceneFile(path, materials->value, options);
        if (!file) return failure(SPLATFX_ERROR_FILE, file.error());
        auto scene = std::make_unique<splatfx_scene>();
        scene->value = std::move(file->scene); // before any prepare: nothing in it points at itself yet
        for (const SceneEffectInfo& e : file->effects) scene->effects.push_back(e.id);
        scene->materials = materials->identity;
        scene->hasMaterials = true;
        *out = listed(std::move(scene), Magic::Scene);
        return success();
    });
}

uint32_t splatfx_scene_effect_count(const splatfx_scene* scene) { return isLive(scene, Magic::Scene) ? std::uint32_t(scene->effects.size()) : 0; }

splatfx_status splatfx_scene_set_effect_enabled(splatfx_scene* scene, uint32_t id, int enabled, splatfx_error* error) {
    return guard("splatfx_scene_set_effect_enabled", error, [&] {
        if (auto bad = checkHandle(scene, Magic::Scene, "scene", "splatfx_scene")) return *bad;
        if (id >= scene->effects.size())
            return failure(SPLATFX_ERROR_NOT_FOUND,
                           "id " + std::to_string(id) + " is not an effect of this scene (it has " + std::to_string(scene->effects.size()) + ")");
        scene->value.setEnabled(scene->effects[id], enabled != 0);
        return success();
    });
}

splatfx_status splatfx_scene_set_hdr_lit(splatfx_scene* scene, int on, splatfx_error* error) {
    return guard("splatfx_scene_set_hdr_lit", error, [&] {
        if (auto bad = checkHandle(scene, Magic::Scene, "scene", "splatfx_scene")) return *bad;
        scene->value.setHdrLit(on != 0);
        return success();
    });
}

int splatfx_scene_hdr_lit(const splatfx_scene* scene) { return isLive(scene, Magic::Scene) && scene->value.hdrLit() ? 1 : 0; }

void splatfx_obstacle_desc_init(splatfx_obstacle_desc* desc) {
    if (!desc) return;
    *desc = {};
    desc->shape = SPLATFX_OBSTACLE_BOX;
    for (float& v : desc->size) v = 1.0f;
    for (int i = 0; i < 16; ++i) desc->transform[i] = i % 5 == 0 ? 1.0f : 0.0f;
}

splatfx_status splatfx_scene_add_obstacle(splatfx_scene* scene, uint32_t id, const splatfx_obstacle_desc* desc, splatfx_error* error) {
    return guard("splatfx_scene_add_obstacle", error, [&] {
        if (auto bad = checkHandle(scene, Magic::Scene, "scene", "splatfx_scene")) return *bad;
        if (!desc) return invalid("desc is NULL");
        if (id >= scene->effects.size())
            return failure(SPLATFX_ERROR_NOT_FOUND,
                           "id " + std::to_string(id) + " is not an effect of this scene (it has " + std::to_string(scene->effects.size()) + ")");
        FluidSolver* solver = scene->value.effect(scene->effects[id]).solver();
        if (!solver) return invalid("effect " + std::to_string(id) + " has no solver (obstacles belong to smoke and dust effects)");
        if (desc->shape < SPLATFX_OBSTACLE_BOX || desc->shape > SPLATFX_OBSTACLE_MESH)
            return invalid("desc.shape is " + std::to_string(int(desc->shape)) + "; expected a splatfx_obstacle_shape value");
        constexpr std::uint32_t kMaxTriangles = 1u << 20;
        if (desc->triangle_count > kMaxTriangles)
            return invalid("desc.triangle_count is " + std::to_string(desc->triangle_count) + "; expected at most " + std::to_string(kMaxTriangles));
        if (desc->triangle_count > 0 && !desc->triangles)
            return invalid("desc.triangles is NULL but desc.triangle_count is " + std::to_string(desc->triangle_count));
        Obstacle o;
        o.desc.shape = ObstacleShape(int(desc->shape));
        o.desc.size = vec3Of(desc->size);
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) o.desc.transform[c][r] = desc->transform[c * 4 + r];
        for (std::uint32_t i = 0; i < desc->triangle_count * 3; ++i) o.desc.triangles.push_back(vec3Of(desc->triangles + 3 * i));
        o.desc.slip = desc->no_slip ? Slip::None : Slip::Free;
        if (auto bad = toMotion("desc.motion", desc->motion_keys, desc->motion_key_count, o.motion)) return *bad;
        if (Status st = solver->addObstacle(o); !st) {
            std::string msg = st.error();
            if (msg.rfind("ObstacleDesc.", 0) == 0) msg = "desc." + msg.substr(13);
            return invalid(msg);
        }
        return success();
    });
}

// ---- [camera]

splatfx_status splatfx_camera_from_matrices(const float view[16], const float proj[16], int32_t width, int32_t height, splatfx_camera* out,
                                            splatfx_error* error) {
    return guard("splatfx_camera_from_matrices", error, [&] {
        if (!out) return invalid("out is NULL");
        if (!view) return invalid("view is NULL");
        if (!proj) return invalid("proj is NULL");
        splatfx_camera c{};
        for (int i = 0; i < 16; ++i) {
            c.view[i] = view[i];
            c.proj[i] = proj[i];
        }
        c.viewport[0] = width;
        c.viewport[1] = height;
        if (auto bad = checkCamera(c, "camera")) return *bad;
        *out = c;
        return success();
    });
}

splatfx_status splatfx_camera_look_at(const float eye[3], const float target[3], const float up[3], float fov_y, int32_t width, int32_t height,
                                      float near_plane, float far_plane, splatfx_camera* out, splatfx_error* error) {
    return guard("splatfx_camera_look_at", error, [&] {
        if (!out) return invalid("out is NULL");
        if (!eye) return invalid("eye is NULL");
        if (!target) return invalid("target is NULL");
        if (!up) return invalid("up is NULL");
        for (auto bad : {checkFinite3("eye", eye), checkFinite3("target", target), checkFinite3("up", up)})
            if (bad) return *bad;
        if (!(fov_y > 0.0f && fov_y < 3.14159265f)) return invalid("fov_y is " + str(fov_y) + "; expected radians in (0, pi)");
        if (!(near_plane > 0.0f && far_plane > near_plane && std::isfinite(far_plane)))
            return invalid("near_plane " + str(near_plane) + ", far_plane " + str(far_plane) + "; expected 0 < near_plane < far_plane, both finite");
        const glm::vec3 e = vec3Of(eye), t = vec3Of(target), u = vec3Of(up);
        const glm::vec3 forward = t - e;
        if (!(glm::length(forward) > 0.0f)) return invalid("eye and target are the same point; expected a direction to look in");
        if (!(glm::length(glm::cross(glm::normalize(forward), u)) > 1e-6f))
            return invalid("up is zero or parallel to target - eye; expected a direction across the view");
        if (width < 1 || width > kMaxViewportSide || height < 1 || height > kMaxViewportSide)
            return invalid("width, height are " + std::to_string(width) + ", " + std::to_string(height) + "; expected sizes in [1, " +
                           std::to_string(kMaxViewportSide) + "] pixels");
        const Camera cam = Camera::lookAt(e, t, u, fov_y, {width, height}, near_plane, far_plane);
        splatfx_camera c{};
        const float* v = glm::value_ptr(cam.view);
        const float* p = glm::value_ptr(cam.proj);
        for (int i = 0; i < 16; ++i) {
            c.view[i] = v[i];
            c.proj[i] = p[i];
        }
        c.viewport[0] = width;
        c.viewport[1] = height;
        if (auto bad = checkCamera(c, "camera")) return *bad;
        *out = c;
        return success();
    });
}

// ---- [frame]

splatfx_status splatfx_frame_create(splatfx_frame** out, splatfx_error* error) {
    return guard("splatfx_frame_create", error, [&] {
        if (!out) return invalid("out is NULL");
        *out = listed(std::make_unique<splatfx_frame>(), Magic::Frame);
        return success();
    });
}

void splatfx_frame_destroy(splatfx_frame* frame) { destroyHandle(frame, Magic::Frame); }

splatfx_status splatfx_frame_get_stats(const splatfx_frame* frame, splatfx_frame_stats* out, splatfx_error* error) {
    return guard("splatfx_frame_get_stats", error, [&] {
        if (!out) return invalid("out is NULL");
        if (auto bad = checkHandle(frame, Magic::Frame, "frame", "splatfx_frame")) return *bad;
        const FrameCounters& c = frame->value.counters();
        *out = splatfx_frame_stats{c.declared, c.needed, c.simulated, c.drawn, c.splats, frame->value.time()};
        return success();
    });
}

splatfx_status splatfx_scene_prepare(splatfx_scene* scene, double time_sec, const splatfx_camera* camera, const splatfx_materials* materials,
                                     splatfx_frame* frame, splatfx_error* error) {
    return guard("splatfx_scene_prepare", error, [&] {
        if (auto bad = checkHandle(scene, Magic::Scene, "scene", "splatfx_scene")) return *bad;
        if (auto bad = checkHandle(materials, Magic::Materials, "materials", "splatfx_materials")) return *bad;
        if (auto bad = checkHandle(frame, Magic::Frame, "frame", "splatfx_frame")) return *bad;
        if (auto bad = checkSceneMaterials(*scene, *materials)) return *bad;
        // Only a hook can get here: the render reads the frame's splats after the hook returns.
        if (isHeld(frame))
            return failure(SPLATFX_ERROR_INVALID_STATE, "frame is being drawn by the render that called this hook; prepare another frame");
        if (!camera) return invalid("camera is NULL");
        if (!std::isfinite(time_sec)) return invalid("time_sec is " + str(float(time_sec)) + "; expected a finite number of seconds");
        if (time_sec < 0.0) return invalid("time_sec is " + str(float(time_sec)) + "; expected seconds >= 0");
        if (time_sec > kMaxTimeSec) {
            char buf[200];
            std::snprintf(buf, sizeof buf,
                          "time_sec is %g; expected seconds <= %g (kMaxTimeSec: later times lose the dynamics' precision; restart the clock)",
                          time_sec, kMaxTimeSec);
            return invalid(buf);
        }
        if (auto bad = checkCamera(*camera, "camera")) return *bad;
        if (Status s = scene->value.prepare(time_sec, toCamera(*camera), materials->value, frame->value); !s) return invalid(s.error());
        frame->prepared = true;
        frame->hdrLit = scene->value.hdrLit();
        frame->materials = materials->identity;
        // Drawn without what was asked for: the host hears it, and may still render the frame.
        if (const std::string& lit = scene->value.lightingError(); !lit.empty())
            return invalid(lit + " (the frame is prepared without it and can be rendered)");
        return success();
    });
}

} // extern "C"
