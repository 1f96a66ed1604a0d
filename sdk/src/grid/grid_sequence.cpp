// GridSequence: validation and linear interpolation between baked frames.
// Optical depth interpolates linearly because it is linear in density (the
// material of frame a fading into frame b); the colour coordinate is the
// depth-weighted mean of the two frames' (the colour of the mixed material,
// not of an empty cell's arbitrary value).
#include "splatfx/grid_sequence.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "grid/number_text.hpp"

namespace splatfx {

using grid_detail::str;

namespace {

std::string cellName(const GridSequence& s, std::size_t i) {
    const std::size_t nx = std::size_t(s.dims.x), ny = std::size_t(s.dims.y);
    return "cell (" + std::to_string(i % nx) + ", " + std::to_string((i / nx) % ny) + ", " + std::to_string(i / (nx * ny)) + ")";
}

} // namespace

Status GridSequence::validate() const {
    if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0)
        return makeError("grid sequence: dims are (" + std::to_string(dims.x) + ", " + std::to_string(dims.y) + ", " + std::to_string(dims.z) +
                         "); expected positive cell counts");
    const std::uint64_t cells = std::uint64_t(dims.x) * std::uint64_t(dims.y) * std::uint64_t(dims.z);
    if (cells > kMaxVoxels) return makeError("grid sequence: " + std::to_string(cells) + " cells; the limit is " + std::to_string(kMaxVoxels));
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(spacing[a]) || spacing[a] <= 0.0f)
            return makeError("grid sequence: spacing[" + std::to_string(a) + "] is " + str(spacing[a]) + "; expected a positive finite value");
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(transform[c][r])) return makeError("grid sequence: transform has a non-finite entry");
    if (!std::isfinite(framesPerSec) || framesPerSec <= 0.0)
        return makeError("grid sequence: framesPerSec is " + str(float(framesPerSec)) + "; expected a positive finite value");
    if (frames.empty()) return makeError("grid sequence: no frames");
    for (std::size_t f = 0; f < frames.size(); ++f) {
        const GridSequenceFrame& fr = frames[f];
        const std::string at = "grid sequence frame " + std::to_string(f) + ": ";
        if (fr.opticalDepth.size() != cells)
            return makeError(at + "opticalDepth holds " + std::to_string(fr.opticalDepth.size()) + " values; expected " + std::to_string(cells));
        if (!fr.colorCoord.empty() && fr.colorCoord.size() != cells)
            return makeError(at + "colorCoord holds " + std::to_string(fr.colorCoord.size()) + " values; expected 0 or " + std::to_string(cells));
        if (!fr.velocityCellsPerSec.empty() && fr.velocityCellsPerSec.size() != cells)
            return makeError(at + "velocityCellsPerSec holds " + std::to_string(fr.velocityCellsPerSec.size()) + " values; expected 0 or " +
                             std::to_string(cells));
        if ((fr.colorCoord.empty()) != (frames[0].colorCoord.empty()))
            return makeError(at + "colorCoord is " + (fr.colorCoord.empty() ? "missing" : "present") + " but frame 0's is " +
                             (frames[0].colorCoord.empty() ? "missing" : "present") + "; every frame or none must carry colour");
        for (std::size_t i = 0; i < cells; ++i) {
            const float d = fr.opticalDepth[i];
            if (!std::isfinite(d) || d < 0.0f)
                return makeError(at + cellName(*this, i) + ": opticalDepth is " + str(d) + "; expected a finite value >= 0");
            if (!fr.colorCoord.empty() && !(fr.colorCoord[i] >= 0.0f && fr.colorCoord[i] <= 1.0f))
                return makeError(at + cellName(*this, i) + ": colorCoord is " + str(fr.colorCoord[i]) + "; expected a finite value in [0, 1]");
            if (!fr.velocityCellsPerSec.empty()) {
                const glm::vec3 v = fr.velocityCellsPerSec[i];
                if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
                    return makeError(at + cellName(*this, i) + ": velocityCellsPerSec is not finite");
            }
        }
    }
    return {};
}

