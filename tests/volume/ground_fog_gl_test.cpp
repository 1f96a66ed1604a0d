// Ground fog drawn by the projected-tetrahedra pass against the layer's
// continuous field (renderGroundFogExact), every pixel within a bound derived
// per pixel from the pre-integration table's resolution and GL's filtering.
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "splatfx/reference.hpp"
#include "volume_test_util.hpp"

using namespace splatfx;

namespace {

class GroundFogGL : public test::GLTest {};

} // namespace

// Full resolution, sorted, the affine scalar (the prisms hold the field
// exactly, GroundFogExact.FullResolutionAffineTetrahedraAreTheField): what is
// left between the GL frame and the field is the table and the GL arithmetic.
TEST_F(GroundFogGL, FullResolutionMatchesTheFieldWithinTheTablesBound) {
    constexpr glm::ivec2 kSize{40, 30};
    GroundFogDesc d;
    d.dims = {17, 13};
    d.originWorld = {-10.0f, 0.0f, -10.0f};
    d.spacingWorld = 1.25f;
    d.densityDepthWorld = 3.0f;
    for (int j = 0; j < 13; ++j)
        for (int i = 0; i < 17; ++i) {
            const float x = float(i) / 16.0f, z = float(j) / 16.0f;
            d.terrainHeight.push_back(2.0f * std::sin(6.0f * x) * std::cos(5.0f * z) + 0.5f * x);
            d.fogTop.push_back(0.8f);
        }
    const float kappa = 1.5f;
    auto fog = GroundFog::create(d);
    auto tf = makeGroundFogTransfer({0.9f, 0.92f, 0.95f}, kappa);
    ASSERT_TRUE(fog && tf);
    // The longest segment in a tetrahedron is below its prism's diagonal:
    // sqrt(2 * 1.25^2 + 2.8^2) < 3.4 (thickness <= 0.8 + 2.0): no lookup is split.
    const float maxLength = 4.0f;
    auto table = PreIntegrationTable::create(*tf, {.scalarResolution = 64, .lengthResolution = 128, .maxLengthWorld = maxLength});
    ASSERT_TRUE(table);
    const Camera cam = Camera::lookAt({-22.0f, 16.0f, -18.0f}, {0.0f, 0.0f, 0.0f}, {0, 1, 0}, glm::radians(55.0f), kSize, 0.1f, 200.0f);
    Frame frame;
    frame.begin(0.0, cam);
    FrameVolume& fv = frame.volumes().emplace_back();
    fv.table = &*table;
    ASSERT_TRUE(fog->update(cam, fv.lod));
    frame.end();
    auto fr = gl::FrameRenderer::create();
    auto fb = gl::Framebuffer::create({.width = kSize.x, .height = kSize.y, .color = gl::Precision::F32});
    ASSERT_TRUE(fr && fb);
    fr->render(frame, {.framebuffer = fb->handle(), .depthTexture = fb->depthTexture(), .drawOpaque = [] {
                           glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
                           glClearDepth(1.0);
                           glDepthMask(GL_TRUE);
                           glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                       }});
    const Image img = fb->read();
    GroundFogExactStats fs;
    auto field = renderGroundFogExact(d, *tf, cam, {}, &fs);
    ASSERT_TRUE(field);

    // Per pixel: every segment the ray has in a tetrahedron is one table
    // lookup of alpha = 1 - exp(-u), u = kappa l (sf + sb) / 2 (extinction
    // linear in the scalar; colour C alpha with C <= 1, so alpha bounds every
    // channel). Trilinear interpolation is off by at most (1/8) sum h_i^2
    // max |d2 alpha / dx_i^2| over the cell: (kappa l / 2)^2 along each
    // scalar, (kappa s)^2 along the length (s the larger scalar, l the
    // longer length of the cell). GL weights texels with as few as 8 bits of
    // sub-texel precision: 3 * 2^-9 times the cell's spread, <= the first
    // derivatives times the steps, kappa l / 2 * h_s twice and kappa s * h_l.
    // A segment off by e moves the composite by <= 2e. Float geometry (the
    // fragment's entry and exit, ~16 ulps of distances < 64) moves each
    // segment's optical depth by <= 2 kappa s * 16 * 2^-24 * 64.
    // Rasterization: GL snaps projected vertices to 2^-GL_SUBPIXEL_BITS of a
    // pixel, so a pixel centre that close to a tetrahedron's projected
    // outline may get or miss that tetrahedron's fragment: where rays through
    // points that close to the centre (8 around it) disagree on crossing a
    // tetrahedron, its whole segment, at most kappa s times the longest of
    // their chords, counts twice.
    GLint subpixelBits = 4; // the GL minimum
    glGetIntegerv(GL_SUBPIXEL_BITS, &subpixelBits);
    const double snap = std::ldexp(1.0, -std::max(subpixelBits, 1));
    const double hs = 1.0 / 63.0, hl = double(maxLength) / 127.0, k = double(kappa);
    const double tFloat = 16.0 * std::ldexp(1.0, -24) * 64.0;
    const glm::dmat4 inv = glm::inverse(glm::dmat4(cam.proj) * glm::dmat4(cam.view));
    auto ray = [&](double px, double py) { // window position, top row first
        const double nx = px / kSize.x * 2.0 - 1.0, ny = 1.0 - py / kSize.y * 2.0;
        const glm::dvec4 a = inv * glm::dvec4(nx, ny, -1.0, 1.0), b = inv * glm::dvec4(nx, ny, 1.0, 1.0);
        const glm::dvec3 o = glm::dvec3(a) / a.w;
        return std::make_pair(o, glm::normalize(glm::dvec3(b) / b.w - o));
    };
    // A sphere around each tetrahedron, to skip those no ray near the pixel can reach.
    std::vector<std::pair<glm::dvec3, double>> spheres;
    for (const Tetrahedron& t : fv.lod.tets) {
        const glm::dvec3 c = (glm::dvec3(t.position[0]) + glm::dvec3(t.position[1]) + glm::dvec3(t.position[2]) + glm::dvec3(t.position[3])) / 4.0;
        double r = 0.0;
        for (const glm::vec3& p : t.position) r = std::max(r, glm::length(glm::dvec3(p) - c));
        spheres.emplace_back(c, r);
    }
    int over = 0, covered = 0, snapped = 0;
    double worst = 0.0, worstRatio = 0.0;
    for (int y = 0; y < kSize.y; ++y)
        for (int x = 0; x < kSize.x; ++x) {
            const auto [o, dir] = ray(x + 0.5, y + 0.5);
            std::vector<std::pair<glm::dvec3, glm::dvec3>> near;
            for (int q = 0; q < 8; ++q) {
                const double ang = q * 3.14159265358979 / 4.0;
                near.push_back(ray(x + 0.5 + 1.5 * snap * std::cos(ang), y + 0.5 + 1.5 * snap * std::sin(ang)));
            }
            double bound = fs.maxErrorEstimate + 1e-5; // the field's quadrature; F32 blending
            for (std::size_t ti = 0; ti < fv.lod.tets.size(); ++ti) {
                const Tetrahedron& t = fv.lod.tets[ti];
                // The 8 rays are within 1.5 * 2^-4 pixel of the centre's: at
                // the far plane (200; a pixel spans 200 * 2 tan(27.5 deg) / 30
                // < 7 world units) under 0.7 world units apart: skip beyond 1.
                const glm::dvec3 rel = spheres[ti].first - o;
                if (glm::length(rel - glm::dot(rel, dir) * dir) > spheres[ti].second + 1.0) continue;
                const glm::dvec2 iv = voltest::rayInterval(t, o, dir);
                const bool hit = iv.y > std::max(iv.x, 0.0);
                bool disagree = false;
                double chord = hit ? iv.y - std::max(iv.x, 0.0) : 0.0, sMax = 0.0;
                for (const auto& [no, nd] : near) {
                    const glm::dvec2 ni = voltest::rayInterval(t, no, nd);
                    const bool nh = ni.y > std::max(ni.x, 0.0);
                    disagree |= nh != hit;
                    if (nh) chord = std::max(chord, ni.y - std::max(ni.x, 0.0));
                }
                for (float v : t.scalar) sMax = std::max(sMax, double(v));
                if (disagree) {
                    bound += 2.0 * k * sMax * chord;
                    ++snapped;
                }
                if (!hit) continue;
                const double t0 = std::max(iv.x, 0.0), t1 = iv.y;
                // The ray copied in: a lambda cannot capture a structured binding (before C++23).
                auto scalarAt = [&t, ro = o, rd = dir](double tt) {
                    const glm::dvec4 l = voltest::barycentric(t, ro + tt * rd);
                    return l.x * t.scalar[0] + l.y * t.scalar[1] + l.z * t.scalar[2] + l.w * t.scalar[3];
                };
                const double l = t1 - t0 + hl, s = std::max(scalarAt(t0), scalarAt(t1)) + hs;
                const double interp = (2.0 * hs * hs * (k * l / 2.0) * (k * l / 2.0) + hl * hl * (k * s) * (k * s)) / 8.0;
                const double weights = 3.0 * std::ldexp(1.0, -9) * (2.0 * hs * k * l / 2.0 + hl * k * s);
                bound += 2.0 * (interp + weights + 2.0 * k * s * tFloat);
            }
            double e = 0.0;
            for (int c = 0; c < 4; ++c) e = std::max(e, std::abs(double(img.at(x, y, c)) - double(field->at(x, y, c))));
            over += e > bound ? 1 : 0;
            worst = std::max(worst, e);
            worstRatio = std::max(worstRatio, e / bound);
            covered += field->at(x, y, 3) > 0.05f ? 1 : 0;
        }
    EXPECT_GT(covered, kSize.x * kSize.y / 20); // the fog lies in the valleys: about a tenth of the view
    EXPECT_EQ(over, 0) << "worst |GL - field| " << worst << ", worst ratio to its bound " << worstRatio << " (" << snapped
                       << " pixel-tetrahedron pairs within snapping of an outline)";
    RecordProperty("max_gl_vs_field", std::to_string(worst));
    RecordProperty("worst_ratio_to_bound", std::to_string(worstRatio));
}
