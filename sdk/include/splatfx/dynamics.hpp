// splatfx/dynamics.hpp: global and local texture dynamics (which textured
// splat each voxel shows, frame by frame).
//
// King et al. 1999, sec. 3.2 (global dynamics): "grabbing the texture index of
// the voxel below the current voxel from the previous frame. This texture
// index is then offset slightly", so turbulent structures travel through the
// volume. Sec. 3.3 (local dynamics): phase-shifting through an ordered,
// cyclic texture sequence, or random selection, at a chosen rate, optionally
// cross-faded (Voxel::phase is the cross-fade weight; SplatStyle::crossfade).
//
// Stateless evaluation. For propagation along a fixed lattice direction d the
// recurrence
//     index_0(c) = seedHash(c)                       (sec. 2 step 3: initial random)
//     index_n(c) = index_{n-1}(c - d) + offset       if c - d is a voxel
//                = sourceHash(c, n)                   otherwise (seeded source)
// unrolls to a closed form. With K(c) the number of consecutive voxels
// upwind of c (c - d, c - 2d, ... all in the lattice):
//     n <= K:  index_n(c) = index_0(c - n d) + n * offset
//     n >  K:  index_n(c) = sourceHash(c - K d, n - K) + K * offset
// so any frame is a pure function of (cell, time, seed) and the (static)
// lattice: TextureDynamics evaluates it directly; TexturePropagator runs the
// recurrence step by step (the only way when the direction follows a solver's
// velocity). Arithmetic is modulo 2^32 in both, so they agree exactly; the
// renderer shows layer index % set size.
// It does not move voxels or change opacities: see motion.hpp and solver.hpp.
//
//   splatfx::TextureDynamics tex(grid, {.propagation = {.mode = splatfx::Propagation::Fixed}});
//   auto [texture, phase] = tex.sample(voxelIndex, timeSec);
//   tex.apply(grid, timeSec);  // writes Voxel::texture and Voxel::phase
//
// Threading: plain values; const member functions may be called from any thread.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace splatfx {

class Grid;

// Integer hash (Wellons' "lowbias32" finalizer): good avalanche, no state.
inline std::uint32_t hash32(std::uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}
// Hash of a lattice cell, a seed and a salt (e.g. a step number).
inline std::uint32_t hashCell(glm::ivec3 c, std::uint32_t seed, std::uint32_t salt) {
    std::uint32_t h = hash32(seed ^ 0x9e3779b9u);
    h = hash32(h ^ std::uint32_t(c.x));
    h = hash32(h ^ std::uint32_t(c.y) * 0x85ebca6bu);
    h = hash32(h ^ std::uint32_t(c.z) * 0xc2b2ae35u);
    return hash32(h ^ salt * 0x27d4eb2fu);
}
// Uniform float in [0, 1) from a hash.
inline float hashUnit(std::uint32_t h) { return float(h >> 8) * (1.0f / 16777216.0f); }

enum class Propagation {
    None,     // no inter-voxel propagation
    Fixed,    // along a fixed lattice direction (fire: up); stateless
    Velocity, // along a solver's velocity (upwind cell of the flow); step by step only
};

// Global dynamics (sec. 3.2).
struct PropagationDesc {
    Propagation mode = Propagation::Fixed; // default Fixed
    glm::ivec3 direction{0, 1, 0};         // lattice step a texture travels per propagation step (Fixed); default up (+y)
    float stepsPerSec = 8.0f;              // propagation steps per second (cells travelled per second, Fixed), > 0; default 8
    std::uint32_t offset = 1;              // added to the index at every hop ("offset slightly"); default 1
};

enum class Cycling {
    None,    // keep the propagated index
    Ordered, // phase-shift through the set in order, cyclically (cross-fade ready)
    Random,  // a new random texture at every tick (sec. 3.3's surprising result)
};

// Local dynamics (sec. 3.3).
struct CyclingDesc {
    Cycling mode = Cycling::Ordered; // default Ordered
    float texturesPerSec = 6.0f;     // rate control: ticks per second, >= 0; default 6
    float rateJitter = 0.0f;         // per-voxel rate varies by up to +-rateJitter (fraction), [0, 1); default 0
    bool randomStart = true;         // each voxel starts at a random point of its cycle; default true
};

struct TextureDynamicsDesc {
    PropagationDesc propagation{};
    CyclingDesc cycling{};
    std::uint32_t seed = 1; // every random choice derives from it; default 1
};

struct TextureSample {
    std::uint32_t texture = 0; // texture index (the renderer takes it modulo the set size)
    float phase = 0.0f;        // cross-fade weight towards texture + 1, [0, 1); 0 for Random cycling
};

