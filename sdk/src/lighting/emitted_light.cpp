#include "splatfx/emitted_light.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>

namespace splatfx {
namespace {

constexpr int kSamplesPerSide = 16; // texture samples per side of a splat's quad for its intensity

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

glm::vec3 rowColor(const std::vector<glm::vec4>& row, float coord) {
    if (row.empty()) return glm::vec3(1.0f);
    const float f = std::clamp(std::isfinite(coord) ? coord : 0.0f, 0.0f, 1.0f) * float(row.size() - 1);
    const std::size_t i = std::min(std::size_t(f), row.size() - 1), j = std::min(i + 1, row.size() - 1);
    const float t = f - float(i);
    return glm::vec3(row[i]) * (1.0f - t) + glm::vec3(row[j]) * t;
}

// One splat's emission: its radiant intensity (premultiplied colour
// integrated over the ellipse) and its optical area (log2 depth integrated
// over the ellipse), from point samples at texel centres of its layers.
struct SplatEmission {
    glm::vec3 intensity{0.0f};
    float opticalArea = 0.0f;
};

SplatEmission emission(const Splat& s, const Materials& m, bool packedColor) {
    const int n = m.layerSize();
    if (s.layer >= m.layerCount() || s.nextLayer >= m.layerCount() || !(s.density > 0.0f) || !finite(s.center)) return {};
    const float area = glm::length(glm::cross(s.axisU, s.axisV)); // world area per unit of (u, v)
    if (!(area > 0.0f) || !std::isfinite(area)) return {};
    glm::vec3 base(1.0f);
    if (packedColor) base = glm::vec3(float(s.color & 255u), float((s.color >> 8) & 255u), float((s.color >> 16) & 255u)) / 255.0f;
    else if (std::uint32_t(std::lround(s.colorRow)) < m.colorTableCount()) base = rowColor(m.colorRow(std::uint32_t(std::lround(s.colorRow))), s.colorCoord);
    const std::vector<float>& a = m.layer(s.layer);
    const std::vector<float>& b = m.layer(s.nextLayer);
    const float w = std::clamp(s.blend, 0.0f, 1.0f);
    const int stride = std::max(1, n / kSamplesPerSide);
    glm::vec3 sumColor(0.0f);
    float sumAlpha = 0.0f;
    int count = 0;
    for (int y = stride / 2; y < n; y += stride)
        for (int x = stride / 2; x < n; x += stride, ++count) {
            const std::size_t p = (std::size_t(y) * n + x) * 4;
            const glm::vec4 t = glm::vec4(a[p], a[p + 1], a[p + 2], a[p + 3]) * (1.0f - w) + glm::vec4(b[p], b[p + 1], b[p + 2], b[p + 3]) * w;
            const float alpha = -std::expm1(-0.69314718f * s.density * t.a);
            sumAlpha += alpha;
            sumColor += glm::vec3(t) * alpha; // premultiplied
        }
    if (count == 0) return {};
    const float quad = 4.0f * area; // (u, v) in [-1, 1]^2: area 4 per unit
    if (!std::isfinite(quad)) return {};
    // What the splat takes from light crossing it anywhere in its quad is its
    // mean opacity (a textured splat has holes), as an optical depth.
    const float meanAlpha = std::min(sumAlpha / float(count), 1.0f - 1e-6f);
    return {base * sumColor * (quad / float(count)), -std::log2(1.0f - meanAlpha) * quad};
}

// The fraction of a splat's light that leaves the volume, averaged over the
// six axis directions: the splats' optical areas binned on a coarse grid,
// each bin's mean optical depth across a face = its optical area / the face.
class Occlusion {
public:
    Occlusion(std::span<const Splat> splats, std::span<const SplatEmission> e, const std::vector<std::size_t>& emitting) {
        glm::vec3 lo(1e30f), hi(-1e30f);
        float radius = 0.0f;
        for (std::size_t i : emitting) {
            lo = glm::min(lo, splats[i].center), hi = glm::max(hi, splats[i].center);
            radius += std::sqrt(glm::length(glm::cross(splats[i].axisU, splats[i].axisV)));
        }
        radius /= float(std::max<std::size_t>(emitting.size(), 1));
        const float cell = std::max(radius, 1e-6f);
        mLo = lo - 0.5f * cell;
        const glm::vec3 extent = hi - lo + cell;
        // A bin about one splat radius wide, at most 32 a side.
        // Clamped before the conversion: a splat 1e30 away must not overflow the int.
        mDims = glm::ivec3(glm::clamp(glm::ceil(extent / cell), glm::vec3(1.0f), glm::vec3(32.0f)));
        mCell = extent / glm::vec3(mDims);
        mDepth.assign(std::size_t(mDims.x) * mDims.y * mDims.z, 0.0f);
        for (std::size_t i : emitting) mDepth[index(bin(splats[i].center))] += e[i].opticalArea;
    }
    // Transmittance from p (a splat of optical area `own`) out of the volume
    // along +x, +y, +z (plus) and -x, -y, -z (minus).
    void escape(glm::vec3 p, float own, glm::vec3& plus, glm::vec3& minus) const {
        const glm::ivec3 c = bin(p);
        for (int axis = 0; axis < 3; ++axis) {
            const float face = mCell[(axis + 1) % 3] * mCell[(axis + 2) % 3];
            for (int dir : {-1, 1}) {
                // Half of its own bin lies ahead, less the splat itself: its
                // emission is premultiplied, it does not pass through itself.
                float tau = 0.5f * std::max(mDepth[index(c)] - own, 0.0f);
                glm::ivec3 q = c;
                for (q[axis] += dir; q[axis] >= 0 && q[axis] < mDims[axis]; q[axis] += dir) tau += mDepth[index(q)];
                (dir > 0 ? plus : minus)[axis] = std::exp2(-tau / face);
            }
        }
    }

