// Shared by the reference renderers (private): GL's pixel-to-ray mapping,
// host-image checks, colour-row lookup and a row-parallel loop.
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/camera.hpp"
#include "splatfx/image.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/result.hpp"

namespace splatfx::reference {

// The segment of the line through a pixel centre between the near and far
// planes, in world space, in double, in the camera's depth convention
// (Camera::depth). Points along it all rasterize to that pixel; t measures
// world distance from the near-plane point.
struct PixelRay {
    glm::dvec3 origin{0.0}; // on the near plane
    glm::dvec3 dir{0.0};    // unit, towards the far plane
    double tFar = 0.0;      // distance to the far plane (+inf without one)
    double tLimit = 0.0;    // min(tFar, host depth): fragments beyond it are dropped
};

class RayMapper {
public:
    explicit RayMapper(const Camera& camera)
        : mInv(glm::inverse(glm::dmat4(camera.proj) * glm::dmat4(camera.view))), mW(camera.viewport.x), mH(camera.viewport.y),
          mDepth(camera.depth), mUnproject(depthUnprojection(camera)), mForward(camera.forward()),
          mNearDepth(mUnproject.viewDepth(camera.depth.nearWindow())) {
        // Under an infinite far plane each ray's direction comes from a finite
        // point beyond the near plane (at twice its view depth).
        const glm::dmat4 P(camera.proj);
        mInfinite = camera.perspective() && P[2][2] / P[2][3] == mDepth.farNdc();
        mInnerNdc = mInfinite ? P[2][2] / P[2][3] - P[3][2] / (P[2][3] * 2.0 * mNearDepth) : mDepth.farNdc();
    }

    // (x, y): output pixel, top row first. hostDepth: window depth or > 1 for
    // none (any convention: the depth itself is read through depthUnprojection).
    PixelRay ray(int x, int y, double hostDepth) const {
        // GL: window x = x + 0.5; the output is flipped, so GL row = H - 1 - y.
        const double nx = (x + 0.5) / mW * 2.0 - 1.0;
        const double ny = (mH - 1 - y + 0.5) / mH * 2.0 - 1.0;
        const glm::dvec3 p0 = unproject(nx, ny, mDepth.nearNdc()), p1 = unproject(nx, ny, mInnerNdc);
        PixelRay r;
        r.origin = p0;
        const glm::dvec3 d = p1 - p0;
        const double len = glm::length(d);
        r.dir = len > 0.0 ? d / len : glm::dvec3(0.0, 0.0, -1.0);
        r.tFar = mInfinite ? std::numeric_limits<double>::infinity() : len;
        r.tLimit = r.tFar;
        if (hostDepth <= 1.0) {
            // View depth grows by dot(dir, forward) per unit of t from the near plane.
            const double t = (mUnproject.viewDepth(hostDepth) - mNearDepth) / glm::dot(r.dir, mForward);
            r.tLimit = std::min(r.tFar, t);
        }
        return r;
    }

private:
    glm::dvec3 unproject(double nx, double ny, double nz) const {
        const glm::dvec4 p = mInv * glm::dvec4(nx, ny, nz, 1.0);
        return glm::dvec3(p) / p.w;
    }
    glm::dmat4 mInv;
    int mW, mH;
    DepthConvention mDepth;
    DepthUnprojection mUnproject;
    glm::dvec3 mForward;
    double mNearDepth;
    bool mInfinite = false;
    double mInnerNdc = 1.0;
};

inline Status checkHost(const ReferenceHost& host, const Camera& camera, const char* who) {
    const int w = camera.viewport.x, h = camera.viewport.y;
    if (w <= 0 || h <= 0 || w > 16384 || h > 16384)
        return makeError(std::string(who) + ": camera.viewport " + std::to_string(w) + "x" + std::to_string(h) +
                         " must be between 1 and 16384 on each side");
    auto check = [&](const Image* img, int channels, const char* field) -> Status {
        if (!img) return {};
        if (img->width != w || img->height != h || img->channels < channels || img->pixels.size() != size_t(img->width) * img->height * img->channels)
            return makeError(std::string(who) + ": " + field + " is " + std::to_string(img->width) + "x" + std::to_string(img->height) + "x" +
                             std::to_string(img->channels) + "; expected " + std::to_string(w) + "x" + std::to_string(h) + " with at least " +
                             std::to_string(channels) + " channel(s)");
        return {};
    };
    if (Status s = check(host.backgroundImage, 4, "host.backgroundImage"); !s) return s;
    return check(host.depth, 1, "host.depth");
}

inline glm::dvec4 background(const ReferenceHost& host, int x, int y) {
    if (!host.backgroundImage) return glm::dvec4(host.background);
    const Image& b = *host.backgroundImage;
    return {b.at(x, y, 0), b.at(x, y, 1), b.at(x, y, 2), b.at(x, y, 3)};
}

inline double hostDepth(const ReferenceHost& host, int x, int y) { return host.depth ? double(host.depth->at(x, y, 0)) : 2.0; }

// The vertex shader's colour lookup: linear between entries, texel-centre exact, in double.
inline glm::dvec3 rowColor(const std::vector<glm::vec4>& row, double coord) {
    if (row.empty()) return glm::dvec3(1.0);
    const double f = std::clamp(std::isfinite(coord) ? coord : 0.0, 0.0, 1.0) * double(row.size() - 1);
    const size_t i = std::min(size_t(f), row.size() - 1);
    const size_t j = std::min(i + 1, row.size() - 1);
    const double t = f - double(i);
    return glm::dvec3(row[i]) * (1.0 - t) + glm::dvec3(row[j]) * t;
}

// Runs body(row) for every row in [0, rows) on `threads` workers.
inline void parallelRows(int rows, int threads, const std::function<void(int)>& body) {
    int n = threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
    n = std::clamp(n, 1, std::max(rows, 1));
    std::atomic<int> next{0};
    auto work = [&] {
        for (int r = next++; r < rows; r = next++) body(r);
    };
    std::vector<std::thread> pool;
    for (int i = 1; i < n; ++i) pool.emplace_back(work);
    work();
    for (auto& t : pool) t.join();
}

} // namespace splatfx::reference
