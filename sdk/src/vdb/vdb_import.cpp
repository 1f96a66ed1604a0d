// OpenVDB import (splatfx::vdb): every frame's file walked (vdb_file_check:
// its structure checked against its bytes, each grid's voxels counted, tiles
// included) and its grid metadata checked first; then frame by frame the file
// walked again down to its voxel buffers, read by OpenVDB, and its density,
// temperature and velocity box-filtered onto one coarse lattice (see
// splatfx/vdb.hpp for the filters and why the density filter preserves each
// coarse cell's optical depth). OpenVDB throws; no exception leaves this file.
#include "splatfx/vdb.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <openvdb/openvdb.h>

#include "vdb_file_check.hpp"

namespace splatfx {
namespace {

constexpr int kMaxFrames = 100000; // a sequence longer than this is a pattern mistake

std::string num(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
}

std::string where(const std::string& path, int frame, const std::string& grid) {
    return "OpenVDB file '" + path + "' (frame " + std::to_string(frame) + "), grid '" + grid + "': ";
}

// floor(a / b) for b > 0.
int floorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// What the metadata of one frame says, before any voxel is read.
struct FrameInfo {
    std::string path;
    int frame = 0;
    openvdb::math::Transform::Ptr transform;
    openvdb::CoordBBox densityBox; // of the active voxels, tiles included (from the walk)
};

// Checks one grid's metadata: present, of the expected type, a fog volume.
template <class GridT>
Status checkGrid(const openvdb::GridPtrVec& grids, const std::string& path, int frame, const std::string& name, const char* typeWanted,
                 openvdb::GridBase::ConstPtr& found) {
    const std::string at = where(path, frame, name);
    std::string names;
    for (const auto& g : grids) {
        if (!g) continue;
        if (g->getName() == name) found = g;
        names += (names.empty() ? "" : ", ") + ("'" + g->getName() + "'");
    }
    if (!found) return makeError(at + "no such grid in the file (it has " + (names.empty() ? std::string("no grids") : names) + ")");
    if (!found->isType<GridT>()) return makeError(at + "holds " + found->valueType() + " values; expected a " + typeWanted + " grid");
    if (found->getGridClass() == openvdb::GRID_LEVEL_SET) return makeError(at + "is a level set (signed distances), not a density/fog volume");
    return {};
}

// The walk's counts for one grid against the budgets; `total` adds up the
// sequence's voxels so far.
Status checkLayout(const vdbfile::GridLayout& g, const std::string& path, int frame, const VdbImportDesc& desc, std::uint64_t& total) {
    const std::string at = where(path, frame, g.name);
    // The metadata named the grid but its descriptor does not: OpenVDB would read another grid.
    if (!g.found) return makeError(at + "is named in the grids' metadata but no grid descriptor has that name; the file is inconsistent");
    if (!g.instanceOf.empty())
        return makeError(at + "is an instance of grid '" + g.instanceOf + "' (it shares that grid's tree); instanced grids are not supported");
    if (!g.supported) return makeError(at + "has tree type " + g.type + "; expected Tree_float_5_4_3 or Tree_vec3s_5_4_3");
    if (g.activeVoxels == 0) return makeError(at + "is empty (no active voxels)");
    if (g.activeVoxels > desc.maxFileVoxels)
        return makeError(at + "has " + std::to_string(g.activeVoxels) + " active voxels (" + std::to_string(g.tileVoxels) +
                         " of them in tiles; counted from the file's tree, no voxel value read); the limit is " + std::to_string(desc.maxFileVoxels) +
                         " (VdbImportDesc::maxFileVoxels)");
    if (g.treeBytes > desc.maxTreeBytes)
        return makeError(at + "would take about " + std::to_string(g.treeBytes) +
                         " bytes of memory in OpenVDB (estimated from the nodes of the file's tree before OpenVDB reads it); the limit is " +
                         std::to_string(desc.maxTreeBytes) + " (VdbImportDesc::maxTreeBytes)");
    total = g.activeVoxels > std::numeric_limits<std::uint64_t>::max() - total ? std::numeric_limits<std::uint64_t>::max() : total + g.activeVoxels;
    if (total > desc.maxSequenceVoxels)
        return makeError(at + "brings the voxels to expand to " + std::to_string(total) + " (tiles included, over the imported grids of frames " +
                         "up to this one); the limit is " + std::to_string(desc.maxSequenceVoxels) + " (VdbImportDesc::maxSequenceVoxels)");
    return {};
}

// The transform must be a uniform scale plus a translation (axis-aligned
// cubic voxels): the box filter's exactness needs blocks of whole voxels.
Status checkTransform(const openvdb::math::Transform& xf, const std::string& at, double& voxelSize, openvdb::Vec3d& origin) {
    if (!xf.isLinear()) return makeError(at + "has a non-linear (frustum) transform; only a uniform scale plus translation is supported");
    const openvdb::Mat4d m = xf.baseMap()->getAffineMap()->getMat4();
    const double s = m(0, 0);
    const double tol = 1e-9 * std::abs(s);
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
            const double want = r == c ? s : 0.0;
            if (std::abs(m(r, c) - want) > tol)
                return makeError(at + "has a rotated, sheared or non-uniform transform (voxel size " + num(xf.voxelSize()[0]) + ", " +
                                 num(xf.voxelSize()[1]) + ", " + num(xf.voxelSize()[2]) + "); only a uniform scale plus translation is supported");
        }
    if (!(s > 0.0) || !std::isfinite(s)) return makeError(at + "has voxel size " + num(s) + "; expected a positive finite value");
    voxelSize = s;
    origin = openvdb::Vec3d(m(3, 0), m(3, 1), m(3, 2)); // OpenVDB matrices act on row vectors: translation in row 3
    return {};
}

// Calls voxel(coord, value) for every active voxel of the grid and
// tile(box, value) for every active tile: a tile is filled by region, never
// voxel by voxel (a 128^3 tile is 2 million voxels).
template <class GridT, class V, class T>
void forEachActive(const GridT& grid, V&& voxel, T&& tile) {
    for (auto it = grid.cbeginValueOn(); it; ++it) {
        if (it.isVoxelValue()) {
            voxel(it.getCoord(), *it);
        } else {
            openvdb::CoordBBox b;
            it.getBoundingBox(b);
            tile(b, *it);
        }
    }
}

struct Lattice {
    int factor = 1;
    openvdb::Coord lo; // first coarse cell, in coarse cell units of the file's index space
    glm::ivec3 dims{0};
    double voxelSize = 1.0;
    openvdb::Vec3d origin{0.0};