SequencePosition GridSequence::position(double t) const {
    const std::size_t n = frames.size();
    if (n <= 1 || !std::isfinite(t)) return {};
    double u = t * framesPerSec;
    if (end == SequenceEnd::Loop) {
        u = std::fmod(u, double(n));
        if (u < 0.0) u += double(n);
    } else {
        u = std::clamp(u, 0.0, double(n - 1));
    }
    std::size_t a = std::min(std::size_t(u), n - 1);
    double w = u - double(a);
    std::size_t b = a + 1;
    if (b >= n) {
        if (end == SequenceEnd::Loop) b = 0;
        else b = a, w = 0.0;
    }
    // fmod can return n minus a rounding error: float(w) then rounds to 1.
    const float wf = std::min(float(w), std::nextafter(1.0f, 0.0f));
    return {a, b, wf};
}

double GridSequence::durationSec() const {
    const std::size_t n = frames.size();
    if (n == 0) return 0.0;
    return (end == SequenceEnd::Loop ? double(n) : double(n - 1)) / framesPerSec;
}

void GridSequence::sampleDepth(double t, std::vector<float>& out) const {
    const SequencePosition p = position(t);
    const std::vector<float>& a = frames[p.a].opticalDepth;
    const std::vector<float>& b = frames[p.b].opticalDepth;
    out.resize(a.size());
    const float w = p.weight;
    for (std::size_t i = 0; i < a.size(); ++i) out[i] = a[i] + (b[i] - a[i]) * w;
}

void GridSequence::sampleVelocity(double t, std::vector<glm::vec3>& out) const {
    const SequencePosition p = position(t);
    const std::vector<glm::vec3>& a = frames[p.a].velocityCellsPerSec;
    const std::vector<glm::vec3>& b = frames[p.b].velocityCellsPerSec;
    out.assign(cellCount(), glm::vec3(0.0f));
    const float w = p.weight;
    for (std::size_t i = 0; i < out.size(); ++i) {
        const glm::vec3 va = a.empty() ? glm::vec3(0.0f) : a[i];
        const glm::vec3 vb = b.empty() ? glm::vec3(0.0f) : b[i];
        out[i] = va + (vb - va) * w;
    }
}

void GridSequence::sample(double t, Grid& out, float minOpacity) const {
    assert(!frames.empty() && "GridSequence::sample: the sequence has no frames (validate() first)");
    const SequencePosition p = position(t);
    const GridSequenceFrame& fa = frames[p.a];
    const GridSequenceFrame& fb = frames[p.b];
    const float w = p.weight;
    const bool colour = !fa.colorCoord.empty();
    out.dims = dims;
    out.spacing = spacing;
    out.transform = transform;
    out.voxels.clear();
    const float span = float(std::max(dims.y - 1, 1));
    std::size_t i = 0;
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x, ++i) {
                const float da = fa.opticalDepth[i] * (1.0f - w), db = fb.opticalDepth[i] * w;
                const float depth = da + db;
                if (!(depth > 0.0f)) continue;
                // -expm1 keeps thin material's opacity accurate (1 - exp(-d) cancels for small d).
                const float opacity = float(-std::expm1(-double(depth)));
                if (opacity < minOpacity) continue;
                Voxel v;
                v.cell = {x, y, z};
                v.opacity = std::min(opacity, 1.0f);
                v.colorCoord = colour ? std::clamp((da * fa.colorCoord[i] + db * fb.colorCoord[i]) / depth, 0.0f, 1.0f) : float(y) / span;
                out.voxels.push_back(v);
            }
}

bool GridSequence::hasVelocity() const {
    for (const GridSequenceFrame& f : frames)
        if (!f.velocityCellsPerSec.empty()) return true;
    return false;
}

float GridSequence::maxDepth() const {
    float m = 0.0f;
    for (const GridSequenceFrame& f : frames)
        for (float d : f.opticalDepth) m = std::max(m, d);
    return m;
}

} // namespace splatfx
