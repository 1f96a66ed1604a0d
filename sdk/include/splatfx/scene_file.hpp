// splatfx/scene_file.hpp: scene files (versioned JSON) to a ready Scene.
//
// A scene file describes effects (presets or hand-shaped grids, their
// texture sets, colour tables, dynamics and motion), simple scene geometry
// (ground plane, boxes, cylinders, spheres, meshes) sharing motions with the
// effects, a camera path and output settings. loadSceneFile() parses it,
// builds every effect through presets.hpp / Effect::fromGrid into a Scene,
// registers their texture sets and colour tables in the caller's Materials,
// and returns the rest (geometry, camera, output) as plain data.
// The format is documented field by field in docs/scene-format.md.
//
// It does NOT load meshes, draw geometry, evaluate the camera path or create
// GL resources: geometry comes back as descriptions (type, resolved mesh
// path, transform, motion, colour) for the host to draw, which keeps the SDK
// free of model-loading libraries. It never reads the wall clock.
//
//   splatfx::Materials materials(splatfx::Footprint{});
//   auto file = splatfx::loadSceneFile("samples/03-cow-through-fire/scene.json", materials);
//   if (!file) { std::fprintf(stderr, "%s\n", file.error().c_str()); return 1; }
//   file->scene.update(t, camera);  // then scene.emit(builder, materials)
//
// On failure the message names the file, the field as a JSON path
// (`effects[2].dims`) and what was expected; syntax errors give line and
// column; unknown keys are errors (with a suggestion when one is close).
// Several problems are reported at once (up to SceneFileOptions::maxErrors).
// Paths inside a scene file are relative to the file's folder.
//
// Threading: loadSceneFile touches only its arguments; the result is a
// plain value (the Scene inside it follows scene.hpp's rules).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/budget.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/motion.hpp"
#include "splatfx/result.hpp"
#include "splatfx/scene.hpp"

