// splatfx/vdb.hpp: OpenVDB files (a simulation's density, temperature and
// velocity) to a GridSequence on the coarse lattice. Target splatfx::vdb,
// built only when OpenVDB is found (find_package(splatfx COMPONENTS vdb)).
//
// Reads one .vdb file or a numbered sequence (Blender's mantaflow cache,
// EmberGen, Houdini) and resamples each frame onto a coarse lattice whose
// cells are blocks of N x N x N file voxels (N = voxelsPerCell), aligned to
// multiples of N in the file's index space, the same lattice for every frame:
//   density      box average over the block: the coarse cell holds exactly
//                the block's integrated density, so its optical depth
//                tau = extinctionPerDensity * mean density * N * voxelSize
//                equals the mean of the file-resolution optical depths of
//                the axis-aligned rays through the block (opacity 1 - e^-tau);
//   temperature  density-weighted mean over the block (the temperature of the
//                material, not of the empty air around it), mapped to the
//                colour coordinate 1 - (T - cold) / (hot - cold), clamped:
//                hottest at 0, as the SDK's fire tables and solver expect;
//   velocity     box average over the block, times velocityScale, in lattice
//                cells per second (a staggered velocity grid is averaged as if
//                cell-centred: half a file voxel, well inside one coarse cell).
// Before OpenVDB reads a file, splatfx walks its structure (header, metadata,
// grid descriptors, transforms, trees; and before each frame's voxels are
// read, their buffers) and checks every count, length and offset against the
// bytes present: OpenVDB allocates whatever a file claims, so a corrupted
// file is refused ("refused before OpenVDB reads it: ...", naming what is
// wrong and where) instead of exhausting memory. Formats 222 to 224 (OpenVDB
// 3.0 onwards) with grid offsets are read; instanced grids are not.
// Before any voxel data is read, every frame is checked (grid present, float
// or vec3s type, a fog volume, active voxels counted from the tree with tiles
// included, above 0 and within maxFileVoxels, the tree's memory within
// maxTreeBytes, the sequence's voxels within maxSequenceVoxels, a transform
// that is a uniform scale plus translation and equal in every grid and
// frame); each error names the file, the frame and the grid. Frames are then
// read one at a time (each released before the next); tiles are filled by
// region, not voxel by voxel.
// It does not write VDB files, render, or keep files open, and it reads no
// grid other than the three named.
//
//   auto seq = splatfx::loadVdbSequence("smoke/fluid_data_####.vdb", 1, 24, {.maxCellsPerAxis = 24});
//   if (!seq) return fail(seq.error());
//   auto smoke = splatfx::Effect::fromSequence(std::move(*seq), desc);
//
// Threading: the functions touch only their arguments (OpenVDB's own
// type registry is initialized on first use, which OpenVDB makes thread-safe).
#pragma once

#include <cstdint>
#include <limits>
#include <string>

#include "splatfx/grid_sequence.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/result.hpp"

namespace splatfx {

// Largest coarse cells x frames a sequence may hold (each cell-frame is 20
// bytes: optical depth, colour, velocity): 2^27, 2.5 GiB.
inline constexpr std::uint64_t kMaxVdbSequenceCells = std::uint64_t(1) << 27;

struct VdbImportDesc {
    std::string densityGrid = "density"; // float grid, required; default "density"
    std::string temperatureGrid =
        "temperature";                     // float grid; empty: colour by height; default "temperature" (Blender; "flame" and "heat" are common too)
    std::string velocityGrid = "velocity"; // vec3s grid; empty: no flow; default "velocity"
    // File voxels per coarse cell along every axis, >= 1; 0: the smallest
    // that keeps the union of the frames' density boxes within
    // maxCellsPerAxis cells along its longest side. Default 0.
    int voxelsPerCell = 0;
    int maxCellsPerAxis = 24; // used when voxelsPerCell is 0, >= 1; default 24
    // Extinction coefficient per unit density, per world unit of the file
    // (sigma = density * this). Default 1.
    float extinctionPerDensity = 1.0f;
    // Temperature mapped to colour coordinate 0 (hot) and 1 (cold); when
    // both are NaN, the hottest and coldest coarse cells holding material
    // over all frames. Default NaN (automatic).
    float temperatureHot = std::numeric_limits<float>::quiet_NaN();
    float temperatureCold = std::numeric_limits<float>::quiet_NaN();
    // The unit of the file's velocity grid: world units per second, or file
    // voxels per second (Blender 3.4's mantaflow cache: on the committed bake
    // the density-weighted mean upward velocity, 14.8 voxels/s at frame 16,
    // matches the density centroid rising about 16 voxels/s).
    enum class VelocityUnit { WorldPerSec, VoxelsPerSec };
    VelocityUnit velocityUnit = VelocityUnit::WorldPerSec; // default WorldPerSec
    float velocityScale = 1.0f;                            // multiplies the file's velocity (after the unit); default 1
    double framesPerSec = 24.0;                            // playback rate of the sequence, > 0; default 24
    SequenceEnd end = SequenceEnd::Loop;                   // default Loop
    // A grid with more active voxels than this, tiles included (a tile counts
    // its node's extent cubed: 512, 2^21 or 2^36 voxels), is refused; counted
    // from the file's tree before any voxel value is read. Default 2^28 (1 GiB
    // of floats).
    std::uint64_t maxFileVoxels = std::uint64_t(1) << 28;
    // A grid whose tree would take OpenVDB more memory than this (its nodes and
    // voxel buffers, estimated from the file's tree before OpenVDB reads it) is
    // refused. Default 2^32 (4 GiB).
    std::uint64_t maxTreeBytes = std::uint64_t(1) << 32;
    // The active voxels of all imported grids of all frames, tiles included,
    // may not exceed this; checked frame by frame before any voxel value is
    // read. Tiles are filled by region, so a tiled voxel costs far less than a
    // leaf's; this bounds the work of long sequences. Default 2^36.
    std::uint64_t maxSequenceVoxels = std::uint64_t(1) << 36;
};

// One file as a one-frame sequence (frame number 0 in messages).
Result<GridSequence> loadVdb(const std::string& path, const VdbImportDesc& desc = {});

// Files pattern with the frame number in place of its run of '#' (zero-padded
// to the run's length: "fluid_data_####.vdb" -> "fluid_data_0007.vdb"), for
// firstFrame..lastFrame. lastFrame < firstFrame: every consecutive frame
// from firstFrame whose file exists (at least one). Sequence frame i is file
// frame firstFrame + i.
Result<GridSequence> loadVdbSequence(const std::string& pattern, int firstFrame, int lastFrame, const VdbImportDesc& desc = {});

// One file's density grid at full resolution, for references (denseMedium:
// what the coarse lattice is measured against): the box of its active voxels
// (tiles included) as a dense array of the file's values, inactive voxels 0,
// with the file's voxel size and the world centre of the box's first voxel.
// Refused like loadVdb (the file walked before OpenVDB reads it, desc's grid
// name and budgets, a float fog volume, a uniform scale plus translation,
// finite densities >= 0), and when the box holds more than maxVoxels.
Result<DenseVoxels> readVdbDensity(const std::string& path, const VdbImportDesc& desc = {}, std::uint64_t maxVoxels = std::uint64_t(1) << 26);

// The file name for one frame of a pattern (see loadVdbSequence); the
// pattern unchanged when it has no '#'.
std::string vdbFramePath(const std::string& pattern, int frame);

} // namespace splatfx
