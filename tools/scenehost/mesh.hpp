// tools/scenehost/mesh.hpp: triangle meshes for scene geometry (host side).
//
// Loads any format assimp reads (OBJ, OFF, Collada, glTF, PLY, ...) into one
// indexed triangle list with smooth normals, builds the primitive shapes a
// scene file names (plane, box, cylinder, sphere), and writes OFF files (to
// derive the small meshes the samples ship). Not part of the SDK: the SDK
// stays free of model-loading libraries (scene_file.hpp only names the file).
//
//   auto cow = scenehost::loadMesh("samples/03-cow-through-fire/cow.off");
//   if (!cow) return fail(cow.error());
//   scenehost::Mesh fitted = scenehost::fitted(*cow, 2.0f); // 2 units long, resting on y = 0
//
// Threading: free functions on plain values.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/budget.hpp"
#include "splatfx/motion.hpp"
#include "splatfx/result.hpp"

namespace scenehost {

struct Mesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;     // one per position, unit length
    std::vector<std::uint32_t> indices; // triangles
    splatfx::Aabb bounds() const;
};

// Every mesh of the file, node transforms applied, merged. Errors name the file.
// assimp runs in a child process (fork) held to budgets.meshImportBytes and
// meshImportSeconds, and opens only regular files in the mesh's own folder, so
// a file that crashes, hangs or exhausts it is an error here.
splatfx::Result<Mesh> loadMesh(const std::string& path, const splatfx::Budgets& budgets = {});
// A terrain grid from an image's channel 0 (splatfx::heightmapPoint
// for each sample, two triangles a cell, facing +y). Errors name the file.
// An image of more samples than budgets.heightmapVertices is refused from its
// header, before it is decoded.
splatfx::Result<Mesh> heightmapMesh(const std::string& path, float spacing, float heightScale, const splatfx::Budgets& budgets = {});
// Scaled so the largest bounding-box side is `size`, centred on x and z, resting on y = 0.
Mesh fitted(const Mesh& mesh, float size);
// Area-weighted vertex normals from the triangles.
void computeNormals(Mesh& mesh);
// Writes an OFF file ("OFF", counts, vertices with `decimals` digits, triangles).
splatfx::Status saveOff(const std::string& path, const Mesh& mesh, int decimals = 4);

// Primitives in object space (see splatfx::GeometryType for their extents).
Mesh planeMesh(glm::vec3 size);
Mesh boxMesh(glm::vec3 size);
Mesh cylinderMesh(glm::vec3 size, int segments = 24);
Mesh sphereMesh(glm::vec3 size, int segments = 24);

} // namespace scenehost
