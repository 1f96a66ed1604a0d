// Splat-exact reference: the splat model of splats.hpp evaluated without the
// real-time path's approximations (see reference.hpp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <vector>

#include "reference_common.hpp"
#include "splatfx/reference.hpp"

namespace splatfx {
namespace {

constexpr double kLn2 = 0.69314718055994530942;
constexpr int kTile = 16;

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// One layer as the reference samples it, in double: RGB as stored, alpha
// either as stored or with the sampled footprint window divided out.
struct RefLayer {
    int size = 0;
    std::vector<glm::dvec4> texels;

    // GL_LINEAR, GL_CLAMP_TO_EDGE, texel centres at (i + 0.5) / size.
    glm::dvec4 sample(double s, double t) const {
        const double fx = s * size - 0.5, fy = t * size - 0.5;
        const double x0f = std::floor(fx), y0f = std::floor(fy);
        const double ax = fx - x0f, ay = fy - y0f;
        auto clampi = [&](double v) { return int(std::clamp(v, 0.0, double(size - 1))); };
        const int x0 = clampi(x0f), x1 = clampi(x0f + 1.0), y0 = clampi(y0f), y1 = clampi(y0f + 1.0);
        auto at = [&](int x, int y) { return texels[size_t(y) * size + x]; };
        return (at(x0, y0) * (1.0 - ax) + at(x1, y0) * ax) * (1.0 - ay) + (at(x0, y1) * (1.0 - ax) + at(x1, y1) * ax) * ay;
    }
};

RefLayer makeLayer(const Materials& m, std::uint32_t index, const std::vector<float>& window, bool divideWindow) {
    RefLayer L;
    L.size = m.layerSize();
    const int n = L.size;
    const std::vector<float>& src = m.layer(index);
    L.texels.resize(size_t(n) * n);
    for (size_t p = 0; p < L.texels.size(); ++p) L.texels[p] = glm::dvec4(src[p * 4], src[p * 4 + 1], src[p * 4 + 2], src[p * 4 + 3]);
    if (!divideWindow) return L;
    // TextureSet::windowed stored alpha = detail * window(texel centre); undo it.
    std::vector<char> known(L.texels.size(), 0);
    for (size_t p = 0; p < L.texels.size(); ++p)
        if (window[p] > 0.0f) {
            L.texels[p].a = std::clamp(double(src[p * 4 + 3]) / double(window[p]), 0.0, 1.0);
            known[p] = 1;
        }
    // Texels whose centre lies outside the support carry no detail; extend the
    // nearest inner texel along the radius so bilinear taps near the rim see
    // detail, not zero (the exact window is what brings the rim to zero).
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const size_t p = size_t(y) * n + x;
            if (known[p]) continue;
            const double cx = x + 0.5 - 0.5 * n, cy = y + 0.5 - 0.5 * n;
            const double len = std::sqrt(cx * cx + cy * cy);
            double a = 0.0;
            for (double k = 1.0; k < len; k += 0.5) {
                const int xi = int(std::floor(0.5 * n + cx * (1.0 - k / len)));
                const int yi = int(std::floor(0.5 * n + cy * (1.0 - k / len)));
                if (xi < 0 || yi < 0 || xi >= n || yi >= n) continue;
                if (known[size_t(yi) * n + xi]) {
                    a = L.texels[size_t(yi) * n + xi].a;
                    break;
                }
            }
            L.texels[p].a = a;
        }
    return L;
}

struct Fragment {
    double t;
    double alpha;
    glm::dvec3 color; // premultiplied
    int side = 1;     // at equal t: 0 in front of a surface, 1 at it, 2 behind it
};

// Ray parameters where the ray crosses a triangle (Moller-Trumbore), in (0, tMax].
void crossings(const ReferenceSurface& s, const glm::dvec3& o, const glm::dvec3& d, double tMax, std::vector<double>& out) {
    for (std::size_t i = 0; i + 2 < s.triangles.size(); i += 3) {
        const glm::dvec3 a = s.triangles[i], e1 = s.triangles[i + 1] - a, e2 = s.triangles[i + 2] - a;
        const glm::dvec3 p = glm::cross(d, e2);
        const double det = glm::dot(e1, p);
        if (!(std::abs(det) > 1e-300)) continue;
        const glm::dvec3 q = o - a;
        const double u = glm::dot(q, p) / det;
        // u > 0: a ray through a quad's diagonal crosses it once (its second triangle has v = 0 there).
        if (u <= 0.0 || u > 1.0) continue;
        const glm::dvec3 qe = glm::cross(q, e1);
        const double v = glm::dot(d, qe) / det;
        if (v < 0.0 || u + v > 1.0) continue;
        const double t = glm::dot(e2, qe) / det;
        if (t > 0.0 && t <= tMax && std::isfinite(t)) out.push_back(t);
    }
}

} // namespace