namespace splatfx {

// The "format" and "version" a scene file must carry.
inline constexpr const char* kSceneFileFormat = "splatfx-scene";
inline constexpr int kSceneFileVersion = 1;

enum class GeometryType {
    Plane,     // square in the object's xz plane, size.x by size.z, facing +y
    Box,       // axis-aligned in object space, size = full extents
    Cylinder,  // along object +y from y = 0 to size.y, radius size.x / 2
    Sphere,    // radius size.x / 2, centred on the object origin
    Mesh,      // triangles from meshPath (the host loads it)
    Heightmap, // a terrain grid from heightmapPath (an image, channel 0), centred on the object origin
    Empty,     // nothing drawn: an anchor whose motion other objects and effects share
};

// One piece of scene geometry. Object to world at t:
//   motion.matrix(t) * transform
// where `transform` is the static placement (position, rotation, scale) and
// `motion` is its own keyframed/procedural motion or the motion of the object
// it is attached to (so a locomotive's parts and its smoke move together).
struct GeometryDesc {
    std::string name; // default "geometry[i]"
    GeometryType type = GeometryType::Box;
    std::string meshPath;      // Mesh: absolute or cwd-relative path, resolved against the scene file
    glm::vec3 size{1.0f};      // world units (see GeometryType); default 1
    glm::mat4 transform{1.0f}; // static placement; default identity
    Motion motion;             // default at rest
    std::string attachedTo;    // name of the object whose motion it shares; default empty
    glm::vec3 color{0.6f};     // linear RGB albedo; default grey
    // Below 1: a transparent surface (glass), premultiplied
    // (lit colour x opacity, opacity) per layer, which a host draws through
    // transparentGlsl() into the fragment lists (tools/scenehost does). [0, 1]; default 1 (opaque).
    float opacity = 1.0f;
    // Mesh: scale the mesh so its bounding box's largest side is this long
    // and rest it on y = 0 centred on x and z (before `transform`); 0 keeps
    // the file's own units. Default 0.
    float fitSize = 0.0f;
    // Heightmap: sample (i, j) of the image (row 0 = -z edge) is the
    // point ((i - (w-1)/2) s, heightScale v, (j - (h-1)/2) s), s = heightmapSpacing,
    // v the image value in [0, 1] (a 16-bit PGM: code / 65535). heightmapPoint() below.
    std::string heightmapPath;     // Heightmap: resolved against the scene file
    float heightmapSpacing = 1.0f; // world units between samples; default 1
    float heightmapScale = 1.0f;   // world height of value 1; default 1
};

// Object-space point of heightmap sample (i, j) of a w x h image with value v.
inline glm::vec3 heightmapPoint(int i, int j, int w, int h, float v, float spacing, float scale) {
    return {(float(i) - 0.5f * float(w - 1)) * spacing, scale * v, (float(j) - 0.5f * float(h - 1)) * spacing};
}

// One key of the camera path.
struct CameraKey {
    double timeSec = 0.0;         // strictly increasing; default 0
    glm::vec3 position{0, 2, 10}; // world; default (0, 2, 10)
    glm::vec3 target{0, 1, 0};    // world point looked at; default (0, 1, 0)
    float fovYRad = 0.7853982f;   // vertical field of view, radians; default 45 degrees
};

struct CameraPath {
    std::vector<CameraKey> keys; // at least one (a default key when the file has no camera)
    bool smooth = true;          // smoothstep between keys (false: linear); default true
    float nearPlane = 0.05f;     // world units; default 0.05
    float farPlane = 500.0f;     // world units; default 500
};

struct OutputSettings {
    glm::ivec2 size{640, 480};                 // pixels; default 640x480
    int frames = 48;                           // default 48
    float fps = 24.0f;                         // animation time of frame i is i / fps; default 24
    glm::vec3 background{0.02f, 0.02f, 0.04f}; // clear colour, linear RGB; default near black
    std::string name;                          // output file stem; default the scene file's folder name
};

// What the file said about each effect, beside the Scene entry built for it.
struct SceneEffectInfo {
    EffectId id = 0;          // in SceneFile::scene
    std::string name;         // default "<kind><i>"
    std::string kind;         // "fire", "smoke", ..., "grid"
    std::string attachedTo;   // geometry name whose motion it rides; default empty
    bool traditional = false; // drawn with plain footprints (Fig. 1a); default false
};

// What the file said about each volume (clouds, ground fog), beside the
// Scene entry built for it.
struct SceneVolumeInfo {
    EffectId id = 0;  // in SceneFile::scene
    std::string name; // default "volume<i>"
    std::string kind; // "clouds" or "groundFog"
};

// A LOD ground-fog layer whose terrain mesh the host draws in place of a
// heightmap geometry (groundFog key "terrainGeometry"), so the terrain and
// the fog's bottom are one mesh.
struct GroundFogTerrain {
    std::string geometry; // the heightmap geometry's name
    EffectId fog = 0;     // the layer in SceneFile::scene (Scene::groundFogTerrain(fog), findGroundFog(fog))
};

// A light whose direction moves over time (a light's "directionEnd" and
// "moveSec" keys): from the file's direction at t = 0 to directionEnd at
// t = moveSec, the unit direction interpolated along the great circle, then
// held. The host applies it each frame (Scene::setLight): lit clouds relight.
struct LightMotion {
    std::size_t light = 0;   // index into SceneFile::scene.lights()
    glm::vec3 from{0, -1, 0}; // direction at t = 0
    glm::vec3 to{0, -1, 0};   // direction at t >= seconds
    float seconds = 1.0f;     // > 0
    // The light at timeSec: `base` with the interpolated direction.
    Light at(const Light& base, double timeSec) const;
};

struct SceneFile {
    std::string path;       // the file as given
    std::string title;      // default empty
    std::uint32_t seed = 1; // scene seed after SceneFileOptions::seed; default 1
    Scene scene;            // the file's effects, then its volumes, each in file order
    std::vector<SceneEffectInfo> effects;
    std::vector<SceneVolumeInfo> volumes;
    std::vector<GeometryDesc> geometry;
    CameraPath camera;
    OutputSettings output;
    std::vector<GroundFogTerrain> groundFogTerrain; // default none
    std::vector<LightMotion> lightMotions;          // default none
};

struct SceneFileOptions {
    // Replaces the file's top-level "seed" (every effect's seed derives from it).
    std::optional<std::uint32_t> seed; // default: the file's seed
    int maxErrors = 8;                 // problems reported before giving up, >= 1; default 8
    // What the file may ask to build: lattice and solver cells, sampled
    // texels, texture layers (budget.hpp); checked before each is built.
    Budgets budgets{}; // default: Budgets' defaults
};

// Reads and builds a scene file. Expects options.maxErrors >= 1.
// On failure the texture sets and colour tables of effects built before the
// problem was found may remain in `materials` (unused, harmless); pass a
// scratch Materials to only validate a file.
Result<SceneFile> loadSceneFile(const std::string& path, Materials& materials, const SceneFileOptions& options = {});

// Same, from text already in memory. `path` names the file in messages and
// its folder anchors relative paths (it need not exist).
Result<SceneFile> parseSceneFile(const std::string& text, const std::string& path, Materials& materials, const SceneFileOptions& options = {});

} // namespace splatfx