    // Optical depth (log2) along the segment from a splat's centre to `to`,
    // through the bins it crosses (midpoint rule, half a bin per step), the
    // splat's own optical area `own` taken out of its bin.
    float depthAlong(glm::vec3 from, glm::vec3 to, float own) const {
        const glm::vec3 hi = mLo + mCell * glm::vec3(mDims);
        // Clip to the grid's box (slab test): outside it there is no depth.
        const glm::vec3 d = to - from;
        float t0 = 0.0f, t1 = 1.0f;
        for (int a = 0; a < 3; ++a) {
            if (d[a] == 0.0f) continue;
            float ta = (mLo[a] - from[a]) / d[a], tb = (hi[a] - from[a]) / d[a];
            if (ta > tb) std::swap(ta, tb);
            t0 = std::max(t0, ta), t1 = std::min(t1, tb);
        }
        if (!(t1 > t0)) return 0.0f;
        // Scaled: a splat 1e30 away must not overflow the length's square.
        const float big = std::max(std::abs(d.x), std::max(std::abs(d.y), std::abs(d.z)));
        const float length = glm::length(d / big) * big * (t1 - t0);
        // Two steps per bin crossed (it crosses at most sum_a |d_a| / cell_a
        // bin faces, <= 3 x 32); clamped in float before the conversion.
        const glm::vec3 crossed = glm::abs(d) * (t1 - t0) / mCell;
        const int steps = int(std::clamp(std::ceil(2.0f * (crossed.x + crossed.y + crossed.z)), 1.0f, 2.0f * 3.0f * 32.0f));
        const float dt = (t1 - t0) / float(steps), step = length / float(steps);
        const float volume = mCell.x * mCell.y * mCell.z;
        const glm::ivec3 start = bin(from);
        float depth = 0.0f;
        for (int k = 0; k < steps; ++k) {
            const glm::ivec3 c = bin(from + d * (t0 + (float(k) + 0.5f) * dt));
            depth += std::max(mDepth[index(c)] - (c == start ? own : 0.0f), 0.0f);
        }
        return depth * step / volume;
    }

private:
    glm::ivec3 bin(glm::vec3 p) const { return glm::ivec3(glm::clamp(glm::floor((p - mLo) / mCell), glm::vec3(0.0f), glm::vec3(mDims - 1))); }
    std::size_t index(glm::ivec3 c) const { return (std::size_t(c.z) * mDims.y + c.y) * mDims.x + c.x; }
    glm::vec3 mLo{0.0f}, mCell{1.0f};
    glm::ivec3 mDims{1};
    std::vector<float> mDepth;
};

// Each splat's emission into e; the indices of those that emit.
std::vector<std::size_t> collect(std::span<const Splat> splats, const Materials& materials, bool packedColor, std::vector<SplatEmission>& e) {
    e.assign(splats.size(), SplatEmission{});
    std::vector<std::size_t> emitting;
    for (std::size_t i = 0; i < splats.size(); ++i) {
        e[i] = emission(splats[i], materials, packedColor);
        if (e[i].intensity.x + e[i].intensity.y + e[i].intensity.z > 0.0f) emitting.push_back(i);
    }
    return emitting;
}

} // namespace

Status validate(const EmittedLightDesc& d) {
    if (d.lights < 1 || d.lights > kMaxEmittedLights)
        return makeError("EmittedLightDesc.lights must be in [1, " + std::to_string(kMaxEmittedLights) + "], got " + std::to_string(d.lights));
    if (!(d.scale >= 0.0f) || !std::isfinite(d.scale)) return makeError("EmittedLightDesc.scale must be finite and >= 0");
    if (!(d.reachWorld > 0.0f)) return makeError("EmittedLightDesc.reachWorld must be > 0");
    if (d.mode != EmittedLightMode::PointLights && d.mode != EmittedLightMode::Grid) return makeError("EmittedLightDesc.mode is not a known mode");
    if (d.gridDims.x < 2 || d.gridDims.y < 2 || d.gridDims.z < 2 || d.gridDims.x > kMaxEmittedGridNodes || d.gridDims.y > kMaxEmittedGridNodes ||
        d.gridDims.z > kMaxEmittedGridNodes || d.gridDims.x * d.gridDims.y * d.gridDims.z > kMaxEmittedGridNodes)
        return makeError("EmittedLightDesc.gridDims must be >= 2 on each axis with at most " + std::to_string(kMaxEmittedGridNodes) + " nodes, got " +
                         std::to_string(d.gridDims.x) + " x " + std::to_string(d.gridDims.y) + " x " + std::to_string(d.gridDims.z));
    if (!(d.gridMargin >= 0.0f) || !std::isfinite(d.gridMargin)) return makeError("EmittedLightDesc.gridMargin must be finite and >= 0");
    return {};
}

Result<std::vector<EmittedLight>> fitEmittedLights(std::span<const Splat> splats, const Materials& materials, const EmittedLightDesc& desc,
                                                   bool packedColor) {
    if (Status s = validate(desc); !s) return makeError(s.error());
    std::vector<SplatEmission> e;
    const std::vector<std::size_t> emitting = collect(splats, materials, packedColor, e);
    if (emitting.empty()) return std::vector<EmittedLight>{};
    std::vector<glm::vec3> plus(splats.size(), glm::vec3(1.0f)), minus(splats.size(), glm::vec3(1.0f));
    if (desc.occlusion) {
        const Occlusion occlusion(splats, e, emitting);
        for (std::size_t i : emitting) occlusion.escape(splats[i].center, e[i].opticalArea, plus[i], minus[i]);
    }
    // Weighted k-means on the centres, weight = the light that leaves (channel sum, mean escape).
    std::vector<float> w(emitting.size());
    glm::dvec3 mean(0.0);
    double total = 0.0;
    for (std::size_t k = 0; k < emitting.size(); ++k) {
        const std::size_t i = emitting[k];
        const glm::vec3 I = e[i].intensity;
        const glm::vec3 esc = 0.5f * (plus[i] + minus[i]);
        w[k] = (I.x + I.y + I.z) * std::max((esc.x + esc.y + esc.z) / 3.0f, 1e-12f);
        mean += double(w[k]) * glm::dvec3(splats[emitting[k]].center);
        total += w[k];
    }
    mean /= total;
    // Start from equal-weight slices along the principal axis (power iteration on the covariance).
    glm::dmat3 cov(0.0);
    for (std::size_t k = 0; k < emitting.size(); ++k) {
        const glm::dvec3 d = glm::dvec3(splats[emitting[k]].center) - mean;
        cov += double(w[k]) * glm::outerProduct(d, d);
    }
    glm::dvec3 axis(0.3, 1.0, 0.2);
    for (int it = 0; it < 16; ++it) {
        const glm::dvec3 next = cov * axis;
        const double len = glm::length(next);
        if (!(len > 0.0)) break;
        axis = next / len;
    }
    std::vector<std::size_t> order(emitting.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::vector<double> along(emitting.size());
    for (std::size_t k = 0; k < emitting.size(); ++k) along[k] = glm::dot(glm::dvec3(splats[emitting[k]].center) - mean, axis);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return along[a] < along[b]; });
    // No more lights than distinct centres: splats all at one point (or at a
    // few) would otherwise be sliced into coincident clusters that k-means
    // never separates, several lights at one place taking the frame's slots.
    std::vector<glm::vec3> centres(emitting.size());
    for (std::size_t k = 0; k < emitting.size(); ++k) centres[k] = splats[emitting[k]].center;
    auto lexLess = [](glm::vec3 a, glm::vec3 b) { return a.x != b.x ? a.x < b.x : a.y != b.y ? a.y < b.y : a.z < b.z; };
    std::sort(centres.begin(), centres.end(), lexLess);
    const std::size_t distinct = std::size_t(std::unique(centres.begin(), centres.end()) - centres.begin());
    const int K = int(std::min<std::size_t>(std::size_t(desc.lights), distinct));
    std::vector<int> label(emitting.size());
    double run = 0.0;
    for (std::size_t k : order) {
        label[k] = std::min(K - 1, int(run / total * K));
        run += w[k];
    }
    std::vector<glm::dvec3> centre(K);
    std::vector<double> mass(K);
    auto centroids = [&] {
        std::fill(centre.begin(), centre.end(), glm::dvec3(0.0));
        std::fill(mass.begin(), mass.end(), 0.0);
        for (std::size_t k = 0; k < emitting.size(); ++k) {
            centre[label[k]] += double(w[k]) * glm::dvec3(splats[emitting[k]].center);
            mass[label[k]] += w[k];
        }
        for (int c = 0; c < K; ++c)
            if (mass[c] > 0.0) centre[c] /= mass[c];
    };
    centroids();
    for (int it = 0; it < 8; ++it) {
        bool moved = false;
        for (std::size_t k = 0; k < emitting.size(); ++k) {
            const glm::dvec3 p(splats[emitting[k]].center);
            int best = label[k];
            double bestD = glm::dot(p - centre[best], p - centre[best]);
            for (int c = 0; c < K; ++c) {
                const double d = glm::dot(p - centre[c], p - centre[c]);
                if (mass[c] > 0.0 && d < bestD) best = c, bestD = d;
            }
            moved |= best != label[k];
            label[k] = best;
        }
        if (!moved) break;
        centroids();
    }
    std::vector<EmittedLight> lights(K);
    std::vector<double> spread(K, 0.0), power(K, 0.0);
    std::vector<glm::dvec3> plusSum(K, glm::dvec3(0.0)), minusSum(K, glm::dvec3(0.0));
    for (std::size_t k = 0; k < emitting.size(); ++k) {
        const int c = label[k];
        const std::size_t i = emitting[k];
        lights[c].intensity += e[i].intensity * desc.scale;
        const double p = double(e[i].intensity.x + e[i].intensity.y + e[i].intensity.z);
        power[c] += p;
        plusSum[c] += p * glm::dvec3(plus[i]);
        minusSum[c] += p * glm::dvec3(minus[i]);
        const glm::dvec3 d = glm::dvec3(splats[i].center) - centre[c];
        spread[c] += double(w[k]) * glm::dot(d, d);
    }
    for (int c = 0; c < K; ++c) {
        lights[c].position = glm::vec3(centre[c]);
        lights[c].radius = mass[c] > 0.0 ? float(std::sqrt(spread[c] / mass[c])) : 0.0f;
        if (power[c] > 0.0) lights[c].escapePlus = glm::vec3(plusSum[c] / power[c]), lights[c].escapeMinus = glm::vec3(minusSum[c] / power[c]);
    }
    for (const EmittedLight& l : lights)
        if (!std::isfinite(l.intensity.x + l.intensity.y + l.intensity.z))
            return makeError("EmittedLightDesc.scale: the lights' intensity overflows float (scale " + std::to_string(desc.scale) + ")");
    std::erase_if(lights, [](const EmittedLight& l) { return !(l.intensity.x + l.intensity.y + l.intensity.z > 0.0f); });
    std::stable_sort(lights.begin(), lights.end(), [](const EmittedLight& a, const EmittedLight& b) {
        return a.intensity.x + a.intensity.y + a.intensity.z > b.intensity.x + b.intensity.y + b.intensity.z;
    });
    return lights;
}