    // Linear cell index of a file voxel, or -1 outside the lattice.
    std::int64_t cellOf(const openvdb::Coord& c) const {
        const int x = floorDiv(c.x(), factor) - lo.x(), y = floorDiv(c.y(), factor) - lo.y(), z = floorDiv(c.z(), factor) - lo.z();
        if (x < 0 || y < 0 || z < 0 || x >= dims.x || y >= dims.y || z >= dims.z) return -1;
        return (std::int64_t(z) * dims.y + y) * dims.x + x;
    }

    // Calls f(cell, voxels) for every cell the box of file voxels overlaps,
    // with the number of the box's voxels inside that cell.
    template <class F>
    void forEachCell(const openvdb::CoordBBox& box, F&& f) const {
        int from[3], to[3];
        for (int a = 0; a < 3; ++a) {
            from[a] = std::max(floorDiv(box.min()[a], factor) - lo[a], 0);
            to[a] = std::min(floorDiv(box.max()[a], factor) - lo[a], (a == 0 ? dims.x : a == 1 ? dims.y : dims.z) - 1);
            if (from[a] > to[a]) return;
        }
        auto overlap = [&](int a, int cell) {
            const std::int64_t c0 = std::int64_t(cell + lo[a]) * factor, c1 = c0 + factor - 1;
            return std::min<std::int64_t>(box.max()[a], c1) - std::max<std::int64_t>(box.min()[a], c0) + 1;
        };
        for (int z = from[2]; z <= to[2]; ++z)
            for (int y = from[1]; y <= to[1]; ++y) {
                const std::int64_t yz = overlap(1, y) * overlap(2, z);
                for (int x = from[0]; x <= to[0]; ++x) f((std::int64_t(z) * dims.y + y) * dims.x + x, double(overlap(0, x) * yz));
            }
    }
};

// The frame being checked or read, for a message when OpenVDB throws where it was not expected to.
struct Current {
    std::string path;
    int frame = 0;
};

Result<GridSequence> loadFrames(const std::vector<std::string>& paths, const std::vector<int>& frameNumbers, const VdbImportDesc& desc,
                                Current& cur) {
    if (desc.densityGrid.empty()) return makeError("VdbImportDesc::densityGrid is empty; name the density grid (e.g. \"density\")");
    if (desc.voxelsPerCell < 0) return makeError("VdbImportDesc::voxelsPerCell is " + std::to_string(desc.voxelsPerCell) + "; expected >= 0");
    if (desc.voxelsPerCell == 0 && desc.maxCellsPerAxis < 1)
        return makeError("VdbImportDesc::maxCellsPerAxis is " + std::to_string(desc.maxCellsPerAxis) + "; expected >= 1");
    if (!(desc.extinctionPerDensity >= 0.0f) || !std::isfinite(desc.extinctionPerDensity))
        return makeError("VdbImportDesc::extinctionPerDensity is " + num(desc.extinctionPerDensity) + "; expected a finite value >= 0");
    if (!std::isfinite(desc.velocityScale)) return makeError("VdbImportDesc::velocityScale is not finite");
    if (!(desc.framesPerSec > 0.0) || !std::isfinite(desc.framesPerSec))
        return makeError("VdbImportDesc::framesPerSec is " + num(desc.framesPerSec) + "; expected a positive finite value");
    const bool autoRange = std::isnan(desc.temperatureHot) && std::isnan(desc.temperatureCold);
    if (!autoRange && !(std::isfinite(desc.temperatureHot) && std::isfinite(desc.temperatureCold) && desc.temperatureHot != desc.temperatureCold))
        return makeError("VdbImportDesc::temperatureHot and temperatureCold must both be NaN (automatic) or finite and different; got " +
                         num(desc.temperatureHot) + " and " + num(desc.temperatureCold));

    openvdb::initialize();
    std::vector<std::string> gridNames{desc.densityGrid};
    if (!desc.temperatureGrid.empty()) gridNames.push_back(desc.temperatureGrid);
    if (!desc.velocityGrid.empty()) gridNames.push_back(desc.velocityGrid);
    std::uint64_t sequenceVoxels = 0;
    // Pass 2's walk of one frame's file, down to the voxel buffers, with its counts checked again.
    auto walkFrame = [&](const std::string& path, int frame, bool buffers) -> Status {
        auto walked = vdbfile::walk(path, gridNames, buffers);
        if (!walked)
            return makeError("OpenVDB file '" + path + "' (frame " + std::to_string(frame) + "): refused before OpenVDB reads it: " + walked.error());
        std::uint64_t total = 0;
        for (const vdbfile::GridLayout& g : *walked)
            if (Status s = checkLayout(g, path, frame, desc, total); !s) return s;
        return {};
    };

    std::vector<FrameInfo> infos;
    // Pass 1: every frame's structure, voxel counts and metadata, so a bad frame 200 fails
    // before frame 1's voxels are read. Only what is needed for the lattice is kept.
    for (std::size_t i = 0; i < paths.size(); ++i) {
        FrameInfo fi;
        fi.path = paths[i];
        fi.frame = frameNumbers[i];
        cur = {fi.path, fi.frame};
        const std::string fileAt = "OpenVDB file '" + fi.path + "' (frame " + std::to_string(fi.frame) + "): ";
        std::error_code ec;
        if (!std::filesystem::is_regular_file(fi.path, ec)) return makeError(fileAt + "no such file");
        auto walked = vdbfile::walk(fi.path, gridNames, false);
        if (!walked) return makeError(fileAt + "refused before OpenVDB reads it: " + walked.error());
        const std::vector<vdbfile::GridLayout> layouts = std::move(*walked);
        openvdb::GridPtrVecPtr grids;
        try {
            openvdb::io::File file(fi.path);
            file.open(false);
            grids = file.readAllGridMetadata();
            file.close();
        } catch (const std::exception& e) { return makeError(fileAt + "cannot be read as OpenVDB: " + e.what()); }
        openvdb::GridBase::ConstPtr density, temperature, velocity;
        if (Status s = checkGrid<openvdb::FloatGrid>(*grids, fi.path, fi.frame, desc.densityGrid, "float", density); !s) return makeError(s.error());
        if (!desc.temperatureGrid.empty())
            if (Status s = checkGrid<openvdb::FloatGrid>(*grids, fi.path, fi.frame, desc.temperatureGrid, "float", temperature); !s)
                return makeError(s.error());
        if (!desc.velocityGrid.empty())
            if (Status s = checkGrid<openvdb::Vec3SGrid>(*grids, fi.path, fi.frame, desc.velocityGrid, "vec3s (float vector)", velocity); !s)
                return makeError(s.error());
        for (const vdbfile::GridLayout& g : layouts)
            if (Status s = checkLayout(g, fi.path, fi.frame, desc, sequenceVoxels); !s) return makeError(s.error());
        fi.densityBox = layouts[0].activeBox;
        fi.transform = density->transform().copy();
        double vs = 0.0;
        openvdb::Vec3d origin;
        if (Status s = checkTransform(*fi.transform, where(fi.path, fi.frame, desc.densityGrid), vs, origin); !s) return makeError(s.error());
        for (const auto& other : {temperature, velocity})
            if (other && !(other->transform() == *fi.transform))
                return makeError(where(fi.path, fi.frame, other->getName()) + "has a transform different from grid '" + desc.densityGrid +
                                 "' in the same file (voxel size " + num(other->transform().voxelSize()[0]) + " vs " + num(vs) +
                                 "); every imported grid must share one transform");
        if (!infos.empty() && !(*fi.transform == *infos[0].transform)) {
            const openvdb::Vec3d o0 = infos[0].transform->indexToWorld(openvdb::Vec3d(0.0)), o1 = fi.transform->indexToWorld(openvdb::Vec3d(0.0));
            return makeError(where(fi.path, fi.frame, desc.densityGrid) + "has a transform different from frame " + std::to_string(infos[0].frame) +
                             "'s ('" + infos[0].path + "'): voxel size " + num(vs) + " vs " + num(infos[0].transform->voxelSize()[0]) +
                             ", index origin at (" + num(o1[0]) + ", " + num(o1[1]) + ", " + num(o1[2]) + ") vs (" + num(o0[0]) + ", " + num(o0[1]) +
                             ", " + num(o0[2]) + "); every frame of a sequence must share one transform");
        }
        infos.push_back(std::move(fi));
    }

    // Pass 2, frame by frame: the file walked again, down to the voxel buffers OpenVDB is
    // about to read (the checks of pass 1 repeated, in case the file changed), then read,
    // resampled, and let go before the next frame.
    struct Loaded {
        openvdb::FloatGrid::ConstPtr density, temperature;
        openvdb::Vec3SGrid::ConstPtr velocity;
    };
    auto readFrame = [&](const FrameInfo& fi, Loaded& out) -> Status {
        if (Status s = walkFrame(fi.path, fi.frame, true); !s) return s;
        try {
            openvdb::io::File file(fi.path);
            file.open(false);
            out.density = openvdb::gridConstPtrCast<openvdb::FloatGrid>(file.readGrid(desc.densityGrid));
            if (!desc.temperatureGrid.empty()) out.temperature = openvdb::gridConstPtrCast<openvdb::FloatGrid>(file.readGrid(desc.temperatureGrid));
            if (!desc.velocityGrid.empty()) out.velocity = openvdb::gridConstPtrCast<openvdb::Vec3SGrid>(file.readGrid(desc.velocityGrid));
            file.close();
        } catch (const std::exception& e) {
            return makeError("OpenVDB file '" + fi.path + "' (frame " + std::to_string(fi.frame) + "): reading the grids failed: " + e.what());
        }
        const std::string at = where(fi.path, fi.frame, desc.densityGrid);
        if (!out.density) return makeError(at + "could not be read as a float grid");
        if (out.density->background() != 0.0f)
            return makeError(at + "has background " + num(out.density->background()) + "; a density grid's empty space must be 0");
        return {};
    };

    // The lattice: the union of the frames' density boxes, in blocks of `factor` voxels.
    openvdb::CoordBBox unionBox;
    for (const FrameInfo& fi : infos) unionBox.expand(fi.densityBox);
    Lattice lat;
    {
        openvdb::Vec3d origin;
        (void)checkTransform(*infos[0].transform, "", lat.voxelSize, origin);
        lat.origin = origin;
    }
    const openvdb::Coord extent = unionBox.dim();
    const int longest = std::max({extent.x(), extent.y(), extent.z()});
    lat.factor = desc.voxelsPerCell > 0 ? desc.voxelsPerCell : std::max(1, (longest + desc.maxCellsPerAxis - 1) / desc.maxCellsPerAxis);
    lat.lo =
        openvdb::Coord(floorDiv(unionBox.min().x(), lat.factor), floorDiv(unionBox.min().y(), lat.factor), floorDiv(unionBox.min().z(), lat.factor));
    const openvdb::Coord hi(floorDiv(unionBox.max().x(), lat.factor), floorDiv(unionBox.max().y(), lat.factor),
                            floorDiv(unionBox.max().z(), lat.factor));
    const std::uint64_t cells =
        std::uint64_t(hi.x() - lat.lo.x() + 1) * std::uint64_t(hi.y() - lat.lo.y() + 1) * std::uint64_t(hi.z() - lat.lo.z() + 1);
    if (cells > kMaxVoxels)
        return makeError(where(infos[0].path, infos[0].frame, desc.densityGrid) + "the frames' density spans " + std::to_string(extent.x()) + " x " +
                         std::to_string(extent.y()) + " x " + std::to_string(extent.z()) + " voxels; at " + std::to_string(lat.factor) +
                         " voxels per cell that is " + std::to_string(cells) + " coarse cells, more than " + std::to_string(kMaxVoxels) +
                         " (raise VdbImportDesc::voxelsPerCell)");
    lat.dims = glm::ivec3(hi.x() - lat.lo.x() + 1, hi.y() - lat.lo.y() + 1, hi.z() - lat.lo.z() + 1);
    if (cells * infos.size() > kMaxVdbSequenceCells)
        return makeError(where(infos[0].path, infos[0].frame, desc.densityGrid) + "the sequence would hold " + std::to_string(cells) +
                         " coarse cells x " + std::to_string(infos.size()) + " frames, more than " + std::to_string(kMaxVdbSequenceCells) +
                         " cells in all (kMaxVdbSequenceCells); raise VdbImportDesc::voxelsPerCell or load fewer frames");

    GridSequence seq;
    seq.dims = lat.dims;
    const double cellWorld = lat.voxelSize * lat.factor;
    seq.spacing = glm::vec3(float(cellWorld));
    seq.framesPerSec = desc.framesPerSec;
    seq.end = desc.end;
    {
        // World position of coarse cell 0's centre: the centre of its block,
        // file index lo * factor + (factor - 1) / 2 (OpenVDB voxel centres sit
        // on integer index coordinates). Grid::localPosition centres x and z,
        // so the transform adds that half-extent back.
        const double c0 = 0.5 * double(lat.factor - 1);
        const openvdb::Vec3d p0 = infos[0].transform->indexToWorld(
            openvdb::Vec3d(lat.lo.x() * double(lat.factor) + c0, lat.lo.y() * double(lat.factor) + c0, lat.lo.z() * double(lat.factor) + c0));
        const glm::dvec3 half(0.5 * (lat.dims.x - 1) * cellWorld, 0.0, 0.5 * (lat.dims.z - 1) * cellWorld);
        seq.transform = glm::mat4(1.0f);
        seq.transform[3] = glm::vec4(glm::vec3(glm::dvec3(p0[0], p0[1], p0[2]) + half), 1.0f);
    }
    const std::size_t n = seq.cellCount();
    const double blockVoxels = double(lat.factor) * lat.factor * lat.factor;
    // tau = sigma_mean * edge = extinction * (sum of density / voxels in block) * cellWorld.
    const double depthPerDensitySum = double(desc.extinctionPerDensity) * cellWorld / blockVoxels;
    std::vector<std::vector<double>> temperatures; // per frame, density-weighted mean (NaN: no material)
    float tMin = std::numeric_limits<float>::infinity(), tMax = -std::numeric_limits<float>::infinity();

    for (std::size_t i = 0; i < infos.size(); ++i) {
        const FrameInfo& fi = infos[i];
        cur = {fi.path, fi.frame};
        Loaded g;
        if (Status s = readFrame(fi, g); !s) return makeError(s.error());
        GridSequenceFrame frame;
        std::vector<double> sum(n, 0.0), sumT(n, 0.0);
        auto tAcc = g.temperature ? std::make_unique<openvdb::FloatGrid::ConstAccessor>(g.temperature->getConstAccessor()) : nullptr;
        bool negative = false;
        auto bad = [&](float d) { return !(d >= 0.0f) || !std::isfinite(d); };
        forEachActive(
            *g.density,
            [&](const openvdb::Coord& c, float d) {
                const std::int64_t k = lat.cellOf(c);
                if (k < 0 || d == 0.0f) return;
                if (bad(d)) return void(negative = true);
                sum[std::size_t(k)] += d;
                if (tAcc) sumT[std::size_t(k)] += double(d) * double(tAcc->getValue(c));
            },
            [&](const openvdb::CoordBBox& box, float d) {
                if (d == 0.0f) return;
                if (bad(d)) return void(negative = true);
                if (!tAcc) return lat.forEachCell(box, [&](std::int64_t k, double count) { sum[std::size_t(k)] += d * count; });
                // The temperature varies inside the tile only where it has leaves (8^3 voxels,
                // aligned to 8 as every tile is): per voxel there, per 8^3 block elsewhere.
                for (int z = box.min().z(); z <= box.max().z(); z += 8)
                    for (int y = box.min().y(); y <= box.max().y(); y += 8)
                        for (int x = box.min().x(); x <= box.max().x(); x += 8) {
                            const openvdb::Coord o(x, y, z);
                            if (const auto* leaf = tAcc->probeConstLeaf(o)) {
                                for (auto c = leaf->getNodeBoundingBox().begin(); c; ++c) {
                                    const std::int64_t k = lat.cellOf(*c);
                                    if (k < 0) continue;
                                    sum[std::size_t(k)] += d;
                                    sumT[std::size_t(k)] += double(d) * double(leaf->getValue(*c));
                                }
                            } else {
                                const double t = tAcc->getValue(o);
                                lat.forEachCell(openvdb::CoordBBox(o, o.offsetBy(7)), [&](std::int64_t k, double count) {
                                    sum[std::size_t(k)] += d * count;
                                    sumT[std::size_t(k)] += double(d) * t * count;
                                });
                            }
                        }
            });
        if (negative)
            return makeError(where(fi.path, fi.frame, desc.densityGrid) + "holds negative, NaN or infinite densities; expected finite values >= 0");
        frame.opticalDepth.resize(n);
        for (std::size_t k = 0; k < n; ++k) frame.opticalDepth[k] = float(sum[k] * depthPerDensitySum);
        if (g.temperature) {
            std::vector<double> t(n, std::numeric_limits<double>::quiet_NaN());
            for (std::size_t k = 0; k < n; ++k)
                if (sum[k] > 0.0 && frame.opticalDepth[k] > 0.0f) {
                    t[k] = sumT[k] / sum[k];
                    if (!std::isfinite(t[k]))
                        return makeError(where(fi.path, fi.frame, desc.temperatureGrid) +
                                         "holds NaN or infinite temperatures where there is density");
                    tMin = std::min(tMin, float(t[k]));
                    tMax = std::max(tMax, float(t[k]));
                }
            temperatures.push_back(std::move(t));
        }
        if (g.velocity) {
            const openvdb::Vec3s bg = g.velocity->background();
            std::vector<glm::dvec3> v(n, glm::dvec3(0.0));
            bool nonFinite = false;
            auto add = [&](std::int64_t k, const openvdb::Vec3s& u, double count) {
                if (!std::isfinite(u[0]) || !std::isfinite(u[1]) || !std::isfinite(u[2])) nonFinite = true;
                v[std::size_t(k)] += count * glm::dvec3(u[0] - bg[0], u[1] - bg[1], u[2] - bg[2]);
            };
            forEachActive(
                *g.velocity,
                [&](const openvdb::Coord& c, const openvdb::Vec3s& u) {
                    if (const std::int64_t k = lat.cellOf(c); k >= 0) add(k, u, 1.0);
                },
                [&](const openvdb::CoordBBox& box, const openvdb::Vec3s& u) {
                    lat.forEachCell(box, [&](std::int64_t k, double count) { add(k, u, count); });
                });
            if (nonFinite) return makeError(where(fi.path, fi.frame, desc.velocityGrid) + "holds NaN or infinite velocities");
            // World units (or file voxels) per second to lattice cells per second.
            const double unit = desc.velocityUnit == VdbImportDesc::VelocityUnit::VoxelsPerSec ? lat.voxelSize : 1.0;
            const double toCells = double(desc.velocityScale) * unit / cellWorld;
            frame.velocityCellsPerSec.resize(n);
            for (std::size_t k = 0; k < n; ++k) {
                const glm::dvec3 mean = glm::dvec3(bg[0], bg[1], bg[2]) + v[k] / blockVoxels;
                frame.velocityCellsPerSec[k] = glm::vec3(mean * toCells);
            }
        }
        seq.frames.push_back(std::move(frame));
    }

    if (!desc.temperatureGrid.empty()) {
        float hot = desc.temperatureHot, cold = desc.temperatureCold;
        if (autoRange) hot = tMax, cold = tMin;
        const double span = double(hot) - double(cold);
        for (std::size_t i = 0; i < seq.frames.size(); ++i) {
            std::vector<float>& cc = seq.frames[i].colorCoord;
            cc.assign(n, 0.0f);
            for (std::size_t k = 0; k < n; ++k) {
                const double t = temperatures[i][k];
                if (std::isnan(t)) continue; // no material: the colour is never seen (depth-weighted)
                // An automatic range of one temperature maps everything to hot.
                const double u = span != 0.0 ? (t - double(cold)) / span : 1.0;
                cc[k] = float(std::clamp(1.0 - u, 0.0, 1.0));
            }
        }
    }
    if (Status s = seq.validate(); !s) return makeError("OpenVDB import of '" + infos[0].path + "': " + s.error());
    return seq;
}

// OpenVDB throws from more places than its readers (a transform whose matrix is singular
// throws when its affine map is asked for): no exception leaves the importer.
Result<GridSequence> load(const std::vector<std::string>& paths, const std::vector<int>& frameNumbers, const VdbImportDesc& desc) {
    Current cur;
    try {
        return loadFrames(paths, frameNumbers, desc, cur);
    } catch (const std::exception& e) { return makeError("OpenVDB file '" + cur.path + "' (frame " + std::to_string(cur.frame) + "): " + e.what()); }
}

} // namespace

