// Ground fog as vertical prisms of three tetrahedra over a height field
// (Roettger & Ertl 2002, sec. 6): at full resolution, or over a
// view-dependent LOD terrain (a 4-8 bintree) with the fog top geomorphed.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "splatfx/volume.hpp"
#include "volume/ground_fog_light.hpp"

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
    bool clip = true;                          // LodRefineDesc::clipNear
    std::vector<glm::vec3>* terrain = nullptr; // the host's terrain triangles, or null
    // Full resolution: per-node frustum culling of the BSP (LodRefineDesc::frustumCull).
    bool cull = false;
    glm::dvec4 planes[6]{};     // the view frustum, normalized, inside >= 0
    double yLo = 0.0, yHi = 0.0; // the layer's lowest terrain and highest fog top
    bool prisms = true;          // false below a culled node: terrain only
    const detail::FogLitView* lit = nullptr; // lit layer: light scalars and density as length scale

    // Cells [x0, x1) x [z0, z1) (every prism over them within yLo..yHi) outside the frustum?
    bool outside(int x0, int x1, int z0, int z1) const {
        const double s = d.spacingWorld;
        const glm::dvec3 lo(d.originWorld.x + x0 * s, yLo, d.originWorld.z + z0 * s), hi(d.originWorld.x + x1 * s, yHi, d.originWorld.z + z1 * s);
        for (const glm::dvec4& pl : planes) {
            const glm::dvec3 p(pl.x >= 0 ? hi.x : lo.x, pl.y >= 0 ? hi.y : lo.y, pl.z >= 0 ? hi.z : lo.z);
            // A margin of 1e-6 of the box's size: float heights rounded the other way are kept.
            if (glm::dot(glm::dvec3(pl), p) + pl.w < -1e-6 * (1.0 + glm::length(hi - lo))) return true;
        }
        return false;
    }
    // Culls cells [x0, x1) x [z0, z1) when outside; true when nothing more is to be emitted for them.
    template <class Visit>
    bool culled(int x0, int x1, int z0, int z1, Visit&& visit) {
        if (!cull || !prisms || !outside(x0, x1, z0, z1)) return false;
        ++out.stats.nodesCulled;
        if (terrain) { // the host's terrain still wants the whole mesh
            prisms = false;
            visit();
            prisms = true;
        }
        return true;
    }

    // A terrain triangle, counter-clockwise seen from above (+y).
    void terrainTri(glm::vec3 a, glm::vec3 b, glm::vec3 c) {
        if (!terrain) return;
        const double ny = (double(b.z) - a.z) * (double(c.x) - a.x) - (double(b.x) - a.x) * (double(c.z) - a.z);
        if (ny < 0.0) std::swap(b, c);
        terrain->push_back(a), terrain->push_back(b), terrain->push_back(c);
    }

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
        if (clip)
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
                    for (int b = 0; b < 4; ++b)
                        found |= pieces[std::size_t(i)].position[std::size_t(a)] == pieces[std::size_t(j)].position[std::size_t(b)];
                    if (found) shared[ns++] = pieces[std::size_t(i)].position[std::size_t(a)];
                    else apexI = a;
                }
                if (ns != 3 || apexI < 0) continue;
                const glm::dvec3 p0(shared[0]), nrm = glm::cross(glm::dvec3(shared[1]) - p0, glm::dvec3(shared[2]) - p0);
                const bool iNearer =
                    (eyeSide(cam, p0, nrm) > 0.0) == (glm::dot(nrm, glm::dvec3(pieces[std::size_t(i)].position[std::size_t(apexI)]) - p0) > 0.0);
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

    // One prism vertex: its global order key, its (displayed) terrain point and fog thickness.
    struct PV {
        std::uint64_t key;
        glm::vec3 bottom;
        float h;
    };

    // One triangle's prism on grid points.
    void prism(glm::ivec2 a, glm::ivec2 b, glm::ivec2 c) {
        auto pv = [&](glm::ivec2 p) {
            return PV{std::uint64_t(p.x) + std::uint64_t(d.dims.x) * std::uint64_t(p.y), bottom(p.x, p.y), thickness(p.x, p.y)};
        };
        prismOf(pv(a), pv(b), pv(c));
    }

    // One triangle's prism: three tetrahedra by the global vertex order
    // (every shared vertical quad is split from the higher-indexed bottom
    // vertex to the lower-indexed top one, on both sides), in MPVO order.
    // Returns whether the prism had any fog (else it is dropped).
    bool prismOf(PV a, PV b, PV c) {
        PV v[3] = {a, b, c};
        std::sort(v, v + 3, [&](const PV& p, const PV& q) { return p.key < q.key; });
        float h[3];
        glm::vec3 B[3], T[3];
        for (int k = 0; k < 3; ++k) {
            h[k] = v[k].h;
            B[k] = v[k].bottom;
            T[k] = B[k] + glm::vec3(0.0f, h[k], 0.0f);
        }
        if (h[0] <= 0.0f && h[1] <= 0.0f && h[2] <= 0.0f) return false; // zero-height prism dropped
        ++out.stats.fullResolution;
        // The scalar at each bottom vertex: `density`, or affine in height (densityDepthWorld > 0).
        float sb[3];
        for (int k = 0; k < 3; ++k) sb[k] = d.densityDepthWorld > 0.0f ? std::min(d.density * h[k] / d.densityDepthWorld, 1.0f) : d.density;
        Tetrahedron t[3];
        t[0].position = {B[0], B[1], B[2], T[0]};
        t[0].scalar = {sb[0], sb[1], sb[2], 0.0f};
        t[1].position = {B[1], B[2], T[0], T[1]};
        t[1].scalar = {sb[1], sb[2], 0.0f, 0.0f};
        t[2].position = {B[2], T[0], T[1], T[2]};
        t[2].scalar = {sb[2], 0.0f, 0.0f, 0.0f};
        for (int k = 0; k < 3; ++k) t[k].lengthScale = {1.0f, 1.0f, 1.0f, 1.0f};
        if (lit) { // the fog's scalar becomes the length scale (sigma = rho f), the light the scalar
            float lb[3], lt[3];
            for (int k = 0; k < 3; ++k) lb[k] = lit->scalarAt(B[k], false), lt[k] = lit->scalarAt(T[k], true);
            t[0].lengthScale = t[0].scalar, t[0].scalar = {lb[0], lb[1], lb[2], lt[0]};
            t[1].lengthScale = t[1].scalar, t[1].scalar = {lb[1], lb[2], lt[0], lt[1]};
            t[2].lengthScale = t[2].scalar, t[2].scalar = {lb[2], lt[0], lt[1], lt[2]};
        }
        bool keep[3];
        // The prism's horizontal extent for the degenerate test (the grid spacing at full resolution).
        const double ext = std::max({std::abs(double(B[1].x) - B[0].x), std::abs(double(B[1].z) - B[0].z), std::abs(double(B[2].x) - B[0].x),
                                     std::abs(double(B[2].z) - B[0].z)});
        for (int k = 0; k < 3; ++k) {
            const double o = orient(t[k]);
            const double scale = ext * ext * std::max({h[0], h[1], h[2]});
            keep[k] = std::abs(o) > 1e-9 * scale;
            if (o < 0.0) { // positively oriented, as the pass expects
                std::swap(t[k].position[0], t[k].position[1]);
                std::swap(t[k].scalar[0], t[k].scalar[1]);
                std::swap(t[k].lengthScale[0], t[k].lengthScale[1]);
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
        if (d.sortFree) order[0] = 0, order[1] = 1, order[2] = 2;                    // eq. 10: any order
        else if (!zeroNearer && twoNearer) order[0] = 0, order[1] = 1, order[2] = 2; // t0 < t1 < t2
        else if (zeroNearer && !twoNearer) order[0] = 2, order[1] = 1, order[2] = 0; // t2 < t1 < t0
        else if (zeroNearer && twoNearer) order[0] = 1, order[1] = 0, order[2] = 2;  // t1 first; t0, t2 share an edge only
        else order[0] = 0, order[1] = 2, order[2] = 1;                               // t1 last
        for (int k : order)
            if (keep[k]) push(t[k]);
        return true;
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
        if (terrain) {
            terrainTri(bottom(first[0].x, first[0].y), bottom(first[1].x, first[1].y), bottom(first[2].x, first[2].y));
            terrainTri(bottom(second[0].x, second[0].y), bottom(second[1].x, second[1].y), bottom(second[2].x, second[2].y));
        }
        if (!prisms) return;
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
        if (culled(x0, x1, z0, z1, [&] { range(x0, x1, z0, z1); })) return;
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

// ---------------------------------------------------------------------------
// LOD terrain (sec. 6 with the metric of sec. 2.2 and the morphing of sec. 3):
// a right-triangle bintree (4-8 mesh) over the padded (2^n+1)^2 grid.
// ---------------------------------------------------------------------------

// A bintree triangle on grid points: apex `a`, hypotenuse `l`-`r`. Its
// children are (m, l, a) and (m, a, r), m the hypotenuse midpoint; it is a
// leaf when m is not a grid point (the hypotenuse is a unit-cell diagonal).
struct Tri {
    glm::ivec2 a, l, r;
};

struct LodGrid {
    int n = 0, maxDepth = 0;
    glm::ivec2 dims{0}; // the unpadded grid
    glm::vec3 origin{0.0f};
    float spacing = 1.0f;
    const float *height = nullptr, *thickness = nullptr, *delta = nullptr, *radius = nullptr;

    std::size_t at(glm::ivec2 p) const { return std::size_t(p.x) + std::size_t(n) * std::size_t(p.y); }
    // The same float expression as Emitter::bottom, so full refinement gives the same bits.
    float worldX(int i) const { return origin.x + float(i) * spacing; }
    float worldZ(int j) const { return origin.z + float(j) * spacing; }
    glm::dvec3 point(glm::ivec2 p) const { return {double(worldX(p.x)), double(height[at(p)]), double(worldZ(p.y))}; }
    // No area inside the grid (wholly in the padding, or in the cells just beyond its last row/column).
    bool outside(const Tri& t) const { return std::min({t.a.x, t.l.x, t.r.x}) >= dims.x - 1 || std::min({t.a.y, t.l.y, t.r.y}) >= dims.y - 1; }
};

// Every triangle of depth `target` (roots are depth 0), in any order.
template <class F>
void visitDepth(const Tri& t, int depth, int target, F&& f) {
    if (depth == target) return f(t);
    const glm::ivec2 m = (t.l + t.r) / 2;
    visitDepth(Tri{m, t.l, t.a}, depth + 1, target, f);
    visitDepth(Tri{m, t.a, t.r}, depth + 1, target, f);
}

// Displayed (morphed) values at a vertex: terrain height and fog thickness.
struct Shown {
    float h, th;
};

struct LodRefiner {
    const LodGrid& g;
    Emitter& em;
    glm::dvec3 eye;
    double C, c;
    bool morph;
    bool cull = false;         // LodRefineDesc::frustumCull
    glm::dvec4 planes[6]{};    // the view frustum, normalized (Gribb & Hartmann), inside >= 0
    double maxThickness = 0.0; // the layer's thickest fog
    bool prisms = true;        // false below a culled triangle: terrain only

    // Is a sphere around triangle t holding everything drawn below it outside
    // the frustum? Its descendants lie within r(m) of m (true heights); the
    // morphed heights are between the region's true ones, so sqrt(2) of that
    // radius covers them; the fog adds at most maxThickness above.
    bool culled(const Tri& t, bool splittable) const {
        const glm::dvec3 pa = g.point(t.a), pl = g.point(t.l), pr = g.point(t.r), c0 = (pa + pl + pr) / 3.0;
        double rad = std::max({glm::length(pa - c0), glm::length(pl - c0), glm::length(pr - c0)});
        if (splittable) {
            const glm::ivec2 m = (t.l + t.r) / 2;
            rad = std::max(rad, glm::length(g.point(m) - c0) + double(g.radius[g.at(m)]));
        }
        rad = rad * std::sqrt(2.0) * (1.0 + 1e-6) + maxThickness;
        for (const glm::dvec4& pl4 : planes)
            if (glm::dot(glm::dvec3(pl4), c0) + pl4.w < -rad) return true;
        return false;
    }

    void leaf(const Tri& t, Shown sa, Shown sl, Shown sr) {
        if (g.outside(t)) return;
        if (!prisms && !em.terrain) return;
        auto key = [&](glm::ivec2 p) { return std::uint64_t(p.x) + std::uint64_t(g.n) * std::uint64_t(p.y); };
        const int X = g.dims.x - 1, Z = g.dims.y - 1;
        if (std::max({t.a.x, t.l.x, t.r.x}) <= X && std::max({t.a.y, t.l.y, t.r.y}) <= Z) {
            auto pv = [&](glm::ivec2 p, Shown s) { return Emitter::PV{key(p), glm::vec3(g.worldX(p.x), s.h, g.worldZ(p.y)), s.th}; };
            const Emitter::PV a = pv(t.a, sa), l = pv(t.l, sl), r = pv(t.r, sr);
            em.terrainTri(a.bottom, l.bottom, r.bottom);
            if (prisms) em.prismOf(a, l, r);
            return;
        }
        clippedLeaf(t, sa, sl, sr, key);
    }

    // A leaf across the grid's last column or row: cut to the grid (x <= X,
    // z <= Z, in grid coordinates) so no fog and no terrain reach into the
    // padding; the convex piece is fanned and the fan drawn by a BSP through
    // its apex. Cut points are computed from the original edge, from its
    // lower-keyed end, and keyed by the edge, so the triangle across that
    // edge makes the same point with the same key (conforming prisms).
    template <class Key>
    void clippedLeaf(const Tri& t, Shown sa, Shown sl, Shown sr, Key&& key) {
        struct CV {
            glm::dvec2 p;
            float h, th;
            std::uint64_t key;
        };
        const int X = g.dims.x - 1, Z = g.dims.y - 1;
        const glm::ivec2 v[3] = {t.a, t.l, t.r};
        const Shown sv[3] = {sa, sl, sr};
        const std::uint64_t nn = std::uint64_t(g.n) * std::uint64_t(g.n);
        CV pts[12];
        int np = 0;
        auto add = [&](const CV& c) {
            for (int i = 0; i < np; ++i)
                if (pts[i].p == c.p) {
                    pts[i].key = std::min(pts[i].key, c.key);
                    return;
                }
            pts[np++] = c;
        };
        for (int i = 0; i < 3; ++i)
            if (v[i].x <= X && v[i].y <= Z) add({glm::dvec2(v[i]), sv[i].h, sv[i].th, key(v[i])});
        for (int i = 0; i < 3; ++i) {
            int u = i, w = (i + 1) % 3;
            if (key(v[w]) < key(v[u])) std::swap(u, w);
            const glm::dvec2 pu(v[u]), pw(v[w]);
            const std::uint64_t ek = nn + 2 * (key(v[u]) * nn + key(v[w]));
            auto cut = [&](double s, int line) {
                const glm::dvec2 q = pu + s * (pw - pu);
                const float fs = float(s);
                add({line == 0 ? glm::dvec2(double(X), q.y) : glm::dvec2(q.x, double(Z)), sv[u].h + fs * (sv[w].h - sv[u].h),
                     sv[u].th + fs * (sv[w].th - sv[u].th), ek + std::uint64_t(line)});
            };
            if ((pu.x - X) * (pw.x - X) < 0.0) {
                const double s = (X - pu.x) / (pw.x - pu.x);
                if (pu.y + s * (pw.y - pu.y) <= Z) cut(s, 0);
            }
            if ((pu.y - Z) * (pw.y - Z) < 0.0) {
                const double s = (Z - pu.y) / (pw.y - pu.y);
                if (pu.x + s * (pw.x - pu.x) <= X) cut(s, 1);
            }
        }
        { // the grid's corner, if strictly inside the triangle
            const glm::dvec2 c(X, Z), a(v[0]), b(v[1]), d(v[2]);
            const double det = (b.x - a.x) * (d.y - a.y) - (d.x - a.x) * (b.y - a.y);
            const double l1 = ((c.x - a.x) * (d.y - a.y) - (d.x - a.x) * (c.y - a.y)) / det;
            const double l2 = ((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y)) / det;
            if (l1 > 0.0 && l2 > 0.0 && l1 + l2 < 1.0) {
                const float f1 = float(l1), f2 = float(l2), f0 = 1.0f - f1 - f2;
                add({c, f0 * sv[0].h + f1 * sv[1].h + f2 * sv[2].h, f0 * sv[0].th + f1 * sv[1].th + f2 * sv[2].th, ~std::uint64_t(0) - 1});
            }
        }
        if (np < 3) return;
        // Convex: sort by angle around the centroid.
        glm::dvec2 cen(0.0);
        for (int i = 0; i < np; ++i) cen += pts[i].p;
        cen /= double(np);
        double ang[12];
        for (int i = 0; i < np; ++i) ang[i] = std::atan2(pts[i].p.y - cen.y, pts[i].p.x - cen.x);
        for (int i = 1; i < np; ++i) // insertion sort: at most 7 points
            for (int j = i; j > 0 && ang[j] < ang[j - 1]; --j) std::swap(ang[j], ang[j - 1]), std::swap(pts[j], pts[j - 1]);
        auto world = [&](const CV& c) {
            const float x = c.p.x == std::floor(c.p.x) ? g.worldX(int(c.p.x)) : float(double(g.origin.x) + c.p.x * double(g.spacing));
            const float z = c.p.y == std::floor(c.p.y) ? g.worldZ(int(c.p.y)) : float(double(g.origin.z) + c.p.y * double(g.spacing));
            return Emitter::PV{c.key, glm::vec3(x, c.h, z), c.th};
        };
        Emitter::PV wp[12];
        for (int i = 0; i < np; ++i) wp[i] = world(pts[i]);
        // Fan triangles (0, i+1, i+2), i in [lo, hi): split at the line 0 - (k+1), far half first.
        auto emit = [&](auto&& self, int lo, int hi) -> void {
            if (hi - lo == 1) {
                em.terrainTri(wp[0].bottom, wp[lo + 1].bottom, wp[lo + 2].bottom);
                if (prisms) em.prismOf(wp[0], wp[lo + 1], wp[lo + 2]);
                return;
            }
            const int k = (lo + hi) / 2;
            const glm::dvec3 p0(wp[0].bottom.x, 0.0, wp[0].bottom.z), pk(wp[k + 1].bottom.x, 0.0, wp[k + 1].bottom.z);
            const glm::dvec3 side(wp[k].bottom.x, 0.0, wp[k].bottom.z); // in triangle k-1, the low half
            const glm::dvec3 nrm = glm::cross(pk - p0, glm::dvec3(0.0, 1.0, 0.0));
            const bool lowNear = (eyeSide(em.cam, p0, nrm) > 0.0) == (glm::dot(nrm, side - p0) > 0.0);
            if (lowNear && !em.d.sortFree) self(self, k, hi), self(self, lo, k);
            else self(self, lo, k), self(self, k, hi);
        };
        emit(emit, 0, np - 2);
    }

    void refine(const Tri& t, int depth, Shown sa, Shown sl, Shown sr) {
        if (cull && prisms && culled(t, depth < g.maxDepth)) {
            ++em.out.stats.nodesCulled;
            if (!em.terrain) return; // nothing below is drawn
            prisms = false;          // the host's terrain still wants the whole mesh
            refine(t, depth, sa, sl, sr);
            prisms = true;
            return;
        }
        if (depth < g.maxDepth) {
            const glm::ivec2 m = (t.l + t.r) / 2;
            const std::size_t k = g.at(m);
            const double len = glm::length(glm::dvec2(t.r - t.l)) * double(g.spacing);
            const double dist = glm::length(eye - g.point(m)) - double(g.radius[k]);
            const double e = dist > 0.0 ? len * C * std::max(c * double(g.delta[k]), 1.0) / dist : std::numeric_limits<double>::infinity();
            if (e > 1.0) {
                ++em.out.stats.nodesRefined;
                // Geomorph (sec. 3): from the coarse edge (w = 0, e = 1) to the true value (w = 1, e >= 2).
                const float w = morph ? float(std::min(e - 1.0, 1.0)) : 1.0f;
                const float avgH = 0.5f * (sl.h + sr.h), avgT = 0.5f * (sl.th + sr.th);
                const Shown sm{(1.0f - w) * avgH + w * g.height[k], (1.0f - w) * avgT + w * g.thickness[k]};
                const Tri c1{m, t.l, t.a}, c2{m, t.a, t.r};
                // c1 holds l, c2 holds r; the vertical plane through a and m separates them: far one first.
                const glm::dvec3 p0(g.worldX(t.a.x), 0.0, g.worldZ(t.a.y));
                const glm::dvec3 pm(g.worldX(m.x), 0.0, g.worldZ(m.y)), pl(g.worldX(t.l.x), 0.0, g.worldZ(t.l.y));
                const glm::dvec3 nrm = glm::cross(pm - p0, glm::dvec3(0.0, 1.0, 0.0));
                const bool c1Near = (eyeSide(em.cam, p0, nrm) > 0.0) == (glm::dot(nrm, pl - p0) > 0.0);
                if (c1Near && !em.d.sortFree) {
                    refine(c2, depth + 1, sm, sa, sr);
                    refine(c1, depth + 1, sm, sl, sa);
                } else {
                    refine(c1, depth + 1, sm, sl, sa);
                    refine(c2, depth + 1, sm, sa, sr);
                }
                return;
            }
        }
        leaf(t, sa, sl, sr);
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
    if (!std::isfinite(desc.densityDepthWorld) || desc.densityDepthWorld < 0.0f)
        return makeError("GroundFogDesc.densityDepthWorld must be finite and >= 0");
    if (desc.densityDepthWorld > 0.0f)
        for (std::size_t i = 0; i < n; ++i)
            if (desc.fogTop[i] - desc.terrainHeight[i] > desc.densityDepthWorld * (1.0f + 1e-6f))
                return makeError("GroundFogDesc.densityDepthWorld (" + std::to_string(desc.densityDepthWorld) + ") is below the fog thickness " +
                                 std::to_string(desc.fogTop[i] - desc.terrainHeight[i]) + " at point " + std::to_string(i));
    if (desc.lod && (!std::isfinite(desc.minAccuracyC) || !(desc.minAccuracyC > 0.0f)))
        return makeError("GroundFogDesc.minAccuracyC must be finite and > 0, got " + std::to_string(desc.minAccuracyC));
    GroundFog fog;
    fog.mDesc = desc;
    // Heights: every vertex update() emits has a terrain height or a fog top,
    // or (LOD) a morph between such heights of the same kind, which stays
    // inside their range.
    float lowest = std::numeric_limits<float>::infinity(), highest = -lowest;
    for (std::size_t i = 0; i < n; ++i) {
        lowest = std::min({lowest, desc.terrainHeight[i], desc.fogTop[i]});
        highest = std::max({highest, desc.terrainHeight[i], desc.fogTop[i]});
    }
    // Across: the grid, or the LOD's padded grid (set below), where fog tapers off.
    const auto across = [&](int pointsX, int pointsZ) {
        fog.mBounds =
            Aabb{{desc.originWorld.x, lowest, desc.originWorld.z},
                 {desc.originWorld.x + float(pointsX - 1) * desc.spacingWorld, highest, desc.originWorld.z + float(pointsZ - 1) * desc.spacingWorld}};
    };
    across(desc.dims.x, desc.dims.y);
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
    if (!desc.lod) return fog;

    // LOD: pad to (2^k + 1)^2, terrain clamped to the edge, no fog in the padding.
    int levels = 0;
    while ((1 << levels) + 1 < std::max(desc.dims.x, desc.dims.y)) ++levels;
    const int side = (1 << levels) + 1;
    fog.mN = side;
    fog.mMaxDepth = 2 * levels;
    across(side, side);
    const std::size_t np = std::size_t(side) * std::size_t(side);
    fog.mHeight.resize(np);
    fog.mThickness.resize(np);
    fog.mDelta.assign(np, 0.0f);
    fog.mRadius.assign(np, 0.0f);
    for (int j = 0; j < side; ++j)
        for (int i = 0; i < side; ++i) {
            const std::size_t src = std::size_t(std::min(i, desc.dims.x - 1)) + std::size_t(desc.dims.x) * std::size_t(std::min(j, desc.dims.y - 1));
            const std::size_t dst = std::size_t(i) + std::size_t(side) * std::size_t(j);
            const bool inside = i < desc.dims.x && j < desc.dims.y;
            fog.mHeight[dst] = desc.terrainHeight[src];
            fog.mThickness[dst] = inside ? std::max(desc.fogTop[src] - desc.terrainHeight[src], 0.0f) : 0.0f;
            fog.mMaxThickness = std::max(fog.mMaxThickness, double(fog.mThickness[dst]));
        }
    LodGrid g;
    g.n = side, g.maxDepth = fog.mMaxDepth, g.dims = desc.dims, g.origin = desc.originWorld, g.spacing = desc.spacingWorld;
    g.height = fog.mHeight.data(), g.thickness = fog.mThickness.data();
    const int s = side - 1;
    const Tri roots[2] = {{{s, 0}, {0, 0}, {s, s}}, {{0, s}, {s, s}, {0, 0}}};
    // Bottom up by depth: a vertex's local Delta (terrain and fog top against
    // the hypotenuse ends' average), then saturated from its children (the
    // midpoints of the children's hypotenuses, final once the deeper depth is
    // done). The slack on r keeps d(parent) <= d(child) under rounding.
    for (int depth = fog.mMaxDepth - 1; depth >= 0; --depth)
        for (const Tri& root : roots)
            visitDepth(root, 0, depth, [&](const Tri& t) {
                const glm::ivec2 m = (t.l + t.r) / 2;
                const std::size_t km = g.at(m), kl = g.at(t.l), kr = g.at(t.r);
                const double h = fog.mHeight[km], hl = fog.mHeight[kl], hr = fog.mHeight[kr];
                const double top = h + fog.mThickness[km], topL = hl + fog.mThickness[kl], topR = hr + fog.mThickness[kr];
                double dlt = std::max(std::abs(h - 0.5 * (hl + hr)), std::abs(top - 0.5 * (topL + topR)));
                // A triangle across the grid's last row or column carries fog
                // into the padding (tapering to its padded corners' 0) until it
                // splits: count that fog as deviation too, so the metric refines
                // the boundary where fog reaches it.
                const int dx = desc.dims.x - 1, dy = desc.dims.y - 1;
                const int x0 = std::min({t.a.x, t.l.x, t.r.x}), x1 = std::max({t.a.x, t.l.x, t.r.x});
                const int y0 = std::min({t.a.y, t.l.y, t.r.y}), y1 = std::max({t.a.y, t.l.y, t.r.y});
                if ((x0 < dx && x1 > dx) || (y0 < dy && y1 > dy))
                    dlt = std::max({dlt, double(fog.mThickness[g.at(t.a)]), double(fog.mThickness[kl]), double(fog.mThickness[kr])});
                double rad = fog.mRadius[km];
                if (depth + 1 < fog.mMaxDepth)
                    for (glm::ivec2 c : {(t.l + t.a) / 2, (t.a + t.r) / 2}) {
                        const std::size_t kc = g.at(c);
                        dlt = std::max(dlt, double(fog.mDelta[kc]));
                        rad = std::max(rad, (double(fog.mRadius[kc]) + glm::length(g.point(m) - g.point(c))) * (1.0 + 1e-6));
                    }
                // Rounded up to float so the saturation survives the store.
                float df = float(dlt), rf = float(rad);
                if (double(df) < dlt) df = std::nextafter(df, std::numeric_limits<float>::infinity());
                if (double(rf) < rad) rf = std::nextafter(rf, std::numeric_limits<float>::infinity());
                fog.mDelta[km] = std::max(fog.mDelta[km], df);
                fog.mRadius[km] = std::max(fog.mRadius[km], rf);
            });
    // The desc's arrays are not needed by the LOD path.
    fog.mDesc.terrainHeight = {};
    fog.mDesc.fogTop = {};
    return fog;
}

std::size_t GroundFog::bytesFor(glm::ivec2 dims, bool lod) {
    if (dims.x < 2 || dims.y < 2) return 0;
    if (!lod) return 2 * sizeof(float) * std::size_t(dims.x) * std::size_t(dims.y);
    int k = 0;
    while ((1 << k) + 1 < std::max(dims.x, dims.y)) ++k;
    const std::size_t n = (std::size_t(1) << k) + 1;
    return 4 * sizeof(float) * n * n;
}

std::size_t GroundFog::memoryBytes() const {
    return sizeof(float) * (mDesc.terrainHeight.size() + mDesc.fogTop.size() + mHeight.size() + mThickness.size() + mDelta.size() + mRadius.size());
}

Status GroundFog::update(const Camera& camera, LodFrame& out) const { return update(camera, LodRefineDesc{}, out, nullptr); }

Status GroundFog::update(const Camera& camera, const LodRefineDesc& refine, LodFrame& out, std::vector<glm::vec3>* terrainTriangles) const {
    out.tets.clear();
    out.rgb.clear();
    out.stats = {};
    if (terrainTriangles) terrainTriangles->clear();
    const glm::vec3 e = camera.eye(), f = camera.forward();
    if (!std::isfinite(e.x) || !std::isfinite(e.y) || !std::isfinite(e.z) || !std::isfinite(f.x) || !std::isfinite(f.y) || !std::isfinite(f.z))
        return makeError("GroundFog::update: the camera is not finite");
    if (!std::isfinite(refine.detailC) || refine.detailC < 0.0f) return makeError("GroundFog::update: LodRefineDesc.detailC must be finite and >= 0");
    Emitter em{mDesc, camera, out, {}, 0.0f, {}, refine.clipNear, terrainTriangles};
    detail::FogFieldView field;
    detail::FogLitView litView;
    if (mLit) {
        field = fieldView();
        litView.field = &field;
        litView.sunT = mSunT.data();
        litView.phase = &mLighting.gas.phase;
        litView.travel = glm::normalize(mLighting.sun.direction);
        litView.eye = e, litView.back = -f, litView.perspective = camera.perspective();
        const PhaseFunction& ph = mLighting.gas.phase;
        litView.isotropic = ph.lobeCount() == 1 && ph.lobe(0).g == 0.0f; // s = T
        litView.invPhaseMax = 1.0f / mPhaseMax;
        em.lit = &litView;
    }
    em.nearNormal = f;
    em.nearOffset = glm::dot(f, e) + camera.nearPlane();
    glm::dvec4 planes[6];
    const glm::dmat4 vp = glm::dmat4(camera.proj) * glm::dmat4(camera.view);
    for (int i = 0; i < 3; ++i)
        for (int sign = 0; sign < 2; ++sign) {
            glm::dvec4 pl = glm::dvec4(vp[0][3], vp[1][3], vp[2][3], vp[3][3]) + (sign ? -1.0 : 1.0) * glm::dvec4(vp[0][i], vp[1][i], vp[2][i], vp[3][i]);
            const double len = glm::length(glm::dvec3(pl));
            planes[2 * i + sign] = len > 0.0 ? pl / len : glm::dvec4(0.0, 0.0, 0.0, 1.0); // degenerate: never culls
        }
    if (mDesc.lod) {
        LodGrid g;
        g.n = mN, g.maxDepth = mMaxDepth, g.dims = mDesc.dims, g.origin = mDesc.originWorld, g.spacing = mDesc.spacingWorld;
        g.height = mHeight.data(), g.thickness = mThickness.data(), g.delta = mDelta.data(), g.radius = mRadius.data();
        LodRefiner r{g, em, glm::dvec3(e), double(mDesc.minAccuracyC), double(refine.detailC), refine.morph};
        r.cull = refine.frustumCull;
        r.maxThickness = mMaxThickness;
        for (int i = 0; i < 6; ++i) r.planes[i] = planes[i];
        const int s = mN - 1;
        const Tri roots[2] = {{{s, 0}, {0, 0}, {s, s}}, {{0, s}, {s, s}, {0, 0}}};
        auto shown = [&](glm::ivec2 p) { return Shown{mHeight[g.at(p)], mThickness[g.at(p)]}; };
        // The roots are separated by the vertical plane through the diagonal (0,0)-(s,s): far one first.
        const glm::dvec3 p0(g.worldX(0), 0.0, g.worldZ(0)), p1(g.worldX(s), 0.0, g.worldZ(s)), pa(g.worldX(s), 0.0, g.worldZ(0));
        const glm::dvec3 nrm = glm::cross(p1 - p0, glm::dvec3(0.0, 1.0, 0.0));
        const bool firstNear = (eyeSide(camera, p0, nrm) > 0.0) == (glm::dot(nrm, pa - p0) > 0.0);
        const int order[2] = {firstNear && !mDesc.sortFree ? 1 : 0, firstNear && !mDesc.sortFree ? 0 : 1};
        for (int i : order) {
            const Tri& t = roots[i];
            r.refine(t, 0, shown(t.a), shown(t.l), shown(t.r));
        }
        out.stats.fullResolution = 3 * mPrisms;
        out.stats.emitted = out.tets.size();
        return {};
    }
    // Full resolution: the BSP's nodes (sortFree: rows, then cells) outside the frustum emit no prisms.
    em.cull = refine.frustumCull;
    for (int i = 0; i < 6; ++i) em.planes[i] = planes[i];
    em.yLo = double(mBounds.lo.y), em.yHi = double(mBounds.hi.y);
    if (mDesc.sortFree) { // eq. 10: grid order, no BSP
        const int cx = mDesc.dims.x - 1;
        for (int j = 0; j + 1 < mDesc.dims.y; ++j) {
            auto row = [&] {
                for (int i = 0; i < cx; ++i)
                    if (!em.culled(i, i + 1, j, j + 1, [&] { em.cell(i, j); })) em.cell(i, j);
            };
            if (!em.culled(0, cx, j, j + 1, row)) row();
        }
    } else {
        em.range(0, mDesc.dims.x - 1, 0, mDesc.dims.y - 1);
    }
    out.stats.fullResolution = 3 * mPrisms; // every prism with fog, culled or not
    out.stats.emitted = out.tets.size();
    return {};
}

Result<TransferFunction> makeGroundFogTransfer(glm::vec3 color, float extinctionPerWorld) {
    if (!std::isfinite(extinctionPerWorld) || extinctionPerWorld < 0.0f)
        return makeError("makeGroundFogTransfer: extinctionPerWorld must be finite and >= 0");
    return TransferFunction::create({{0.0f, color, 0.0f}, {1.0f, color, extinctionPerWorld}});
}

} // namespace splatfx