glm::vec3 emittedIrradiance(std::span<const EmittedLight> lights, glm::vec3 point, glm::vec3 normal) {
    glm::vec3 sum(0.0f);
    for (const EmittedLight& l : lights) {
        const glm::vec3 d = l.position - point;
        const float d2 = glm::dot(d, d);
        if (!(d2 > 0.0f)) continue;
        const glm::vec3 out = -d / std::sqrt(d2); // from the light towards the point
        const float cosine = std::max(glm::dot(normal, -out), 0.0f);
        const glm::vec3 sq = out * out;
        const glm::vec3 escape = glm::mix(l.escapeMinus, l.escapePlus, glm::step(glm::vec3(0.0f), out));
        sum += l.intensity * (glm::dot(sq, escape) * cosine / (d2 + l.radius * l.radius));
    }
    return sum;
}

} // namespace splatfx

namespace splatfx {

Result<EmittedGrid> fitEmittedGrid(std::span<const Splat> splats, const Materials& materials, const EmittedLightDesc& desc, bool packedColor) {
    if (Status s = validate(desc); !s) return makeError(s.error());
    std::vector<SplatEmission> e;
    const std::vector<std::size_t> emitting = collect(splats, materials, packedColor, e);
    if (emitting.empty()) return EmittedGrid{};
    glm::vec3 lo(1e30f), hi(-1e30f);
    glm::dvec3 centre(0.0);
    double power = 0.0;
    for (std::size_t i : emitting) {
        lo = glm::min(lo, splats[i].center), hi = glm::max(hi, splats[i].center);
        const double p = double(e[i].intensity.x + e[i].intensity.y + e[i].intensity.z);
        centre += p * glm::dvec3(splats[i].center), power += p;
    }
    EmittedGrid g;
    g.dims = desc.gridDims;
    // A flat or point-like emitter with no margin still needs a box: grow an
    // empty axis by the largest splat's half-width.
    float half = 0.0f;
    for (std::size_t i : emitting) half = std::max(half, std::sqrt(glm::length(glm::cross(splats[i].axisU, splats[i].axisV))));
    const glm::vec3 grow = glm::max(glm::vec3(desc.gridMargin), glm::vec3(glm::greaterThanEqual(lo, hi)) * half);
    g.boxMin = lo - grow, g.boxMax = hi + grow;
    g.centre = glm::vec3(centre / power);
    if (!finite(g.boxMin) || !finite(g.boxMax) || !finite(g.centre)) return makeError("fitEmittedGrid: the emitting splats' bounds overflow float");
    const std::optional<Occlusion> occlusion = desc.occlusion ? std::optional<Occlusion>(std::in_place, splats, e, emitting) : std::nullopt;
    const glm::ivec3 n = g.dims;
    g.nodes.assign(std::size_t(n.x) * n.y * n.z, {});
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                const glm::vec3 p = g.boxMin + (g.boxMax - g.boxMin) * (glm::vec3(x, y, z) / glm::vec3(n - 1));
                std::array<glm::dvec3, 6> sum{};
                for (std::size_t i : emitting) {
                    const Splat& s = splats[i];
                    const glm::vec3 w = s.center - p; // towards the splat
                    const double d2 = double(glm::dot(w, w));
                    if (!(d2 > 0.0)) continue; // no direction to it: its light falls on no axis normal
                    const double a2 = double(glm::length(glm::cross(s.axisU, s.axisV)));
                    const double t = occlusion ? double(std::exp2(-occlusion->depthAlong(s.center, p, e[i].opticalArea))) : 1.0;
                    const glm::dvec3 f = glm::dvec3(e[i].intensity) * (t / (d2 + a2));
                    const glm::dvec3 dir = glm::dvec3(w) / std::sqrt(d2);
                    for (int a = 0; a < 3; ++a)
                        sum[std::size_t(2 * a)] += f * std::max(dir[a], 0.0), sum[std::size_t(2 * a + 1)] += f * std::max(-dir[a], 0.0);
                }
                auto& node = g.nodes[(std::size_t(z) * n.y + y) * n.x + x];
                for (std::size_t k = 0; k < 6; ++k) node[k] = glm::vec3(sum[k] * double(desc.scale));
                for (const glm::vec3& v : node)
                    if (!finite(v))
                        return makeError("EmittedLightDesc.scale: the grid's irradiance overflows float (scale " + std::to_string(desc.scale) + ")");
            }
    return g;
}