std::string vdbFramePath(const std::string& pattern, int frame) {
    const std::size_t first = pattern.rfind('#');
    if (first == std::string::npos) return pattern;
    std::size_t start = first;
    while (start > 0 && pattern[start - 1] == '#') --start;
    const std::size_t width = first - start + 1;
    std::string digits = std::to_string(frame < 0 ? -frame : frame);
    if (digits.size() < width) digits.insert(0, width - digits.size(), '0');
    if (frame < 0) digits.insert(0, 1, '-');
    return pattern.substr(0, start) + digits + pattern.substr(first + 1);
}

Result<GridSequence> loadVdb(const std::string& path, const VdbImportDesc& desc) { return load({path}, {0}, desc); }

Result<GridSequence> loadVdbSequence(const std::string& pattern, int firstFrame, int lastFrame, const VdbImportDesc& desc) {
    if (pattern.find('#') == std::string::npos)
        return makeError("OpenVDB sequence '" + pattern + "': the pattern has no '#' run for the frame number (e.g. fluid_data_####.vdb)");
    std::vector<std::string> paths;
    std::vector<int> frames;
    if (lastFrame >= firstFrame) {
        if (std::int64_t(lastFrame) - firstFrame >= kMaxFrames)
            return makeError("OpenVDB sequence '" + pattern + "': " + std::to_string(std::int64_t(lastFrame) - firstFrame + 1) +
                             " frames; the limit is " + std::to_string(kMaxFrames));
        for (int f = firstFrame; f <= lastFrame; ++f) paths.push_back(vdbFramePath(pattern, f)), frames.push_back(f);
    } else {
        std::error_code ec;
        for (int f = firstFrame; f < firstFrame + kMaxFrames && std::filesystem::is_regular_file(vdbFramePath(pattern, f), ec); ++f)
            paths.push_back(vdbFramePath(pattern, f)), frames.push_back(f);
        if (paths.empty())
            return makeError("OpenVDB sequence '" + pattern + "': no file for its first frame " + std::to_string(firstFrame) + " ('" +
                             vdbFramePath(pattern, firstFrame) + "')");
    }
    return load(paths, frames, desc);
}

} // namespace splatfx

