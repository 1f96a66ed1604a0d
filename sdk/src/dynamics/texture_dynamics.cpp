// Global (sec. 3.2) and local (sec. 3.3) texture dynamics of King et al. 1999.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "splatfx/dynamics.hpp"
#include "splatfx/grid.hpp"

namespace splatfx {
namespace {

// Salts keep the hash streams of different uses independent.
constexpr std::uint32_t kSaltInitial = 0x1000193u;
constexpr std::uint32_t kSaltSource = 0x2545f491u;
constexpr std::uint32_t kSaltRate = 0x3c6ef372u;
constexpr std::uint32_t kSaltStart = 0x5851f42du;
constexpr std::uint32_t kSaltRandom = 0x6a09e667u;

} // namespace

std::uint32_t initialIndex(glm::ivec3 cell, std::uint32_t seed) { return hashCell(cell, seed, kSaltInitial); }

std::uint32_t sourceIndex(glm::ivec3 cell, std::int64_t step, std::uint32_t seed) {
    // Two salts so steps 2^32 apart still differ (they never would in practice).
    return hashCell(cell, seed ^ std::uint32_t(std::uint64_t(step) >> 32) * kSaltSource, std::uint32_t(step) ^ kSaltSource);
}

std::uint32_t propagatedIndex(glm::ivec3 cell, int chain, std::int64_t n, const PropagationDesc& d, std::uint32_t seed) {
    assert(n >= 0 && "propagatedIndex: step must be >= 0");
    assert(chain >= 0 && "propagatedIndex: chainLength must be >= 0");
    if (n == 0) return initialIndex(cell, seed);
    // King et al. 1999, sec. 3.2, unrolled: the texture a voxel shows is the one
    // that entered its upwind chain n steps ago (or at the chain's source),
    // offset once per hop.
    if (n <= chain) return initialIndex(cell - int(n) * d.direction, seed) + std::uint32_t(n) * d.offset;
    return sourceIndex(cell - chain * d.direction, n - chain, seed) + std::uint32_t(chain) * d.offset;
}

std::int64_t propagationStep(double t, const PropagationDesc& d) {
    assert(t >= 0.0 && "propagationStep: timeSec must be >= 0");
    assert(d.stepsPerSec > 0.0f && "PropagationDesc::stepsPerSec must be > 0");
    return std::int64_t(std::floor(t * double(d.stepsPerSec)));
}

TextureSample cycleSample(glm::ivec3 cell, double t, const CyclingDesc& d, std::uint32_t seed) {
    assert(t >= 0.0 && "cycleSample: timeSec must be >= 0");
    assert(d.texturesPerSec >= 0.0f && "CyclingDesc::texturesPerSec must be >= 0");
    assert(d.rateJitter >= 0.0f && d.rateJitter < 1.0f && "CyclingDesc::rateJitter must be in [0, 1)");
    if (d.mode == Cycling::None) return {};
    // King et al. 1999, sec. 3.3: phase shifting through the set at a
    // controlled rate; per-voxel start and rate keep neighbours out of step.
    const double rate = double(d.texturesPerSec) * (1.0 + double(d.rateJitter) * (2.0 * hashUnit(hashCell(cell, seed, kSaltRate)) - 1.0));
    const double start = d.randomStart ? double(hashUnit(hashCell(cell, seed, kSaltStart))) : 0.0;
    const double p = t * rate + start;
    const double whole = std::floor(p);
    const auto tick = std::int64_t(whole);
    if (d.mode == Cycling::Random) return {hashCell(cell, seed ^ kSaltRandom, std::uint32_t(tick) ^ std::uint32_t(std::uint64_t(tick) >> 32)), 0.0f};
    float phase = float(p - whole);
    if (phase >= 1.0f) phase = std::nextafter(1.0f, 0.0f); // rounding of p - floor(p) to float
    return {std::uint32_t(tick), phase};
}

TextureDynamics::TextureDynamics(const Grid& lattice, const TextureDynamicsDesc& desc) : mDesc(desc) {
    assert((desc.propagation.mode != Propagation::Fixed || desc.propagation.direction != glm::ivec3(0)) &&
           "PropagationDesc::direction must be non-zero for Propagation::Fixed");
    mCells.reserve(lattice.voxels.size());
    glm::ivec3 lo(0), hi(-1);
    for (std::size_t i = 0; i < lattice.voxels.size(); ++i) {
        const glm::ivec3 c = lattice.voxels[i].cell;
        mCells.push_back(c);
        lo = i == 0 ? c : glm::min(lo, c);
        hi = i == 0 ? c : glm::max(hi, c);
    }
    mLo = lo;
    mSize = glm::max(hi - lo + 1, glm::ivec3(0));
    mOccupied.assign(std::size_t(mSize.x) * mSize.y * mSize.z, 0);
    for (const glm::ivec3& c : mCells) {
        const glm::ivec3 r = c - mLo;
        mOccupied[(std::size_t(r.z) * mSize.y + r.y) * mSize.x + r.x] = 1;
    }
    // Chain lengths: K(c) = K(c - d) + 1 if c - d is occupied, else 0. Walking
    // each chain from every voxel costs O(voxels x extent along d) (a
    // 4096x4096x1 fire never finished loading); memoized over the dense box,
    // each voxel is settled once: O(voxels) in all.
    mChain.assign(mCells.size(), 0);
    if (desc.propagation.mode != Propagation::Fixed) return;
    const glm::ivec3 d = desc.propagation.direction;
    auto dense = [&](glm::ivec3 c) {
        const glm::ivec3 r = c - mLo;
        return (std::size_t(r.z) * mSize.y + r.y) * mSize.x + r.x;
    };
    std::vector<int> chainAt(mOccupied.size(), -1); // -1: not settled yet (or not occupied)
    std::vector<glm::ivec3> pending;
    for (std::size_t i = 0; i < mCells.size(); ++i) {
        // Walk upwind until a settled cell or the chain's source, then settle the walk back down.
        glm::ivec3 c = mCells[i];
        pending.clear();
        int k = -1; // chain length of the cell upwind of the last pending one (-1: none, a source)
        while (chainAt[dense(c)] < 0) {
            pending.push_back(c);
            if (!occupied(c - d)) break;
            c -= d;
        }
        if (chainAt[dense(c)] >= 0) k = chainAt[dense(c)];
        for (auto it = pending.rbegin(); it != pending.rend(); ++it) chainAt[dense(*it)] = ++k;
        mChain[i] = chainAt[dense(mCells[i])];
    }
}

bool TextureDynamics::occupied(glm::ivec3 c) const {
    const glm::ivec3 r = c - mLo;
    if (glm::any(glm::lessThan(r, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(r, mSize))) return false;
    return mOccupied[(std::size_t(r.z) * mSize.y + r.y) * mSize.x + r.x] != 0;
}

TextureSample TextureDynamics::sampleCell(glm::ivec3 cell, double t) const {
    int k = 0;
    if (mDesc.propagation.mode == Propagation::Fixed)
        while (occupied(cell - (k + 1) * mDesc.propagation.direction)) ++k;
    std::uint32_t base = initialIndex(cell, mDesc.seed);
    if (mDesc.propagation.mode == Propagation::Fixed)
        base = propagatedIndex(cell, k, propagationStep(t, mDesc.propagation), mDesc.propagation, mDesc.seed);
    TextureSample s = cycleSample(cell, t, mDesc.cycling, mDesc.seed);
    s.texture += base;
    return s;
}

TextureSample TextureDynamics::sample(std::size_t i, double t) const {
    assert(i < mCells.size() && "TextureDynamics::sample: voxel index out of range");
    const glm::ivec3 cell = mCells[i];
    std::uint32_t base = initialIndex(cell, mDesc.seed);
    if (mDesc.propagation.mode == Propagation::Fixed)
        base = propagatedIndex(cell, mChain[i], propagationStep(t, mDesc.propagation), mDesc.propagation, mDesc.seed);
    TextureSample s = cycleSample(cell, t, mDesc.cycling, mDesc.seed);
    s.texture += base;
    return s;
}

void TextureDynamics::apply(Grid& grid, double t) const {
    assert(grid.voxels.size() == mCells.size() && "TextureDynamics::apply: grid is not the lattice it was built for");
    for (std::size_t i = 0; i < grid.voxels.size(); ++i) {
        assert(grid.voxels[i].cell == mCells[i] && "TextureDynamics::apply: voxel order differs from the lattice");
        const TextureSample s = sample(i, t);
        grid.voxels[i].texture = s.texture;
        grid.voxels[i].phase = s.phase;
    }
}

TexturePropagator::TexturePropagator(glm::ivec3 dims, std::uint32_t seed) : mDims(dims), mSeed(seed) {
    assert(dims.x > 0 && dims.y > 0 && dims.z > 0 && "TexturePropagator: dims must be positive");
    const std::size_t n = std::size_t(dims.x) * dims.y * dims.z;
    mIndex.resize(n);
    mTravel.assign(n, 0.0f);
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x) mIndex[linear({x, y, z})] = initialIndex({x, y, z}, seed);
}

void TexturePropagator::stepFixed(glm::ivec3 d, std::uint32_t offset, const std::vector<std::uint8_t>& occupied) {
    assert(occupied.size() == mIndex.size() && "TexturePropagator::stepFixed: occupied must have one entry per cell");
    ++mSteps;
    mScratch = mIndex;
    for (int z = 0; z < mDims.z; ++z)
        for (int y = 0; y < mDims.y; ++y)
            for (int x = 0; x < mDims.x; ++x) {
                const glm::ivec3 c{x, y, z}, u = c - d;
                // King et al. 1999, sec. 3.2: take the upwind voxel's texture of
                // the previous frame, offset slightly; seed where there is none.
                mScratch[linear(c)] = inside(u) && occupied[linear(u)] ? mIndex[linear(u)] + offset : sourceIndex(c, mSteps, mSeed);
            }
    mIndex.swap(mScratch);
}

void TexturePropagator::advanceFlow(const std::vector<glm::vec3>& vel, const std::vector<std::uint8_t>& occupied, double dt, std::uint32_t offset) {
    assert(vel.size() == mIndex.size() && occupied.size() == mIndex.size() &&
           "TexturePropagator::advanceFlow: one velocity and one occupied flag per cell");
    assert(dt >= 0.0 && "TexturePropagator::advanceFlow: dtSec must be >= 0");
    ++mSteps;
    mScratch = mIndex;
    for (int z = 0; z < mDims.z; ++z)
        for (int y = 0; y < mDims.y; ++y)
            for (int x = 0; x < mDims.x; ++x) {
                const glm::ivec3 c{x, y, z};
                const std::size_t i = linear(c);
                if (!occupied[i]) {
                    mTravel[i] = 0.0f;
                    continue;
                }
                const glm::vec3 v = vel[i];
                const float m = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
                if (!(m > 0.0f) || !std::isfinite(m)) continue;
                const double travelled = double(mTravel[i]) + double(glm::length(v)) * dt;
                if (travelled < 1.0) {
                    mTravel[i] = float(travelled);
                    continue;
                }
                mTravel[i] = float(travelled - std::floor(travelled));
                // Upwind 26-neighbour: components of -v at least half the largest.
                const glm::ivec3 step{std::abs(v.x) >= 0.5f * m ? (v.x > 0 ? 1 : -1) : 0, std::abs(v.y) >= 0.5f * m ? (v.y > 0 ? 1 : -1) : 0,
                                      std::abs(v.z) >= 0.5f * m ? (v.z > 0 ? 1 : -1) : 0};
                const glm::ivec3 u = c - step;
                mScratch[i] = inside(u) && occupied[linear(u)] ? mIndex[linear(u)] + offset : sourceIndex(c, mSteps, mSeed);
            }
    mIndex.swap(mScratch);
}

} // namespace splatfx