glm::vec3 emittedIrradiance(const EmittedGrid& g, glm::vec3 point, glm::vec3 normal) {
    const glm::ivec3 n = g.dims;
    if (n.x < 2 || n.y < 2 || n.z < 2 || g.nodes.size() != std::size_t(n.x) * n.y * n.z) return glm::vec3(0.0f);
    const glm::vec3 q = glm::clamp(point, g.boxMin, g.boxMax);
    const glm::vec3 t = (q - g.boxMin) / (g.boxMax - g.boxMin) * glm::vec3(n - 1);
    if (!finite(t) || !finite(normal)) return glm::vec3(0.0f); // a NaN point or a flat box: no float-to-int of a NaN
    const glm::ivec3 i0 = glm::clamp(glm::ivec3(glm::floor(t)), glm::ivec3(0), n - 2);
    const glm::vec3 f = t - glm::vec3(i0);
    const glm::ivec3 k(normal.x >= 0.0f ? 0 : 1, normal.y >= 0.0f ? 2 : 3, normal.z >= 0.0f ? 4 : 5);
    const glm::vec3 nn = normal * normal;
    glm::vec3 sum(0.0f);
    for (int c = 0; c < 8; ++c) {
        const glm::ivec3 o(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        const glm::vec3 w3 = glm::mix(glm::vec3(1.0f) - f, f, glm::vec3(o));
        const glm::ivec3 i = i0 + o;
        const auto& node = g.nodes[(std::size_t(i.z) * n.y + i.y) * n.x + i.x];
        sum += (w3.x * w3.y * w3.z) * (nn.x * node[std::size_t(k.x)] + nn.y * node[std::size_t(k.y)] + nn.z * node[std::size_t(k.z)]);
    }
    if (q == point) return sum;
    // Outside the box: a point source at the centre whose intensity towards
    // q is read from q's six values (for a point source E(+-a) = I max(+-w_a, 0)
    // / d^2, so I = d^2 x their sum / sum_a |w_a|), shining on p with p's own
    // cosine; plus the grid's departure from it at q, falling as d^-4 (the
    // weighted centre cancels the dipole term): continuous at the box, the
    // point source far away.
    const glm::vec3 dq = g.centre - q, dp = g.centre - point;
    const float dq2 = glm::dot(dq, dq), dp2 = glm::dot(dp, dp);
    if (!(dq2 > 0.0f) || !(dp2 > 0.0f)) return sum;
    const glm::vec3 wq = dq / std::sqrt(dq2), wp = dp / std::sqrt(dp2);
    glm::vec3 all(0.0f);
    for (int c = 0; c < 8; ++c) {
        const glm::ivec3 o(c & 1, (c >> 1) & 1, (c >> 2) & 1);
        const glm::vec3 w3 = glm::mix(glm::vec3(1.0f) - f, f, glm::vec3(o));
        const glm::ivec3 i = i0 + o;
        const auto& node = g.nodes[(std::size_t(i.z) * n.y + i.y) * n.x + i.x];
        all += (w3.x * w3.y * w3.z) * (node[0] + node[1] + node[2] + node[3] + node[4] + node[5]);
    }
    const glm::vec3 intensity = all * (dq2 / (std::abs(wq.x) + std::abs(wq.y) + std::abs(wq.z)));
    const glm::vec3 atQ = intensity * (std::max(glm::dot(normal, wq), 0.0f) / dq2);
    const glm::vec3 atP = intensity * (std::max(glm::dot(normal, wp), 0.0f) / dp2);
    const float r = dq2 / dp2;
    return glm::max(atP + (sum - atQ) * (r * r), glm::vec3(0.0f));
}

} // namespace splatfx