namespace splatfx {

Result<DenseVoxels> readVdbDensity(const std::string& path, const VdbImportDesc& desc, std::uint64_t maxVoxels) {
    const std::string at = where(path, 0, desc.densityGrid);
    try {
        openvdb::initialize();
        std::error_code ec;
        if (!std::filesystem::is_regular_file(path, ec)) return makeError("OpenVDB file '" + path + "' (frame 0): no such file");
        // The same walk as the importer's, down to the voxel buffers, before OpenVDB reads anything.
        auto walked = vdbfile::walk(path, {desc.densityGrid}, true);
        if (!walked) return makeError("OpenVDB file '" + path + "' (frame 0): refused before OpenVDB reads it: " + walked.error());
        std::uint64_t total = 0;
        for (const vdbfile::GridLayout& g : *walked)
            if (Status s = checkLayout(g, path, 0, desc, total); !s) return makeError(s.error());
        openvdb::io::File file(path);
        file.open(false);
        openvdb::GridBase::ConstPtr found;
        if (Status s = checkGrid<openvdb::FloatGrid>(*file.readAllGridMetadata(), path, 0, desc.densityGrid, "float", found); !s)
            return makeError(s.error());
        const auto grid = openvdb::gridConstPtrCast<openvdb::FloatGrid>(file.readGrid(desc.densityGrid));
        file.close();
        if (!grid) return makeError(at + "could not be read as a float grid");
        if (grid->background() != 0.0f)
            return makeError(at + "has background " + num(grid->background()) + "; a density grid's empty space must be 0");
        double vs = 0.0;
        openvdb::Vec3d origin;
        if (Status s = checkTransform(grid->transform(), at, vs, origin); !s) return makeError(s.error());
        const openvdb::CoordBBox box = (*walked)[0].activeBox;
        const openvdb::Coord dim = box.dim();
        const std::uint64_t count = std::uint64_t(dim.x()) * std::uint64_t(dim.y()) * std::uint64_t(dim.z());
        if (count > maxVoxels)
            return makeError(at + "its active box holds " + std::to_string(count) + " voxels, more than " + std::to_string(maxVoxels) +
                             " (readVdbDensity's maxVoxels)");
        DenseVoxels out;
        out.dims = glm::ivec3(dim.x(), dim.y(), dim.z());
        out.voxelSize = vs;
        const openvdb::Vec3d o = grid->transform().indexToWorld(box.min());
        out.origin = glm::dvec3(o[0], o[1], o[2]);
        out.values.assign(count, 0.0f);
        bool bad = false;
        auto set = [&](const openvdb::Coord& c, float d) {
            if (!(d >= 0.0f) || !std::isfinite(d)) return void(bad = true);
            const openvdb::Coord r = c - box.min();
            out.values[(std::size_t(r.z()) * std::size_t(dim.y()) + std::size_t(r.y())) * std::size_t(dim.x()) + std::size_t(r.x())] = d;
        };
        forEachActive(*grid, set, [&](const openvdb::CoordBBox& tile, float d) {
            const openvdb::CoordBBox b(openvdb::Coord::maxComponent(tile.min(), box.min()), openvdb::Coord::minComponent(tile.max(), box.max()));
            for (auto c = b.begin(); c; ++c) set(*c, d);
        });
        if (bad) return makeError(at + "holds negative, NaN or infinite densities; a density must be finite and >= 0");
        return out;
    } catch (const std::exception& e) { return makeError("OpenVDB file '" + path + "' (frame 0): " + e.what()); }
}

} // namespace splatfx