// (issue 15)
ReferenceSurface ReferenceSurface::quad(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d, glm::dvec4 premultiplied) {
    return {{a, b, c, a, c, d}, premultiplied};
}
ReferenceSurface ReferenceSurface::box(glm::dvec3 lo, glm::dvec3 hi, glm::dvec4 premultiplied) {
    ReferenceSurface s{{}, premultiplied};
    auto corner = [&](int i) { return glm::dvec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z); };
    const int faces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
    for (const auto& f : faces) {
        const ReferenceSurface q = quad(corner(f[0]), corner(f[1]), corner(f[2]), corner(f[3]), premultiplied);
        s.triangles.insert(s.triangles.end(), q.triangles.begin(), q.triangles.end());
    }
    return s;
}

Result<Image> renderSplatExact(const std::vector<Splat>& splats, const Camera& camera, const Materials& materials, const SplatExactDesc& desc,
                               SplatExactStats* statsOut) {
    if (Status s = reference::checkHost(desc.host, camera, "renderSplatExact"); !s) return makeError(s.error());
    const int W = camera.viewport.x, H = camera.viewport.y;
    const Footprint& fp = materials.footprint();
    const double R = fp.radius();
    const double F0 = fp.exact(0.0);
    const bool exactWindow = desc.window == ReferenceWindow::Exact;
    const bool cut = desc.depthCut;

    std::vector<RefLayer> layers;
    {
        const std::vector<float> window = fp.image(materials.layerSize());
        for (std::uint32_t i = 0; i < materials.layerCount(); ++i) layers.push_back(makeLayer(materials, i, window, exactWindow));
    }

    SplatExactStats stats;
    // Bin splats into screen tiles by the bounding box of their drawn polygon.
    const int tilesX = (W + kTile - 1) / kTile, tilesY = (H + kTile - 1) / kTile;
    std::vector<std::vector<std::uint32_t>> tiles(size_t(tilesX) * tilesY);
    const glm::dmat4 vp = glm::dmat4(camera.proj) * glm::dmat4(camera.view);
    const double o = 0.41421356; // the octagon of shaders.hpp
    const double octU[8] = {1, 1, o, o, -o, -o, -1, -1}, octV[8] = {-o, o, -1, 1, -1, 1, -o, o};
    const double sqU[4] = {-1, 1, -1, 1}, sqV[4] = {-1, -1, 1, 1};
    for (size_t i = 0; i < splats.size(); ++i) {
        const Splat& s = splats[i];
        const std::uint32_t layer = std::uint32_t(std::lround(s.layer)), next = std::uint32_t(std::lround(s.nextLayer));
        const std::uint32_t row = std::uint32_t(std::lround(s.colorRow));
        if (!finite(s.center) || !finite(s.axisU) || !finite(s.axisV) || !std::isfinite(s.density) || !std::isfinite(s.blend) || !(s.layer >= 0.0f) ||
            layer >= materials.layerCount() || (s.blend > 0.0f && (!(s.nextLayer >= 0.0f) || next >= materials.layerCount())) ||
            !(s.colorRow >= 0.0f) || row >= std::max(materials.colorTableCount(), 1u)) {
            ++stats.skippedSplats;
            continue;
        }
        double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
        bool behind = false;
        const int nv = desc.trimCorners ? 8 : 4;
        for (int k = 0; k < nv; ++k) {
            const double u = desc.trimCorners ? octU[k] : sqU[k], v = desc.trimCorners ? octV[k] : sqV[k];
            const glm::dvec4 c = vp * glm::dvec4(glm::dvec3(s.center) + u * glm::dvec3(s.axisU) + v * glm::dvec3(s.axisV), 1.0);
            if (!(c.w > 1e-12)) {
                behind = true; // crosses the eye plane: the clipped polygon may cover anything
                break;
            }
            const double px = (c.x / c.w * 0.5 + 0.5) * W, py = (1.0 - (c.y / c.w * 0.5 + 0.5)) * H;
            x0 = std::min(x0, px), x1 = std::max(x1, px), y0 = std::min(y0, py), y1 = std::max(y1, py);
        }
        int tx0 = 0, ty0 = 0, tx1 = tilesX - 1, ty1 = tilesY - 1;
        if (!behind) {
            if (x1 < 0.0 || y1 < 0.0 || x0 > W || y0 > H) continue;
            tx0 = std::clamp(int(std::floor(x0)) / kTile, 0, tilesX - 1);
            tx1 = std::clamp(int(std::floor(std::min(x1, double(W)))) / kTile, 0, tilesX - 1);
            ty0 = std::clamp(int(std::floor(y0)) / kTile, 0, tilesY - 1);
            ty1 = std::clamp(int(std::floor(std::min(y1, double(H)))) / kTile, 0, tilesY - 1);
        }
        for (int ty = ty0; ty <= ty1; ++ty)
            for (int tx = tx0; tx <= tx1; ++tx) tiles[size_t(ty) * tilesX + tx].push_back(std::uint32_t(i));
    }

    Image out;
    out.width = W;
    out.height = H;
    out.channels = 4;
    out.pixels.assign(size_t(W) * H * 4, 0.0f);
    const reference::RayMapper mapper(camera);
    std::mutex statsMutex;

    // Fog: integrated from the eye. With a perspective camera every pixel ray
    // passes through the eye, so the optical depths to the fragments are
    // accumulated piece by piece along the ray; otherwise each is integrated
    // from the eye on its own.
    const Fog* fog = desc.fog && !desc.fog->empty() ? desc.fog : nullptr;
    const glm::dvec3 eye(camera.eye());
    const bool throughEye = camera.perspective();
    const double fogFar = fog ? fog->desc().farDistanceWorld : 0.0;
    const glm::dvec3 fogColour = fog ? fog->desc().colour : glm::dvec3(0.0);

    reference::parallelRows(H, desc.threads, [&](int y) {
        std::vector<Fragment> frags;
        std::vector<double> cuts;
        std::vector<glm::dvec4> cutColour;
        std::uint64_t fragCount = 0, maxOverlap = 0;
        double fogTauMax = 0.0, fogErrMax = 0.0;
        std::uint64_t fogBad = 0;
        for (int x = 0; x < W; ++x) {
            const reference::PixelRay ray = mapper.ray(x, y, reference::hostDepth(desc.host, x, y));
            frags.clear();
            // This ray's surface crossings, near to far, and their colours.
            cuts.clear();
            cutColour.clear();
            if (!desc.surfaces.empty()) {
                std::vector<std::pair<double, glm::dvec4>> hits;
                for (const ReferenceSurface& surf : desc.surfaces) {
                    const std::size_t before = cuts.size();
                    crossings(surf, ray.origin, ray.dir, ray.tLimit, cuts);
                    for (std::size_t k = before; k < cuts.size(); ++k) hits.push_back({cuts[k], surf.premultiplied});
                }
                std::stable_sort(hits.begin(), hits.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
                cuts.clear();
                for (const auto& h : hits)
                    if (h.second != glm::dvec4(0.0)) cuts.push_back(h.first), cutColour.push_back(h.second);
            }
            for (std::uint32_t idx : tiles[size_t(y / kTile) * tilesX + x / kTile]) {
                const Splat& s = splats[idx];
                const glm::dvec3 c(s.center), au(s.axisU), av(s.axisV);
                const glm::dvec3 n = glm::cross(au, av);
                const double nLen = glm::length(n);
                const double denom = glm::dot(ray.dir, n);
                if (!(nLen > 0.0) || std::abs(denom) <= 1e-12 * nLen) continue; // edge-on: GL rasterizes nothing
                const double t = glm::dot(c - ray.origin, n) / denom;
                if (!std::isfinite(t)) continue;
                if (!cut && (!(t >= 0.0) || t > ray.tLimit)) continue; // clipped by near/far or hidden by host depth
                const glm::dvec3 r = ray.origin + t * ray.dir - c;
                const double g00 = glm::dot(au, au), g01 = glm::dot(au, av), g11 = glm::dot(av, av);
                const double b0 = glm::dot(au, r), b1 = glm::dot(av, r);
                const double det = g00 * g11 - g01 * g01;
                if (!(det > 0.0)) continue;
                const double u = (g11 * b0 - g01 * b1) / det, v = (g00 * b1 - g01 * b0) / det;
                if (std::abs(u) > 1.0 || std::abs(v) > 1.0) continue;
                if (desc.trimCorners && std::abs(u) + std::abs(v) > 1.0 + o) continue;
                // The vertex shader's texture coordinates: +v is the layer's top row.
                const double ts = 0.5 + 0.5 * u, tt = 0.5 - 0.5 * v;
                glm::dvec4 tex = layers[size_t(std::lround(s.layer))].sample(ts, tt);
                if (s.blend > 0.0f) {
                    const glm::dvec4 t2 = layers[size_t(std::lround(s.nextLayer))].sample(ts, tt);
                    tex = tex * (1.0 - double(s.blend)) + t2 * double(s.blend);
                }
                double detail = tex.a;
                if (exactWindow) {
                    const double rr = R * std::sqrt(u * u + v * v);
                    detail *= rr < R ? fp.exact(rr) / F0 : 0.0;
                }
                const std::uint32_t row = std::uint32_t(std::lround(s.colorRow));
                const glm::dvec3 base =
                    desc.packedColor ? glm::dvec3(double(s.color & 255u), double((s.color >> 8) & 255u), double((s.color >> 16) & 255u)) / 255.0 *
                                           (s.colorCoord < 0.0f ? -double(s.colorCoord) : 1.0)
                    : row < materials.colorTableCount() ? reference::rowColor(materials.colorRow(row), s.colorCoord)
                                                        : glm::dvec3(1.0);
                const glm::dvec3 col = base * glm::dvec3(tex);
                if (!cuts.empty()) {
                    // (issue 15) Sections at the surface crossings: each
                    // keeps its share of the kernel's line integral (depthCut)
                    // or, without the cut, the whole fragment sits at its plane.
                    double l = 1.0, rr = 0.0;
                    if (cut) {
                        l = double(splatRayScale(s, float(R)));
                        if (!(l > 0.0)) continue;
                        rr = R * std::sqrt(u * u + v * v);
                    }
                    auto before = [&](double tc) { // share in front of ray parameter tc
                        return cut ? fp.exactFractionBefore(rr, (tc - t) / l) : (t <= tc ? 1.0 : 0.0);
                    };
                    const double lo = cut ? before(0.0) : 0.0, hi = cut ? std::max(before(ray.tLimit), lo) : 1.0;
                    if (!cut && (!(t >= 0.0) || t > ray.tLimit)) continue;
                    double prev = lo, prevT = 0.0;
                    for (std::size_t k = 0; k <= cuts.size(); ++k) {
                        const double tk = k < cuts.size() ? cuts[k] : ray.tLimit;
                        const double F = k < cuts.size() ? std::clamp(before(tk), lo, hi) : hi;
                        const double share = F - prev;
                        prev = std::max(prev, F);
                        const double lowT = prevT;
                        prevT = tk;
                        if (!(share > 0.0)) continue;
                        const double a = -std::expm1(-kLn2 * double(s.density) * detail * share);
                        if (!(a > 0.0)) continue;
                        double key = t;
                        int side = 1;
                        if (k > 0 && key <= lowT) key = lowT, side = 2;
                        else if (k < cuts.size() && key >= tk) key = tk, side = 0;
                        frags.push_back({key, std::min(a, 1.0), col * std::min(a, 1.0), side});
                    }
                    continue;
                }
                if (cut) {
                    // The depth cut (issue 15): the share of the kernel's line
                    // integral between the near plane (t = 0 on this ray) and
                    // the host surface or far plane (tLimit), exactly
                    // (Footprint::exactFractionBefore); s in kernel units from
                    // the splat plane along the ray, l the along-ray scale.
                    const double l = double(splatRayScale(s, float(R)));
                    if (!(l > 0.0)) continue;
                    const double rr = R * std::sqrt(u * u + v * v);
                    const double share = fp.exactFractionBefore(rr, (ray.tLimit - t) / l) - fp.exactFractionBefore(rr, -t / l);
                    if (!(share > 0.0)) continue;
                    detail *= share;
                }
                // alpha = 1 - 2^(-density * detail), accurate for tiny products.
                const double alpha = std::min(-std::expm1(-kLn2 * double(s.density) * detail), 1.0);
                if (!(alpha > 0.0)) continue;
                frags.push_back({t, alpha, col * alpha});
            }
            // The surfaces' layers at their crossings.
            for (std::size_t k = 0; k < cuts.size(); ++k)
                frags.push_back({cuts[k], std::clamp(cutColour[k].a, 0.0, 1.0), glm::dvec3(cutColour[k]), 1});
            // Per-pixel exact order: farthest first (at equal depth, the far side of a surface first).
            std::stable_sort(frags.begin(), frags.end(),
                             [](const Fragment& a, const Fragment& b) { return a.t != b.t ? a.t > b.t : a.side > b.side; });
            glm::dvec4 acc = reference::background(desc.host, x, y);
            if (!fog) {
                for (const Fragment& f : frags) acc = glm::dvec4(f.color, f.alpha) + (1.0 - f.alpha) * acc;
            } else {
                // Transmittance from the eye to each fragment, nearest first.
                std::vector<double> trans(frags.size(), 1.0);
                double tau = 0.0, err = 0.0;
                glm::dvec3 from = eye;
                auto tauTo = [&](const glm::dvec3& p) {
                    const glm::dvec3 a = throughEye ? from : eye;
                    const FogQuadrature q = integrateFogNumerically(*fog, a, p, desc.fogTimeSec, desc.fogTolerance);
                    if (!q.converged) ++fogBad;
                    const double total = throughEye ? tau + q.value : q.value;
                    err = throughEye ? err + q.errorEstimate : std::max(err, q.errorEstimate);
                    if (throughEye) tau = total, from = p;
                    return total;
                };
                auto transmittanceTo = [&](const glm::dvec3& p) {
                    // Beyond the cut-off f = 0 by definition: no integral (the points come
                    // nearest first, so every later one is beyond it too).
                    if (fogFar > 0.0 && glm::length(p - eye) > fogFar) return 0.0;
                    // No finite point (the sky under an infinite far plane): infinitely far,
                    // fully fogged, as Fog::transmittance and the GL pass take it (exact for a fog
                    // whose density has a positive floor; a fog of point terms alone would keep
                    // some transmittance at infinity, which neither models).
                    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return 0.0;
                    const double tp = tauTo(p);
                    if (std::isfinite(tp)) fogTauMax = std::max(fogTauMax, tp);
                    return std::exp(-tp);
                };
                for (size_t k = frags.size(); k-- > 0;) trans[k] = transmittanceTo(ray.origin + frags[k].t * ray.dir);
                if (desc.fogHost) {
                    const double d = reference::hostDepth(desc.host, x, y);
                    double fb = 0.0; // NaN or outside [0, 1]: fully fogged
                    // The far plane's depth (1, or 0 reversed): its point (none without a far plane: fully fogged).
                    if (!desc.host.depth || d == camera.depth.farWindow()) fb = transmittanceTo(ray.origin + ray.tFar * ray.dir);
                    else if (d >= 0.0 && d <= 1.0) fb = transmittanceTo(ray.origin + ray.tLimit * ray.dir);
                    acc = glm::dvec4(fogColour * (1.0 - fb), 1.0 - fb) + fb * acc;
                }
                for (size_t k = 0; k < frags.size(); ++k) {
                    const Fragment& f = frags[k];
                    const double fk = trans[k];
                    const glm::dvec3 c = fk * f.color + (1.0 - fk) * f.alpha * fogColour;
                    acc = glm::dvec4(c, f.alpha) + (1.0 - f.alpha) * acc;
                }
                fogErrMax = std::max(fogErrMax, err);
            }
            for (int ch = 0; ch < 4; ++ch) out.at(x, y, ch) = float(acc[ch]);
            fragCount += frags.size();
            maxOverlap = std::max<std::uint64_t>(maxOverlap, frags.size());
        }
        std::lock_guard<std::mutex> lock(statsMutex);
        stats.fragments += fragCount;
        stats.maxOverlap = std::max(stats.maxOverlap, maxOverlap);
        stats.fogMaxOpticalDepth = std::max(stats.fogMaxOpticalDepth, fogTauMax);
        stats.fogMaxErrorEstimate = std::max(stats.fogMaxErrorEstimate, fogErrMax);
        stats.fogUnconverged += fogBad;
    });
    if (statsOut) *statsOut = stats;
    return out;
}

} // namespace splatfx
