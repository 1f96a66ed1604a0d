// The VDB tests' exact reference: the file's voxels at full resolution
// (readVdbDensity) and the coarse lattice, each as a continuous medium
// through renderVolumeExact, seen orthographically with one pixel per file
// voxel column so every pixel's ray runs through voxel centres.
#pragma once

#include <cmath>
#include <memory>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "splatfx/reference.hpp"
#include "splatfx/vdb.hpp"

namespace splatfx::vdbtest {

// Coarse cell i's extinction per world unit is its optical depth over its edge,
// each cell a cube of it (Nearest): the lattice as the box filter defines it.
inline std::shared_ptr<DenseVoxels> coarseVoxels(const GridSequence& seq, int frame = 0) {
    auto v = std::make_shared<DenseVoxels>();
    Grid g;
    seq.sample(0.0, g);
    v->dims = seq.dims;
    v->voxelSize = double(seq.spacing.x);
    v->origin = glm::dvec3(g.worldPosition({0, 0, 0}));
    v->values.resize(seq.cellCount());
    for (std::size_t i = 0; i < v->values.size(); ++i) v->values[i] = float(double(seq.frames[std::size_t(frame)].opticalDepth[i]) / v->voxelSize);
    return v;
}

// An orthographic camera looking along -z at the world box [lo, hi] of x and
// y, one pixel per `pixel` world units, pixel centres on lo + (k + 1/2) pixel.
inline Camera orthoAlongZ(glm::dvec2 lo, glm::ivec2 pixels, double pixel, double zEye) {
    const glm::dvec2 c = lo + 0.5 * pixel * glm::dvec2(pixels);
    const double hw = 0.5 * pixel * pixels.x, hh = 0.5 * pixel * pixels.y;
    return Camera::fromMatrices(glm::lookAt(glm::vec3(float(c.x), float(c.y), float(zEye)), glm::vec3(float(c.x), float(c.y), 0.0f), {0, 1, 0}),
                                glm::ortho(float(-hw), float(hw), float(-hh), float(hh), 0.01f, float(2.0 * std::abs(zEye))), pixels);
}

// Each pixel's optical depth -ln(1 - alpha) through one medium.
inline std::vector<double> pixelDepths(const ContinuousMedium& m, const Camera& cam, double tolerance = 1e-9) {
    Materials mat{Footprint{}};
    VolumeField f(mat);
    f.addMedium(m);
    VolumeExactStats st;
    auto img = renderVolumeExact(f, cam, {.tolerance = tolerance, .threads = 1}, &st);
    EXPECT_TRUE(img) << img.error();
    EXPECT_EQ(st.unconverged, 0u);
    std::vector<double> out;
    if (!img) return out;
    for (int y = 0; y < img->height; ++y)
        for (int x = 0; x < img->width; ++x) out.push_back(-std::log1p(-double(img->at(x, y, 3))));
    return out;
}

} // namespace splatfx::vdbtest
