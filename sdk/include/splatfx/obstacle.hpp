// splatfx/obstacle.hpp: solid objects the gas solver flows around (a bridge
// deck, a roof, a moving wagon), taken from the host's geometry.
//
// King et al. 1999, sec. 5, Fig. 9: locomotive smoke "changing shape" as it
// goes under a bridge. An Obstacle is a box, a ground plane, a sphere, a
// cylinder or a closed triangle mesh in its object's frame, placed in the
// world by motion(t) * transform exactly like the scene file's geometry
// (scene_file.hpp, GeometryDesc), so the host hands the solver the objects it
// draws. FluidSolver voxelizes every obstacle onto its grid each substep
// (a cell is solid when its centre is inside), imposes the object's velocity
// on the faces it touches and keeps gas out of it (solver.hpp).
// It does not collide rigid bodies, move the obstacle in response to the gas,
// or draw anything.
//
//   splatfx::Obstacle deck{.desc = {.shape = splatfx::ObstacleShape::Box, .size = {1, 0.3f, 6},
//                                   .transform = glm::translate(glm::mat4(1.0f), {0, 3, 0})}};
//   if (splatfx::Status s = solver.addObstacle(deck); !s) return fail(s.error());
//
// Threading: plain values and pure functions; safe from any thread.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "splatfx/motion.hpp"
#include "splatfx/result.hpp"

namespace splatfx {

// The same solids the scene file's geometry types describe (GeometryType).
enum class ObstacleShape {
    Box,      // axis-aligned in object space, centred on the origin, size = full extents
    Plane,    // the object's xz square (size.x by size.z) and everything below it (object -y): ground
    Sphere,   // radius size.x / 2, centred on the origin
    Cylinder, // along object +y from y = 0 to size.y, radius size.x / 2
    Mesh,     // a closed triangle list (`triangles`), object units
};

// How gas moves along the obstacle's surface (the normal component always
// follows the obstacle: no gas enters it).
enum class Slip {
    Free, // tangential velocity untouched: gas slides along the surface
    None, // the fluid faces beside the surface move with the obstacle (a one-cell boundary layer: the solver has no viscosity to grow one)
};

struct ObstacleDesc {
    ObstacleShape shape = ObstacleShape::Box; // default Box
    glm::vec3 size{1.0f};                     // object units (see ObstacleShape), each > 0 and finite; default 1
    glm::mat4 transform{1.0f};                // static placement in the object (GeometryDesc::transform); default identity
    // Mesh: three vertices per triangle, object units. Must be closed (a
    // cell is solid where the winding number is above 1/2); zero-area
    // triangles add nothing and are allowed; at least one must have area.
    std::vector<glm::vec3> triangles{};
    Slip slip = Slip::Free; // default Free
};

struct Obstacle {
    ObstacleDesc desc{};
    Motion motion{}; // the object it belongs to; world at t = motion.matrix(t) * desc.transform; default at rest at the origin

    glm::mat4 objectToWorld(double timeSec) const { return motion.matrix(timeSec) * desc.transform; }
};

// Checks the desc: sizes positive and finite, transform finite and not
// singular, a mesh's vertex count a multiple of 3 with every vertex finite
// and some triangle of non-zero area. The message names the field
// ("ObstacleDesc.triangles[7] is not finite").
Status validateObstacle(const ObstacleDesc& desc);

// Whether an object-space point is inside the obstacle (boundary points of
// the analytic shapes count as inside). Meshes use the generalized winding
// number (sum of the triangles' solid angles / 4 pi > 1/2), which is robust
// to rays through edges and ignores degenerate triangles.
bool obstacleContains(const ObstacleDesc& desc, glm::vec3 objectPoint);

// Object-space bounds (Plane: unbounded below, so lo.y = -infinity).
Aabb obstacleBounds(const ObstacleDesc& desc);

} // namespace splatfx
