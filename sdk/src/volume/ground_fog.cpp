// Ground fog as vertical prisms of three tetrahedra over a height field
// (Roettger & Ertl 2002, sec. 6), at full resolution (no LOD terrain yet).
#include <algorithm>
#include <cmath>
#include <string>

#include "splatfx/volume.hpp"

namespace splatfx {
namespace {

double orient(const Tetrahedron& t) {
    const glm::dvec3 a(t.position[0]);
    return glm::dot(glm::dvec3(t.position[1]) - a, glm::cross(glm::dvec3(t.position[2]) - a, glm::dvec3(t.position[3]) - a));
}

// The side test of the eye against a plane through `p0` with normal `n`:
// > 0 on the side of `n`. Orthographic eyes are at infinity behind the view.
double eyeSide(const Camera& cam, glm::dvec3 p0, glm::dvec3 n) {
    if (cam.perspective()) return glm::dot(n, glm::dvec3(cam.eye()) - p0);
    return -glm::dot(n, glm::dvec3(cam.forward()));
}

struct Emitter {
    const GroundFogDesc& d;
    const Camera& cam;
    LodFrame& out;
    glm::vec3 nearNormal{0.0f};
    float nearOffset = 0.0f;
    std::vector<Tetrahedron> pieces;

    glm::vec3 bottom(int i, int j) const {
        const std::size_t k = std::size_t(i) + std::size_t(d.dims.x) * std::size_t(j);
        return {d.originWorld.x + float(i) * d.spacingWorld, d.terrainHeight[k], d.originWorld.z + float(j) * d.spacingWorld};
    }
    float thickness(int i, int j) const {
        const std::size_t k = std::size_t(i) + std::size_t(d.dims.x) * std::size_t(j);
        return std::max(d.fogTop[k] - d.terrainHeight[k], 0.0f);
    }

    void push(const Tetrahedron& t) {
        bool visible = true;
        for (const glm::vec3& p : t.position) visible &= glm::dot(nearNormal, p) >= nearOffset;
        if (visible) {
            out.tets.push_back(t);
            return;
        }
        ++out.stats.clippedInput;
        pieces.clear();
        const int n = clipTetrahedron(t, nearNormal, nearOffset, pieces);
        if (n > 1) out.stats.clippedExtra += std::uint64_t(n - 1);
        // The pieces of one cut tetrahedron in MPVO order: of two pieces
        // sharing a face, the one on the eye's side of it is drawn later
        // (pieces meeting in an edge only are unordered; convex, so acyclic).
        const int m = int(pieces.size());
        bool before[3][3] = {}; // before[i][j]: i must be drawn before j
        for (int i = 0; i < m; ++i)
            for (int j = i + 1; j < m; ++j) {
                glm::vec3 shared[4];
                int ns = 0, apexI = -1;
                for (int a = 0; a < 4; ++a) {
                    bool found = false;
                    for (int b = 0; b < 4; ++b) found |= pieces[std::size_t(i)].position[std::size_t(a)] == pieces[std::size_t(j)].position[std::size_t(b)];
                    if (found) shared[ns++] = pieces[std::size_t(i)].position[std::size_t(a)];
                    else apexI = a;
                }
                if (ns != 3 || apexI < 0) continue;
                const glm::dvec3 p0(shared[0]), nrm = glm::cross(glm::dvec3(shared[1]) - p0, glm::dvec3(shared[2]) - p0);
                const bool iNearer = (eyeSide(cam, p0, nrm) > 0.0) ==
                                     (glm::dot(nrm, glm::dvec3(pieces[std::size_t(i)].position[std::size_t(apexI)]) - p0) > 0.0);
                if (iNearer) before[j][i] = true;
                else before[i][j] = true;
            }
        bool placed[3] = {};
        for (int k = 0; k < m; ++k)
            for (int i = 0; i < m; ++i) {
                if (placed[i]) continue;
                bool ready = true;
                for (int j = 0; j < m; ++j) ready &= placed[j] || !before[j][i];
                if (!ready) continue;
                placed[i] = true;
                out.tets.push_back(pieces[std::size_t(i)]);
                break;
            }
        return;
    }

