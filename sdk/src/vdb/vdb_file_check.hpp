// A walk over an OpenVDB file's structure, done by splatfx before OpenVDB
// reads any of it. OpenVDB trusts every count and length in a file: a
// changed metadata length or entry count makes it allocate what the bytes
// claim (gigabytes from a 36 KB file), a root node claiming more children
// than the file holds makes it allocate nodes until memory runs out, and a
// compressed chunk's stated size is allocated as given. The walk checks each
// of those against the bytes actually present, in exactly the order OpenVDB
// 10's io::File reads them, so what OpenVDB then allocates is bounded by the
// file's size (and, for the trees, by what the importer's budgets allow).
//
// It also counts each imported grid's active voxels from the tree topology,
// tiles included (a tile's count is its node's extent cubed), and the
// bounding box of those voxels, before any voxel value is read.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>

#include "splatfx/result.hpp"

namespace splatfx::vdbfile {

// One grid the importer will read, as the walk found it.
struct GridLayout {
    std::string name;
    bool found = false;
    std::string type;               // OpenVDB's tree type name ("Tree_float_5_4_3"), "_HalfFloat" removed
    bool supported = false;         // a float or vec3s tree, not an instance: its tree was walked
    std::uint64_t activeVoxels = 0; // tiles included
    std::uint64_t tileVoxels = 0;   // of which in tiles
    std::uint64_t treeBytes = 0;    // estimate of OpenVDB's allocation for the tree
    openvdb::CoordBBox activeBox;   // of the active voxels, tiles included; empty when none
    std::string instanceOf;         // non-empty: the grid shares the tree of this one
};

// Walks the file's header, file metadata, every grid's descriptor, metadata
// and transform, and the trees of the named grids; with `buffers`, also the
// voxel buffers of those trees (everything io::File::readGrid reads). An
// error says what is wrong and where; the caller adds the file's name.
Result<std::vector<GridLayout>> walk(const std::string& path, const std::vector<std::string>& gridNames, bool buffers);

} // namespace splatfx::vdbfile
