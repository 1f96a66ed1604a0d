// tools/bench/lattice_measure.hpp: how visible a voxel lattice is in rendered frames (issue 25).
//
// King et al. 1999 (sec. 2) stamp every voxel's texture at a grid-fixed
// position; the stamps then form a regular weave whose period is the
// projected voxel spacing. This measure looks for it in the frames' 2D
// power spectrum: each frame's luminance is high-passed (minus a Gaussian
// blur of half the shortest lattice period), multiplied by a soft mask of
// the effect, padded to powers of two and transformed; the power spectra of
// all frames are averaged. At each frequency the projected lattice produces
// (the fundamentals along two lattice axes, their diagonals and the second
// harmonics) the mean power within a small disc is divided by the mean
// power over the ring of the same radius (other periods of the same
// frequency, away from every lattice frequency). A lattice-free image reads
// about 1, give or take its bins' noise; the turbulence control below
// calibrates what "no lattice" reads. An anisotropic image (a flame's
// upright tongues) also stands above its ring along its preferred direction,
// at every period; the second ratio tells the two apart: the disc's power
// over the same direction's at 0.75 and 4/3 of the frequency (geometric
// mean, so any power law reads 1): a lattice is a peak in period, a texture's
// direction is not.
// Plain CPU code: no GL, testable on synthetic images (tests/tools/lattice_measure_test.cpp).
// It does not render anything; splatfx-bench lattice feeds it frames.
//
//   lattice::Accumulator acc({640, 480});
//   for (each frame) acc.add(luminance, mask, basis);   // basis: lattice vectors in pixels
//   lattice::Score s = acc.score(basis);                 // s.ratio: the largest probe's disc / ring power
//
// Threading: plain values; one thread at a time per Accumulator.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace lattice {

// The projected lattice at the effect: pixel offsets (x right, y down) of
// one cell along each lattice axis, and the view direction in cell units
// (the axis the projection integrates out).
struct Basis {
    glm::vec2 axis[3]{};
    glm::vec3 viewCells{0.0f, 0.0f, 1.0f};
    // The frequencies (cycles per pixel) at which a lattice with these
    // vectors shows: integer cell frequencies q (fundamentals, diagonals,
    // second harmonics) nearly perpendicular to the view (|q . v| <= 0.3
    // cycles per cell, v the unit view direction in cells: an effect a few
    // cells deep seen in perspective still shows those), mapped to the
    // screen by f = (J J^T)^-1 J q with J the 2x3 matrix of the axes.
    struct Probe {
        glm::ivec3 q{0};
        glm::vec2 frequency{0.0f};
        std::string label; // "(1,0,0)"
    };
    std::vector<Probe> probes() const;
    // Shortest period among the probes, in pixels (the high-pass scale).
    float shortestPeriodPx() const;
};

struct ProbeScore {
    Basis::Probe probe;
    double disc = 0.0, ring = 0.0, ratio = 0.0; // mean power in the disc, in the ring, their ratio
    double along = 0.0, peak = 0.0; // the same direction's power at 0.75 and 4/3 of the frequency (geometric mean); disc / along
};

struct Score {
    double ratio = 0.0;    // largest probe ratio (the measure)
    double meanRatio = 0.0; // mean over the probes
    double peak = 0.0;      // largest probe's disc / along (a peak in period, whatever the direction's level)
    std::vector<ProbeScore> probes;
    int frames = 0;
};

// The mask of an effect in a frame: 1 where the blurred luminance is above
// `hi` times the frame's largest blurred luminance, 0 below `lo` times it,
// smooth between (so the mask's own edge adds little high frequency).
std::vector<float> flameMask(const std::vector<float>& luminance, int width, int height, float blurSigmaPx, float lo = 0.1f, float hi = 0.3f);
// The same from a luminance already blurred.
std::vector<float> maskOfBlurred(const std::vector<float>& blurred, float lo = 0.1f, float hi = 0.3f);

class Accumulator {
public:
    // Frames of this size (pixels); the transform is the next powers of two.
    explicit Accumulator(glm::ivec2 size);
    // Adds one frame: luminance (row-major, top row first) and a mask in [0, 1].
    void add(const std::vector<float>& luminance, const std::vector<float>& mask, const Basis& basis);
    Score score(const Basis& basis) const;
    int frames() const { return mFrames; }

private:
    glm::ivec2 mSize, mFft;
    std::vector<double> mPower; // averaged over frames, mFft.x * mFft.y
    int mFrames = 0;
};

// A lattice-free control: an animated turbulence field synthesised in the
// Fourier domain (power falling as |k|^-beta, random phases drifting with
// time; isotropic and with no preferred period), shaped like the effect:
// mean(x) * (1 + contrast * noise(x, t)). `seed` picks the phases.
class Turbulence {
public:
    Turbulence(glm::ivec2 size, float beta, std::uint32_t seed);
    // Noise at time t (seconds), zero mean, unit standard deviation.
    std::vector<float> frame(double timeSec) const;

private:
    glm::ivec2 mSize, mFft;
    std::vector<float> mAmplitude, mPhase, mSpeed;
};

// Gaussian blur (separable, clamped edges) of a single-channel image;
// above 8 pixels three box passes of the same variance (for masks).
std::vector<float> blur(const std::vector<float>& image, int width, int height, float sigmaPx);

} // namespace lattice
