// splatfx/solver.hpp: a small, unconditionally stable Eulerian gas solver on
// the coarse grid, and emitters that feed it.
//
// King et al. 1999, sec. 3.1: with coarse grids (the paper's effects hold under
// 300 voxels) "a simple Eulerian or fluid flow calculation [can] be performed
// across the grid, propagating substructures and properties through the
// mesh". FluidSolver is that calculation, in the style of Stam's "Stable
// Fluids" (1999): a staggered (MAC) velocity grid, cell-centred density and
// temperature; per substep
//   1. emitters relax density, temperature (and velocity) towards their
//      targets inside their region (implicit: any dt is stable);
//   2. buoyancy (temperature lifts, density weighs) is added, wind and
//      damping relax the velocity (implicit);
//   3. pressure projection: conjugate gradient on the cell Laplacian makes
//      the velocity divergence free (closed faces: no flow through them;
//      open faces: zero pressure outside);
//   4. semi-Lagrangian advection (RK2 backtrace, clamped to the domain,
//      trilinear interpolation) of density, temperature, then velocity;
//   5. dissipation (implicit decay); optional global mass correction.
// Obstacles (obstacle.hpp) are voxelized at the start of each substep: a
// cell whose centre is inside one is solid. Faces touching a solid cell carry
// the obstacle's velocity (its motion over the substep, or over the last
// millisecond when the substep is shorter) and are walls to the
// projection, so no gas flows into it relative to its motion; Slip::None also
// pins the fluid faces beside it. Density never sits in a solid cell: what a
// moving obstacle covers is handed to the nearest fluid cell, emitters skip
// solid cells, and backtraces stop before they cross one.
// Every update is a convex combination or an implicit relaxation, so fields
// stay finite and density stays non-negative for any time step and any speed.
// toGrid() turns the dense fields into a sparse splatfx::Grid: voxels appear
// where material arrives and disappear where it fades.
// It does not choose textures (dynamics.hpp) or render.
//
//   auto solver = splatfx::FluidSolver::create({.dims = {8, 16, 8}});
//   solver->addEmitter({.desc = {.offset = {0, 0.5f, 0}, .radius = 1.0f}});
//   solver->step(1.0 / 30.0);
//   solver->toGrid(grid, {});
//
// Threading: one thread at a time per solver; solvers are independent.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/grid.hpp"
#include "splatfx/motion.hpp"
#include "splatfx/obstacle.hpp"
#include "splatfx/result.hpp"

