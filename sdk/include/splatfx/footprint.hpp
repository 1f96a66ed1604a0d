// splatfx/footprint.hpp: reconstruction kernels and their pre-integrated footprints.
//
// Splatting (Westover 1989) integrates each voxel's 3D kernel h along the
// viewing ray once, into a 2D footprint F(r) = integral h(sqrt(r^2 + s^2)) ds,
// and stores it in a table (King et al. 1999, sec. 1). Kernels here are
// radially symmetric in voxel units, so one table serves every view; an
// anisotropic voxel (non-cubic spacing, a stretch) is a linear map of this
// kernel and projects to an ellipse (see splats.hpp).
// It does not know about textures or GL.
//
//   splatfx::Footprint fp({.kernel = splatfx::Kernel::CrawfisMax});
//   float w = fp.weight(0.5f);      // F(0.5) / F(0), from the table
//
// Threading: immutable after construction; safe to share.
#pragma once

#include <vector>

namespace splatfx {

enum class Kernel {
    // Crawfis & Max 1993 criterion: the radially symmetric kernel of radius 1.6
    // whose lattice sum reconstructs a constant field as flat as possible.
    // Coefficients re-derived for splatfx (docs/architecture.md): ripple 0.57 %.
    CrawfisMax,
    // exp(-r^2 / (2 sigma^2)), truncated at FootprintDesc::gaussianRadius.
    Gaussian,
};

struct FootprintDesc {
    Kernel kernel = Kernel::CrawfisMax; // default: CrawfisMax
    int tableSize = 256;                // entries over [0, radius]; default 256
    float gaussianSigma = 0.7f;         // voxel units; default 0.7 (Gaussian only)
    float gaussianRadius = 2.0f;        // truncation, voxel units; default 2.0 (Gaussian only)
};

class Footprint {
public:
    explicit Footprint(const FootprintDesc& desc = {});

    const FootprintDesc& desc() const { return mDesc; }
    // Support radius in voxel units: the footprint is zero beyond it.
    float radius() const { return mRadius; }

    // The 3D kernel, normalized so its integral over space is 1.
    double kernel(double r) const;
    // Exact line integral of the kernel at distance r from its centre
    // (adaptive quadrature; what the reference renderer uses).
    double exact(double r) const;
    // Table lookup with linear interpolation: F(r), absolute units.
    float table(float r) const;
    // Table lookup normalized to the centre: F(r) / F(0), in [0, 1].
    float weight(float r) const { return table(r) * mInvCentre; }
    float centre() const { return mTable.empty() ? 0.0f : mTable[0]; }

    // size x size image of weight() over [-radius, radius]^2 (texel centres).
    std::vector<float> image(int size) const;

private:
    FootprintDesc mDesc;
    float mRadius = 1.0f;
    double mNorm = 1.0;
    std::vector<float> mTable;
    float mInvCentre = 1.0f;
};

} // namespace splatfx
