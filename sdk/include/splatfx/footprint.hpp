// splatfx/footprint.hpp: reconstruction kernels and their pre-integrated footprints.
//
// Splatting (Westover 1989) integrates each voxel's 3D kernel h along the
// viewing ray once, into a 2D footprint F(r) = integral h(sqrt(r^2 + s^2)) ds,
// and stores it in a table (King et al. 1999, sec. 1). Kernels here are
// radially symmetric in voxel units, so one table serves every view; an
// anisotropic voxel (non-cubic spacing, a stretch) is a linear map of this
// kernel and projects to an ellipse (see splats.hpp).
//
// The partial line integral (Ebert & Parent 1990's volume
// "sections" in front of a surface): exactBefore(r, s) integrates the kernel
// along the ray at distance r from its centre over ray parameter (-inf, s],
// s measured from the ray's closest approach to the centre, both in kernel
// (voxel) units. A second pre-integrated table holds the fraction of F(r)
// in front of s, so a splat fragment cut by the host's depth or the near
// plane keeps exactly the part of its optical depth in front
// (docs/architecture.md, "The depth cut"); partialGlsl() is the same lookup
// in GLSL for the GL passes.
// It does not know about textures or GL (partialGlsl() only writes text).
//
//   splatfx::Footprint fp({.kernel = splatfx::Kernel::CrawfisMax});
//   float w = fp.weight(0.5f);                 // F(0.5) / F(0), from the table
//   float front = fp.fractionBefore(0.5f, 0.2f); // share of F(0.5) at s <= 0.2
//
// Threading: immutable after construction; safe to share.
#pragma once

#include <string>
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
    // Partial-integral table (fractionBefore): radial entries over r in
    // [0, radius] by depth entries over the chord, sigma = s / sqrt(R^2 - r^2)
    // in [-1, 1]. Each clamped to [2, 1024]. Defaults 32 x 64 (8 KiB):
    // the bench's table-size sweep (docs/BENCHMARKS.md, "The depth cut").
    int partialRadialSize = 32; // default 32
    int partialDepthSize = 64;  // default 64
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

    // Exact partial line integral: the kernel integrated along a ray at
    // distance r from its centre over ray parameter (-inf, s], s the signed
    // distance along the ray from the point of closest approach, both in
    // kernel (voxel) units. 0 for s <= -sqrt(R^2 - r^2) or r >= R, exact(r)
    // for s >= sqrt(R^2 - r^2); exact(r) / 2 at s = 0 (symmetry). NaN r or s: 0.
    double exactBefore(double r, double s) const;
    // The fraction exactBefore(r, s) / exact(r) in [0, 1], exact (double);
    // for r >= R the limit of a vanishing chord (a step at s = 0 for kernels
    // that vanish at their rim is approached smoothly: see the table).
    double exactFractionBefore(double r, double s) const;
    // Same fraction from the pre-integrated table, bilinear (what the GL
    // passes read; the GLSL in partialGlsl() does exactly this lookup).
    float fractionBefore(float r, float s) const;
    // The table, partialRadialSize rows (r = R i / (rows - 1)) of
    // partialDepthSize entries (sigma = -1 + 2 j / (cols - 1)), row-major.
    const std::vector<float>& partialTable() const { return mPartial; }
    int partialRows() const { return mPartialRows; }
    int partialCols() const { return mPartialCols; }

private:
    double rowFraction(double r, double sigma) const;
    double chordIntegral(double r, double from, double to) const;

    FootprintDesc mDesc;
    float mRadius = 1.0f;
    double mRadiusExact = 1.0; // the kernel's support in double (1.6 is not a float)
    double mNorm = 1.0;
    std::vector<float> mTable;
    float mInvCentre = 1.0f;
    std::vector<float> mPartial;
    int mPartialRows = 2, mPartialCols = 2;
};

// GLSL (450 core) for the partial table, to prepend to a shader that cuts
// splats at a depth (the splat pass; the fragment-list pass).
// Declares
//   layout(binding = <binding>) uniform sampler2D splatfx_partial_table;
//   float splatfx_partial_before(float r, float s);
//   float splatfx_ray_scale(vec3 axisU, vec3 axisV, float code01);   // splats.hpp, splatRayScale
// r: radial distance of the ray from the kernel centre, s: signed ray
// parameter from the closest-approach point, both kernel (voxel) units;
// returns the fraction of F(r) at ray parameter <= s, in [0, 1], the same
// bilinear lookup as Footprint::fractionBefore. The radius and table size
// are baked in as constants (the text is the GL passes' own, from the SDK's
// GLSL file partial.glsl). The pass binds a texture made from
// partialTable() (partialCols wide, partialRows high, R32F, GL_LINEAR,
// clamp to edge) to unit `binding`. docs/architecture.md, "The depth cut",
// says how a fragment computes r and s.
std::string partialGlsl(const Footprint& footprint, int binding);

} // namespace splatfx