namespace splatfx {

// A region in world space that injects material, attached to a moving object
// (its Motion): its centre is motion.matrix(t) * offset.
struct EmitterDesc {
    glm::vec3 offset{0.0f}; // centre in the object's frame, object units; default origin
    // World units, > 0; cells within it are fed with weight (1 - (r/radius)^2)^2.
    // Never smaller than half a cell's diagonal, so an emitter always reaches a cell.
    float radius = 1.0f;         // default 1
    float density = 1.0f;        // target density inside the region, >= 0; default 1
    float temperature = 1.0f;    // target temperature (above ambient), >= 0; default 1
    float rate = 4.0f;           // 1/s: how fast cells relax towards the targets, >= 0; default 4
    glm::vec3 velocity{0.0f};    // world units/s the material leaves with (exhaust); default 0
    bool injectVelocity = false; // relax the velocity towards `velocity` too; default false
};

struct Emitter {
    EmitterDesc desc{};
    Motion motion{}; // the object the emitter is attached to; default at rest at the origin
    // World centre at t.
    glm::vec3 worldCenter(double timeSec) const { return glm::vec3(motion.matrix(timeSec) * glm::vec4(desc.offset, 1.0f)); }
};

struct FluidSolverDesc {
    glm::ivec3 dims{8, 16, 8};           // cells per axis, each >= 1, at most kMaxVoxels in all; default 8x16x8
    glm::vec3 spacing{1.0f};             // cell size, grid-local units, > 0; default 1
    glm::mat4 transform{1.0f};           // grid-local to world (same lattice convention as Grid); default identity
    float buoyancy = 4.0f;               // upward acceleration per unit temperature, local units/s^2; default 4
    float weight = 0.0f;                 // downward acceleration per unit density (dust settles), local units/s^2; default 0
    float ambientTemperature = 0.0f;     // temperature of the surroundings; default 0
    glm::vec3 windWorld{0.0f};           // world units/s the air relaxes towards; default none
    float windCoupling = 0.0f;           // 1/s: how fast velocity relaxes towards the wind, >= 0; default 0
    float velocityDamping = 0.2f;        // 1/s, implicit drag, >= 0; default 0.2
    float densityDissipation = 0.0f;     // 1/s, implicit decay of density, >= 0; default 0
    float temperatureDissipation = 0.5f; // 1/s, implicit cooling towards ambient, >= 0; default 0.5
    int pressureIterations = 60;         // conjugate-gradient iterations, >= 0 (0: no projection); default 60
    float pressureTolerance = 1e-5f;     // relative residual at which CG stops early; default 1e-5
    int substeps = 1;                    // substeps per step(), >= 1; default 1
    bool closedFloor = true;             // no flow through the -y face; default true
    bool closedWalls = false;            // no flow through the x and z faces; default false (open)
    bool closedCeiling = false;          // no flow through the +y face; default false (open)
    // Rescale density after advection so its total equals the total before
    // (semi-Lagrangian advection is not conservative). Needs every face closed.
    bool conserveMass = false; // default false
};

// How dense fields become a sparse grid.
enum class ColorSource {
    Temperature, // 1 - (T - ambient) / temperatureRange: hottest at 0 (see SparseOutputDesc)
    Height,      // normalized lattice height (the paper's fire, sec. 2 step 4)
    Density,     // density * opacityPerDensity
};

struct SparseOutputDesc {
    float opacityPerDensity = 0.6f;          // voxel opacity = clamp(density * this, 0, 1); default 0.6
    float minOpacity = 0.01f;                // cells below it are left out (sparse); default 0.01
    ColorSource color = ColorSource::Height; // default Height
    // Temperature colour: coord = 1 - clamp((T - ambient) / temperatureRange):
    // hottest at 0 (a fire table's white-yellow base), cold at 1.
    float temperatureRange = 1.0f; // > 0; default 1
    float stretchPerSpeed = 0.0f;  // kernel stretch = velocity * this (seconds / local unit); default 0 (round kernels)
    float maxStretch = 1.0f;       // cap on |stretch|; default 1
};

struct SolverStats {
    std::uint64_t steps = 0;        // step() calls
    std::uint64_t substeps = 0;     // substeps simulated
    std::uint64_t cellsUpdated = 0; // cells times substeps
    int lastPressureIterations = 0; // CG iterations of the last projection
    float lastResidual = 0.0f;      // relative residual after it
    std::uint64_t solidCells = 0;   // cells inside obstacles at the last voxelization
    double displacedDensity = 0.0;  // density moved out of cells an obstacle covered (total over all substeps)
};

class FluidSolver {
public:
    // Checks the desc; the message names the bad field.
    static Result<FluidSolver> create(const FluidSolverDesc& desc);

    void addEmitter(const Emitter& emitter) { mEmitters.push_back(emitter); }
    std::vector<Emitter>& emitters() { return mEmitters; }
    const std::vector<Emitter>& emitters() const { return mEmitters; }

    // Adds a solid the gas flows around (obstacle.hpp) and voxelizes the
    // obstacles at the current time. On failure (validateObstacle's message,
    // or more than kMaxObstacles) nothing is added.
    static constexpr std::size_t kMaxObstacles = 4096;
    Status addObstacle(const Obstacle& obstacle);
    const std::vector<Obstacle>& obstacles() const { return mObstacles; }
    void clearObstacles();
    // Whether a cell is inside an obstacle (as of the last voxelization).
    bool solid(glm::ivec3 cell) const { return !mSolidOwner.empty() && mSolidOwner[cellIndex(cell)] >= 0; }
    // Largest |divergence| of the face velocities over fluid cells, 1/s
    // (grid-local units): what the last projection left, when called right
    // after it (step(0) projects and does nothing else).
    float maxFluidDivergence() const;