// The recurrence's closed form, as free functions (see the header comment).
// Seed hash of cell c at step 0.
std::uint32_t initialIndex(glm::ivec3 cell, std::uint32_t seed);
// Seed hash of a source cell (no upwind voxel) at step n >= 1.
std::uint32_t sourceIndex(glm::ivec3 cell, std::int64_t step, std::uint32_t seed);
// index_n(c) for a cell with chainLength upwind voxels (K above). Expects step >= 0.
std::uint32_t propagatedIndex(glm::ivec3 cell, int chainLength, std::int64_t step, const PropagationDesc& desc, std::uint32_t seed);
// Propagation step count at t: floor(t * stepsPerSec). Expects t >= 0.
std::int64_t propagationStep(double timeSec, const PropagationDesc& desc);
// Local dynamics of one cell at t: the tick count and phase. Expects t >= 0.
TextureSample cycleSample(glm::ivec3 cell, double timeSec, const CyclingDesc& desc, std::uint32_t seed);

// Stateless global + local texture choice for a static lattice (the voxels of
// a grid; their opacities may change, the set of cells may not).
class TextureDynamics {
public:
    TextureDynamics() = default;
    // Records the lattice and each voxel's upwind chain length. Expects a
    // non-zero direction for Propagation::Fixed; Propagation::Velocity is not
    // stateless and is treated as None here (use TexturePropagator).
    TextureDynamics(const Grid& lattice, const TextureDynamicsDesc& desc);

    // Texture and phase of voxel i (index into the lattice grid's voxels) at t >= 0.
    TextureSample sample(std::size_t voxel, double timeSec) const;
    // Same for any cell of the lattice's bounding box (cells outside the lattice
    // count as sources). Slower: walks the upwind chain.
    TextureSample sampleCell(glm::ivec3 cell, double timeSec) const;
    // Writes texture and phase of every voxel of grid, which must hold the
    // lattice's voxels in the same order (same cells).
    void apply(Grid& grid, double timeSec) const;

    int chainLength(std::size_t voxel) const { return mChain[voxel]; }
    const TextureDynamicsDesc& desc() const { return mDesc; }

private:
    TextureDynamicsDesc mDesc{};
    std::vector<glm::ivec3> mCells;
    std::vector<int> mChain;
    glm::ivec3 mLo{0}, mSize{0};
    std::vector<std::uint8_t> mOccupied; // dense over [mLo, mLo + mSize)
    bool occupied(glm::ivec3 c) const;
};

// Step-by-step propagation on a dense lattice of dims cells (x fastest), for
// the solver path (and to check TextureDynamics against).
class TexturePropagator {
public:
    TexturePropagator() = default;
    // Every cell starts at initialIndex(cell, seed).
    TexturePropagator(glm::ivec3 dims, std::uint32_t seed);

    // One step of the sec. 3.2 recurrence along a fixed direction; occupied[i]
    // says whether cell i holds a voxel (cells that do not are not upwind of anything).
    void stepFixed(glm::ivec3 direction, std::uint32_t offset, const std::vector<std::uint8_t>& occupied);
    // Follows a velocity field (cells / s, one vec3 per cell): each occupied
    // cell accumulates the distance its flow travels and, for each whole cell,
    // takes the index of the neighbour upwind of the flow (the 26-neighbour
    // closest to -velocity) plus offset; with no occupied upwind neighbour it
    // is reseeded. Any dt >= 0 is fine (at most one hop per cell per call).
    void advanceFlow(const std::vector<glm::vec3>& velocityCellsPerSec, const std::vector<std::uint8_t>& occupied, double dtSec,
                     std::uint32_t offset);

    std::uint32_t index(glm::ivec3 cell) const { return mIndex[linear(cell)]; }
    // Overrides one cell's index (e.g. to mark a texture and watch it travel).
    void setIndex(glm::ivec3 cell, std::uint32_t value) { mIndex[linear(cell)] = value; }
    const std::vector<std::uint32_t>& indices() const { return mIndex; }
    std::int64_t steps() const { return mSteps; }
    glm::ivec3 dims() const { return mDims; }

private:
    std::size_t linear(glm::ivec3 c) const { return (std::size_t(c.z) * mDims.y + c.y) * mDims.x + c.x; }
    bool inside(glm::ivec3 c) const { return glm::all(glm::greaterThanEqual(c, glm::ivec3(0))) && glm::all(glm::lessThan(c, mDims)); }
    glm::ivec3 mDims{0};
    std::uint32_t mSeed = 1;
    std::int64_t mSteps = 0;
    std::vector<std::uint32_t> mIndex, mScratch;
    std::vector<float> mTravel;
};

} // namespace splatfx