    // One triangle's prism: three tetrahedra by the global vertex order
    // (every shared vertical quad is split from the higher-indexed bottom
    // vertex to the lower-indexed top one, on both sides), in MPVO order.
    void prism(glm::ivec2 a, glm::ivec2 b, glm::ivec2 c) {
        glm::ivec2 v[3] = {a, b, c};
        auto key = [&](glm::ivec2 p) { return p.x + d.dims.x * p.y; };
        std::sort(v, v + 3, [&](glm::ivec2 p, glm::ivec2 q) { return key(p) < key(q); });
        float h[3];
        glm::vec3 B[3], T[3];
        for (int k = 0; k < 3; ++k) {
            h[k] = thickness(v[k].x, v[k].y);
            B[k] = bottom(v[k].x, v[k].y);
            T[k] = B[k] + glm::vec3(0.0f, h[k], 0.0f);
        }
        if (h[0] <= 0.0f && h[1] <= 0.0f && h[2] <= 0.0f) return; // zero-height prism dropped
        ++out.stats.fullResolution;
        const float s = d.density;
        Tetrahedron t[3];
        t[0].position = {B[0], B[1], B[2], T[0]};
        t[0].scalar = {s, s, s, 0.0f};
        t[1].position = {B[1], B[2], T[0], T[1]};
        t[1].scalar = {s, s, 0.0f, 0.0f};
        t[2].position = {B[2], T[0], T[1], T[2]};
        t[2].scalar = {s, 0.0f, 0.0f, 0.0f};
        bool keep[3];
        for (int k = 0; k < 3; ++k) {
            t[k].lengthScale = {1.0f, 1.0f, 1.0f, 1.0f};
            const double o = orient(t[k]);
            const double scale = double(d.spacingWorld) * d.spacingWorld * std::max({h[0], h[1], h[2]});
            keep[k] = std::abs(o) > 1e-9 * scale;
            if (o < 0.0) { // positively oriented, as the pass expects
                std::swap(t[k].position[0], t[k].position[1]);
                std::swap(t[k].scalar[0], t[k].scalar[1]);
            }
        }
        // Chain t0 - t1 - t2 through faces (B1, B2, T0) and (B2, T0, T1): a
        // tetrahedron on the eye's side of a shared face is drawn after its neighbour.
        auto nearerFirstSide = [&](glm::vec3 f0, glm::vec3 f1, glm::vec3 f2, glm::vec3 apexOfA) {
            const glm::dvec3 p0(f0), n = glm::cross(glm::dvec3(f1) - p0, glm::dvec3(f2) - p0);
            // true: the eye is on the side of A's apex, so A is the nearer one.
            return (eyeSide(cam, p0, n) > 0.0) == (glm::dot(n, glm::dvec3(apexOfA) - p0) > 0.0);
        };
        const bool zeroNearer = nearerFirstSide(B[1], B[2], T[0], B[0]); // t0 vs t1
        const bool twoNearer = nearerFirstSide(B[2], T[0], T[1], T[2]);  // t2 vs t1
        int order[3];
        if (d.sortFree) order[0] = 0, order[1] = 1, order[2] = 2; // eq. 10: any order
        else if (!zeroNearer && twoNearer) order[0] = 0, order[1] = 1, order[2] = 2;      // t0 < t1 < t2
        else if (zeroNearer && !twoNearer) order[0] = 2, order[1] = 1, order[2] = 0; // t2 < t1 < t0
        else if (zeroNearer && twoNearer) order[0] = 1, order[1] = 0, order[2] = 2;  // t1 first; t0, t2 share an edge only
        else order[0] = 0, order[1] = 2, order[2] = 1;                              // t1 last
        for (int k : order)
            if (keep[k]) push(t[k]);
    }

    void cell(int i, int j) {
        const glm::ivec2 p00{i, j}, p10{i + 1, j}, p01{i, j + 1}, p11{i + 1, j + 1};
        glm::ivec2 first[3], second[3];
        glm::vec3 diag0, diag1, apexFirst;
        if (((i + j) & 1) == 0) { // diagonal p00-p11
            first[0] = p00, first[1] = p10, first[2] = p11;
            second[0] = p00, second[1] = p11, second[2] = p01;
            diag0 = bottom(i, j), diag1 = bottom(i + 1, j + 1), apexFirst = bottom(i + 1, j);
        } else { // diagonal p10-p01
            first[0] = p00, first[1] = p10, first[2] = p01;
            second[0] = p10, second[1] = p11, second[2] = p01;
            diag0 = bottom(i + 1, j), diag1 = bottom(i, j + 1), apexFirst = bottom(i, j);
        }
        // The two prisms are separated by the vertical plane through the diagonal: far one first.
        const glm::dvec3 p0(diag0.x, 0.0, diag0.z);
        const glm::dvec3 n = glm::cross(glm::dvec3(diag1.x, 0.0, diag1.z) - p0, glm::dvec3(0.0, 1.0, 0.0));
        const bool firstNear = (eyeSide(cam, p0, n) > 0.0) == (glm::dot(n, glm::dvec3(apexFirst.x, 0.0, apexFirst.z) - p0) > 0.0);
        if (firstNear && !d.sortFree) {
            prism(second[0], second[1], second[2]);
            prism(first[0], first[1], first[2]);
        } else {
            prism(first[0], first[1], first[2]);
            prism(second[0], second[1], second[2]);
        }
    }

