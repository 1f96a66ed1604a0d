// Private: what the scene-file readers share (docs/scene-format.md).
//
// [SECTION] Limits
// [SECTION] Context: the file being read, its folder, the caller's Materials
// [SECTION] Shared pieces (shared.cpp): placement, motion, texture sets,
//           colour tables, lattice dims
// [SECTION] Geometry (geometry.cpp): the list and attachment chains
// [SECTION] Effects (effects.cpp): the fields every kind takes; each kind's
//           own reader is in kinds/ and listed in kinds.cpp
// [SECTION] Camera and output (camera_output.cpp)
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scenefile/json_reader.hpp"
#include "splatfx/color_table.hpp"
#include "splatfx/obstacle.hpp"
#include "splatfx/scene_file.hpp"
#include "splatfx/texture_set.hpp"

namespace splatfx::scenefile {

// [SECTION] Limits

// Larger than any sensible scene, small enough that a typo (an extra zero,
// a unit mistake) is caught before it allocates gigabytes.
inline constexpr double kMaxCoord = 1.0e6; // world units for positions and offsets
// Key times (motion, camera): no later than the dynamics hold exactly
// (kMaxTimeSec, effect_kind.hpp), since no frame may be prepared after it.
inline constexpr double kMaxSeconds = kMaxTimeSec;
inline constexpr int kMaxAxis = 4096; // cells per lattice axis
inline constexpr std::size_t kMaxEffects = 4096;
inline constexpr std::size_t kMaxGeometry = 4096;
inline constexpr std::size_t kMaxKeys = 100000;
inline constexpr std::size_t kMaxFileBytes = 16u << 20;
inline constexpr int kMaxDepth = 64;
inline constexpr int kMaxAttachDepth = 16;

// [SECTION] Context

struct RawGeometry;

// Sizes that cost memory or time in proportion (cells, texels, texture
// layers) are budgets the user can raise: Context::budgets (budget.hpp).

struct Context {
    Diagnostics& d;
    std::filesystem::path baseDir;
    Materials& materials;
    std::uint32_t sceneSeed = 1;
    Budgets budgets{};             // SceneFileOptions::budgets
    std::uint64_t volumeBytes = 0; // the estimates of the volumes read so far (Budgets::volumeBytes)
    // Texture-set folders already read for this file, by canonical path: a
    // level naming one folder for a thousand effects reads it once.
    std::map<std::string, TextureSet> folders{};
    // The file's geometry, for effects that refer to it by name (a solver
    // effect's "obstacles"); set once the geometry list is read.
    const std::vector<RawGeometry>* geometry = nullptr;
    const std::map<std::string, std::size_t>* geometryByName = nullptr;
};

// [SECTION] Shared pieces

// An object read by body(c, o, value) into a default T; nullopt when v is not
// an object or anything was reported while reading it (unknown keys included).
template <class T, class Body>
std::optional<T> readObject(Context& c, const std::string& path, const Json& v, Body body) {
    ObjectReader o(c.d, path, v);
    if (!o.valid()) return std::nullopt;
    const std::size_t before = c.d.count();
    T value{};
    body(c, o, value);
    o.finish();
    if (c.d.count() != before) return std::nullopt;
    return value;
}

// A path from the file, resolved against the scene file's folder.
std::string resolvePath(const Context& c, const std::string& p);

// position / rotationDeg (/ scale) of an object.
glm::mat4 readPlacement(ObjectReader& o, bool withScale);

// A motion object: keys plus procedural motion (motion.hpp).
std::optional<Motion> readMotion(Context& c, const std::string& path, const Json& v);

// A texture set as written in a file.
struct TextureSpec {
    enum class Kind { Procedural, Folder, Faces, SampleImage } kind = Kind::Procedural;
    std::string folder; // Folder: resolved path
    std::string image;  // SampleImage: resolved path
    int count = 8;
    int size = 32;
    std::uint32_t seed = 1;
    int octaves = 4;
    float baseFrequency = 3.0f;
    float loopRadius = 0.25f;
    bool keepColor = false;
};

// presetOnly restricts the forms (presets take only a folder or a procedural count).
std::optional<TextureSpec> readTextureSpec(Context& c, const std::string& path, const Json& v, int defaultCount, std::uint32_t seed, bool presetOnly);
// Loads, generates or samples the set (the file read happens here).
Result<TextureSet> buildTextureSet(const TextureSpec& t);
// A preset's texture-set path: the folder, or empty for procedural.
// A texture-set folder named for a preset, loaded here (once per file): the
// presets are in the file-free core and take the set in memory. Errors go to
// the diagnostics at the effect's path; callers check c.d.ok() afterwards.
std::optional<TextureSet> presetSet(Context& c, const std::string& effectPath, const std::optional<TextureSpec>& t);

// A preset's "textureSet" (a folder or a procedural count) when given;
// `count` becomes its count.
std::optional<TextureSpec> readPresetTextureSet(Context& c, ObjectReader& o, std::uint32_t seed, int& count);

std::optional<ColorTable> readColorTable(Context& c, const std::string& path, const Json& v);

std::uint64_t cells(glm::ivec3 d);
// "64x32x16", as messages write lattice sizes.
std::string dimsText(glm::ivec3 d);
// Reads "dims" (required positive) with the kind's cell limit; `why` explains the limit.
// dims checked against a budget: `field` names the Budgets member it is (messages say how to raise it).
void readDims(Context& c, ObjectReader& o, glm::ivec3& dims, std::uint64_t limit, const char* field, const char* why);

glm::vec3 applyPoint(const glm::mat4& m, glm::vec3 p);

// A "propagation" object (dynamics.hpp, sec. 3.2); allowVelocity admits mode
// "velocity" (kinds that carry a flow: "vdb"). And a "cycling" object (sec. 3.3).
void readPropagation(Context& c, ObjectReader& o, PropagationDesc& p, bool allowVelocity);
void readCycling(Context& c, ObjectReader& o, CyclingDesc& cy);

// [SECTION] Geometry

struct RawGeometry {
    GeometryDesc desc;
    std::string attachTo;
    std::string path;
    bool hasOwnMotion = false;
};

// Resolved placement of a named object: the root motion it rides on and the
// composed static transform down the attachment chain.
struct Anchor {
    Motion motion;
    glm::mat4 transform{1.0f};
};

std::optional<Anchor> resolveAnchor(Context& c, const std::vector<RawGeometry>& geo, const std::map<std::string, std::size_t>& byName,
                                    const std::string& name, const std::string& atPath);
std::vector<RawGeometry> readGeometryList(Context& c, const std::string& path, const Json& v);

// [SECTION] Effects

// Fields every kind shares, read before the kind-specific ones.
struct EffectCommon {
    std::string name, kind, path, attachTo;
    std::uint32_t seed = 1;
    EffectOptions options;
    DynamicsToggles toggles;
    bool traditional = false;
    std::optional<Motion> motion; // own motion, when given
};

// Where an effect rides: the motion of its anchor (or its own motion) and
// the static transform of the geometry it is attached to.
struct Placement {
    Motion motion;
    glm::mat4 parent{1.0f};
};

void readEffects(Context& c, const std::string& path, const Json& v, const std::vector<RawGeometry>& geo,
                 const std::map<std::string, std::size_t>& geoByName, SceneFile& out);

// [SECTION] Lights (lights.cpp; issue 16)

// Top-level "lights" (a list) and "sceneShadow", into out.scene.
void readLights(Context& c, const std::string& path, const Json& v, SceneFile& out);
void readSceneShadow(Context& c, const std::string& path, const Json& v, SceneFile& out);
// An effect's "lighting" object.
void readEffectLighting(Context& c, const std::string& path, const Json& v, EffectLighting& out);
// Every light x every table-lit effect's shadow table, plus the scene shadow,
// against Budgets::lightingBytes (after the effects, lights and sceneShadow).
void checkLightingBudget(Context& c, const SceneFile& out);
// [clouds, issue 17] The top-level "volumes" block (volumes.cpp).
void readVolumes(Context& c, const std::string& path, const Json& v, SceneFile& out);

// [SECTION] Obstacles (obstacles.cpp): a solver effect's "obstacles" list,
// entries naming geometry or giving their own shape; nullopt after reporting.
std::optional<std::vector<Obstacle>> readObstacles(Context& c, const std::string& path, const Json& v);

// [SECTION] Camera and output

void readCamera(Context& c, const std::string& path, const Json& v, CameraPath& cam);
void readOutput(Context& c, const std::string& path, const Json& v, OutputSettings& out);

// [SECTION] Fog (fog_block.cpp): the top-level "fog" block, set on the scene.
void readFog(Context& c, const std::string& path, const Json& v, Scene& scene);

} // namespace splatfx::scenefile