    // Advances by dtSec (>= 0, finite) in desc.substeps equal substeps.
    void step(double dtSec);
    double time() const { return mTime; }

    // Sparse output: one voxel per cell whose opacity reaches minOpacity.
    // Sets dims, spacing and transform; textures and phases are left 0.
    void toGrid(Grid& out, const SparseOutputDesc& desc) const;

    // Dense fields, x fastest then y then z; velocity sampled at cell centres
    // in grid-local units/s.
    const std::vector<float>& density() const { return mDensity; }
    std::vector<float>& density() { return mDensity; }
    const std::vector<float>& temperature() const { return mTemp; }
    std::vector<float>& temperature() { return mTemp; }
    glm::vec3 velocityAt(glm::ivec3 cell) const;
    // The staggered velocity component `axis` on face `face` (face i along
    // the axis lies between cells i-1 and i; 0..dims[axis]), local units/s.
    float faceVelocity(int axis, glm::ivec3 face) const;
    // Sets every face velocity to v (grid-local units/s), e.g. for tests or a
    // prescribed flow.
    void setUniformVelocity(glm::vec3 v);
    std::vector<glm::vec3> cellVelocities() const;
    // Sum of density over cells (times cell volume = 1 cell).
    double totalDensity() const;
    // Largest |face velocity| component, local units/s.
    float maxSpeed() const;

    std::size_t cellIndex(glm::ivec3 c) const { return (std::size_t(c.z) * mDims.y + c.y) * mDims.x + c.x; }
    glm::ivec3 dims() const { return mDims; }
    const FluidSolverDesc& desc() const { return mDesc; }
    const SolverStats& stats() const { return mStats; }
    // Grid-local position of a cell centre (the Grid lattice convention).
    glm::vec3 localPosition(glm::ivec3 cell) const;

private:
    FluidSolver() = default;
    void substep(float dt);
    void applyEmitters(float dt);
    void applyForces(float dt);
    // Whether face f of axis a lies on a boundary the desc closes.
    bool closedFace(int axis, glm::ivec3 f) const;
    void project();
    void advectScalars(float dt);
    void advectVelocity(float dt);
    void dissipate(float dt);
    // Voxelizes the obstacles at mTime (velocities from their motion over the
    // last dt, at least 1 ms), hands covered density to fluid cells, fixes the wall faces.
    void updateObstacles(float dt);
    void enforceObstacleFaces();
    bool fixedFace(int axis, std::size_t faceIndex) const { return !mFixed[axis].empty() && mFixed[axis][faceIndex] != 0; }
    // The last point of the straight path from -> to before it enters a solid cell.
    glm::vec3 stopAtSolid(glm::vec3 from, glm::vec3 to) const;

    float sampleScalar(const std::vector<float>& f, glm::vec3 p, float outside) const;
    float sampleFace(int axis, const std::vector<float>& f, glm::vec3 p) const;
    glm::vec3 velocityCells(glm::vec3 p) const;
    glm::vec3 backtrace(glm::vec3 p, float dt) const;

    FluidSolverDesc mDesc;
    glm::ivec3 mDims{0};
    std::vector<float> mDensity, mTemp, mScratch;
    std::vector<float> mU[3], mUScratch[3];   // face velocities, local units/s
    std::vector<double> mP, mR, mD, mQ, mRhs; // CG workspace
    std::vector<Emitter> mEmitters;
    std::vector<Obstacle> mObstacles;
    std::vector<std::int16_t> mSolidOwner;  // per cell: obstacle index, -1 fluid; empty without obstacles
    std::vector<glm::vec3> mSolidVelocity;  // per cell: the obstacle's velocity there, local units/s
    std::vector<std::uint8_t> mFixed[3];    // per face: velocity prescribed by an obstacle
    std::vector<float> mFixedVelocity[3];   // per face: that velocity, local units/s
    std::vector<int> mComponent;            // projection: connected fluid region of each cell
    std::vector<std::uint8_t> mWallBits;    // projection: which of a cell's six faces are walls
    glm::vec3 mUpLocal{0, 1, 0};
    glm::vec3 mWindLocal{0.0f};
    double mTime = 0.0;
    SolverStats mStats;
};

} // namespace splatfx