    // BSP over cells [x0, x1) x [z0, z1): split the longer side at its middle
    // vertical plane, far half first (exact: the plane separates the halves).
    void range(int x0, int x1, int z0, int z1) {
        if (x1 - x0 == 1 && z1 - z0 == 1) return cell(x0, z0);
        const bool alongX = (x1 - x0) >= (z1 - z0);
        const int m = alongX ? (x0 + x1) / 2 : (z0 + z1) / 2;
        const double plane = double(alongX ? d.originWorld.x : d.originWorld.z) + double(m) * d.spacingWorld;
        const glm::dvec3 n = alongX ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 0, 1);
        const glm::dvec3 p0 = alongX ? glm::dvec3(plane, 0, 0) : glm::dvec3(0, 0, plane);
        const bool eyeHigh = eyeSide(cam, p0, n) > 0.0; // the eye is on the high side: low half is far
        if (alongX) {
            if (eyeHigh) range(x0, m, z0, z1), range(m, x1, z0, z1);
            else range(m, x1, z0, z1), range(x0, m, z0, z1);
        } else {
            if (eyeHigh) range(x0, x1, z0, m), range(x0, x1, m, z1);
            else range(x0, x1, m, z1), range(x0, x1, z0, m);
        }
    }
};

} // namespace

Result<GroundFog> GroundFog::create(const GroundFogDesc& desc) {
    if (desc.dims.x < 2 || desc.dims.y < 2 || desc.dims.x > 8192 || desc.dims.y > 8192)
        return makeError("GroundFogDesc.dims must be 2..8192 points per side, got " + std::to_string(desc.dims.x) + "x" +
                         std::to_string(desc.dims.y));
    const std::size_t n = std::size_t(desc.dims.x) * std::size_t(desc.dims.y);
    if (desc.terrainHeight.size() != n) return makeError("GroundFogDesc.terrainHeight must hold dims.x * dims.y = " + std::to_string(n) + " heights");
    if (desc.fogTop.size() != n) return makeError("GroundFogDesc.fogTop must hold dims.x * dims.y = " + std::to_string(n) + " heights");
    for (std::size_t i = 0; i < n; ++i)
        if (!std::isfinite(desc.terrainHeight[i]) || !std::isfinite(desc.fogTop[i]) || std::abs(desc.terrainHeight[i]) > 1e7f ||
            std::abs(desc.fogTop[i]) > 1e7f)
            return makeError("GroundFogDesc: height " + std::to_string(i) + " is not finite or beyond 1e7");
    if (!std::isfinite(desc.spacingWorld) || !(desc.spacingWorld > 0.0f)) return makeError("GroundFogDesc.spacingWorld must be finite and > 0");
    if (!std::isfinite(desc.density) || desc.density < 0.0f || desc.density > 1.0f) return makeError("GroundFogDesc.density must be in [0, 1]");
    if (!std::isfinite(desc.originWorld.x) || !std::isfinite(desc.originWorld.z)) return makeError("GroundFogDesc.originWorld must be finite");
    GroundFog fog;
    fog.mDesc = desc;
    for (int j = 0; j + 1 < desc.dims.y; ++j)
        for (int i = 0; i + 1 < desc.dims.x; ++i) {
            // Two triangles per cell; a prism counts if any of its vertices has fog.
            const auto th = [&](int x, int z) {
                const std::size_t k = std::size_t(x) + std::size_t(desc.dims.x) * std::size_t(z);
                return desc.fogTop[k] > desc.terrainHeight[k];
            };
            const bool odd = ((i + j) & 1) != 0;
            const bool a = odd ? (th(i, j) || th(i + 1, j) || th(i, j + 1)) : (th(i, j) || th(i + 1, j) || th(i + 1, j + 1));
            const bool b = odd ? (th(i + 1, j) || th(i + 1, j + 1) || th(i, j + 1)) : (th(i, j) || th(i + 1, j + 1) || th(i, j + 1));
            fog.mPrisms += std::uint64_t(a) + std::uint64_t(b);
        }
    return fog;
}

Status GroundFog::update(const Camera& camera, LodFrame& out) const {
    out.tets.clear();
    out.stats = {};
    const glm::vec3 e = camera.eye(), f = camera.forward();
    if (!std::isfinite(e.x) || !std::isfinite(e.y) || !std::isfinite(e.z) || !std::isfinite(f.x) || !std::isfinite(f.y) ||
        !std::isfinite(f.z))
        return makeError("GroundFog::update: the camera is not finite");
    Emitter em{mDesc, camera, out, {}, 0.0f, {}};
    em.nearNormal = f;
    em.nearOffset = glm::dot(f, e) + camera.nearPlane();
    if (mDesc.sortFree) { // eq. 10: grid order, no BSP
        for (int j = 0; j + 1 < mDesc.dims.y; ++j)
            for (int i = 0; i + 1 < mDesc.dims.x; ++i) em.cell(i, j);
    } else {
        em.range(0, mDesc.dims.x - 1, 0, mDesc.dims.y - 1);
    }
    out.stats.fullResolution *= 3; // counted per prism above
    out.stats.emitted = out.tets.size();
    return {};
}

Result<TransferFunction> makeGroundFogTransfer(glm::vec3 color, float extinctionPerWorld) {
    if (!std::isfinite(extinctionPerWorld) || extinctionPerWorld < 0.0f)
        return makeError("makeGroundFogTransfer: extinctionPerWorld must be finite and >= 0");
    return TransferFunction::create({{0.0f, color, 0.0f}, {1.0f, color, extinctionPerWorld}});
}

} // namespace splatfx
