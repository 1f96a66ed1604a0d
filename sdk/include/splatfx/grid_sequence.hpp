// splatfx/grid_sequence.hpp: a baked simulation as a sequence of coarse
// lattice frames (optical depth, colour coordinate, velocity per cell),
// played back as keyframed object dynamics.
//
// King et al. 1999, sec. 3.1 does object dynamics by "procedurally (or
// explicitly) changing the coarse voxel grid"; sec. 6 names simulation data
// as the natural next source. A GridSequence holds that data already
// resampled onto the coarse lattice: one frame per baked simulation frame,
// every frame on the same lattice (dims, spacing, transform). Sampling it at
// a time t interpolates linearly between the two frames around t (optical
// depth and velocity linearly, the colour coordinate weighted by optical
// depth: the colour of the mixed material), the sequence looping or held at
// its ends. Effect::fromSequence (effect.hpp) turns it into an effect with
// texture propagation along the recorded flow (sec. 3.2).
// It does not read files (splatfx/vdb.hpp fills one from OpenVDB files; any
// other importer can fill the fields directly) and does not render.
//
//   splatfx::GridSequence seq;                 // dims, spacing, transform, frames
//   if (Status s = seq.validate(); !s) return fail(s.error());
//   seq.sample(timeSec, grid, 0.01f);          // the interpolated coarse grid at t
//
// Threading: a plain value; const member functions may be called from any thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/grid.hpp"
#include "splatfx/result.hpp"

namespace splatfx {

// What happens after the last frame.
enum class SequenceEnd {
    Loop,  // wraps round: the last frame blends into the first over one frame interval (default)
    Clamp, // holds the first frame before 0 and the last frame after the end
};

// One baked frame on the sequence's lattice. Arrays hold one entry per
// lattice cell, x fastest, then y, then z (index (z * dims.y + y) * dims.x + x).
struct GridSequenceFrame {
    // Optical depth (natural-log units) of one cell edge: a ray crossing a
    // cubic cell along an axis keeps exp(-opticalDepth) of its light, so the
    // voxel's opacity is 1 - exp(-opticalDepth). >= 0 and finite.
    std::vector<float> opticalDepth;
    // Colour-table coordinate, [0, 1]; empty: every voxel's colour comes from its height.
    std::vector<float> colorCoord;
    // Velocity in lattice cells per second (grid-local axes); empty: no flow.
    std::vector<glm::vec3> velocityCellsPerSec;
};

// Where a time falls in the sequence: frames a and b, weight w of b.
struct SequencePosition {
    std::size_t a = 0;
    std::size_t b = 0;
    float weight = 0.0f; // [0, 1)
};

struct GridSequence {
    glm::ivec3 dims{0};                  // lattice cells along x, y, z; default 0 (empty)
    glm::vec3 spacing{1.0f};             // distance between lattice points, grid-local units; default 1
    glm::mat4 transform{1.0f};           // grid-local to world (as Grid::transform; Grid::localPosition centres x and z); default identity
    double framesPerSec = 24.0;          // playback rate, frames per second, > 0; default 24 (Blender's default)
    SequenceEnd end = SequenceEnd::Loop; // default Loop
    std::vector<GridSequenceFrame> frames;

    std::size_t cellCount() const { return std::size_t(dims.x) * std::size_t(dims.y) * std::size_t(dims.z); }
    std::size_t cellIndex(glm::ivec3 c) const {
        return (std::size_t(c.z) * std::size_t(dims.y) + std::size_t(c.y)) * std::size_t(dims.x) + std::size_t(c.x);
    }

    // Checks dims (positive, at most kMaxVoxels cells), spacing, framesPerSec,
    // at least one frame, every array's size and every value (finite,
    // optical depth >= 0, colour in [0, 1]). The message names the frame,
    // the field and the first bad cell.
    Status validate() const;

    // Frames around timeSec (any finite value): Loop wraps with period
    // frames.size() / framesPerSec; Clamp holds the ends.
    SequencePosition position(double timeSec) const;
    // Seconds the sequence plays before it repeats (Loop) or holds (Clamp).
    double durationSec() const;

    // The interpolated coarse grid at timeSec: dims, spacing and transform
    // from the sequence, one voxel per cell whose opacity 1 - exp(-depth) is
    // at least minOpacity (and above 0), texture 0, phase 0, no stretch.
    // Without colour data the colour coordinate is the normalized height.
    // Expects validate() to pass.
    void sample(double timeSec, Grid& out, float minOpacity = 0.0f) const;
    // Interpolated optical depth of every cell (cellCount() entries).
    void sampleDepth(double timeSec, std::vector<float>& out) const;
    // Interpolated velocity of every cell (zeros where frames carry none).
    void sampleVelocity(double timeSec, std::vector<glm::vec3>& out) const;
    // Whether any frame carries velocity.
    bool hasVelocity() const;
    // Largest optical depth of any cell in any frame (0: the sequence is empty everywhere).
    float maxDepth() const;
};

} // namespace splatfx
