// splatfx inside OGRE 1.12 (sample 21, samples/21-ogre-campfire): the fire is
// drawn in OGRE's frame into OGRE's render target, occluded exactly by
// OGRE's depth, with OGRE's camera, and OGRE renders the same pixels after
// splatfx as before it (its GL state cache was not left stale).
// Runs under xvfb-run (tests/ogre/CMakeLists.txt): OGRE's GL3Plus needs GLX.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gl_fixture.hpp"
#include "ogre_campfire.hpp"
#include "splatfx/emitted_light.hpp"
#include "splatfx/image_io.hpp"

namespace {

constexpr int kW = 320, kH = 180;
constexpr double kTime = 1.0;

struct Shot {
    std::vector<std::uint8_t> rgba; // 8-bit, as stored in OGRE's PF_BYTE_RGBA target
    std::vector<float> depth;       // window depth, same rows
};

// One OGRE application per suite (OGRE's Root is a singleton: suites run one
// after the other, each creating and destroying its own).
template <int Scale>
class OgreApp : public ::testing::Test {
public: // the shared checks below are free functions
    static void SetUpTestSuite() {
        auto a = ogrefx::OgreCampfire::create({.width = kW, .height = kH, .resolutionScale = Scale});
        if (a) sApp = std::move(*a);
        else sError = a.error();
    }
    static void TearDownTestSuite() { sApp.reset(); }
    void SetUp() override { ASSERT_TRUE(sApp) << sError; }

    static Shot shot(const ogrefx::FrameOptions& o) {
        Shot s;
        const splatfx::Status st = sApp->render(o);
        EXPECT_TRUE(st) << st.error();
        auto c = sApp->readColour();
        EXPECT_TRUE(c) << c.error();
        auto d = sApp->readDepth();
        EXPECT_TRUE(d) << d.error();
        if (!c || !d) return s;
        EXPECT_EQ(c->width, kW);
        EXPECT_EQ(c->height, kH);
        for (float v : c->pixels) s.rgba.push_back(std::uint8_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)));
        s.depth = std::move(*d);
        return s;
    }
    static bool samePixel(const Shot& a, const Shot& b, std::size_t p) {
        return std::equal(a.rgba.begin() + p * 4, a.rgba.begin() + p * 4 + 4, b.rgba.begin() + p * 4);
    }
    static int maxChannelDiff(const Shot& a, const Shot& b, std::size_t p) {
        int m = 0;
        for (int c = 0; c < 3; ++c) m = std::max(m, std::abs(int(a.rgba[p * 4 + c]) - int(b.rgba[p * 4 + c])));
        return m;
    }
    // Array row r holds GL row r when OGRE flips the target (its render
    // textures), else GL row h-1-r (ogre_campfire.hpp, readDepth()).
    static int glRow(int r) { return sApp->hook().flipped ? r : kH - 1 - r; }

    static inline std::unique_ptr<ogrefx::OgreCampfire> sApp;
    static inline std::string sError;
};
using OgreCampfireTest = OgreApp<1>;
using OgreCampfireHalfResTest = OgreApp<2>; // splats at 1/2 per axis: the depth copy is sampled

// The view distance (along -z of view space) of window depth d, with the
// camera's [-1, 1] projection: z_ndc = (P22 z + P32) / -z.
double forwardOf(const glm::dmat4& proj, double d) {
    if (d >= 1.0) return std::numeric_limits<double>::infinity(); // cleared: nothing drawn there
    return proj[3][2] / ((2.0 * d - 1.0) + proj[2][2]);
}

TEST_F(OgreCampfireTest, TheHookDrawsOnceIntoOgresRenderTargetWithItsDepth) {
    const Shot s = shot({.timeSec = kTime});
    const ogrefx::HookInfo& h = sApp->hook();
    EXPECT_EQ(h.calls, 1);
    EXPECT_NE(h.framebuffer, 0u) << "a render texture is an FBO, never the default framebuffer";
    if (h.framebufferFromOgre) { EXPECT_EQ(h.framebufferFromOgre, h.framebuffer) << "the bound FBO is the target's own"; }
    EXPECT_EQ(h.viewport[2], kW);
    EXPECT_EQ(h.viewport[3], kH);
    EXPECT_GT(h.splats, 100u);
    EXPECT_TRUE(h.depthCopied || h.depthObjectType != 0);
    std::printf("OGRE context: %s; FBO %u, depth object 0x%x format 0x%x copied %d, flipped %d\n", h.glRenderer.c_str(), h.framebuffer,
                h.depthObjectType, h.depthInternalFormat, int(h.depthCopied), int(h.flipped));
}

// The camera splatfx drew with is OGRE's: for every pixel whose ray meets the
// ground in front of the log (nothing else lies between the eye and there),
// OGRE's depth equals the depth of that ground point through the converted
// camera. A wrong transpose, a missing flip or another depth range would miss
// by orders of magnitude more than the tolerance.
TEST_F(OgreCampfireTest, OgresDepthMatchesTheConvertedCameraOnTheGround) {
    const Shot s = shot({.timeSec = kTime});
    ASSERT_EQ(s.depth.size(), std::size_t(kW) * kH);
    const splatfx::Camera cam = sApp->camera();
    const glm::dmat4 viewProj = glm::dmat4(cam.proj) * glm::dmat4(cam.view);
    const glm::dmat4 inv = glm::inverse(viewProj);
    int checked = 0;
    double worst = 0.0;
    for (int r = 0; r < kH; ++r)
        for (int x = 0; x < kW; ++x) {
            const int y = glRow(r);
            const glm::dvec2 ndc(2.0 * (x + 0.5) / kW - 1.0, 2.0 * (y + 0.5) / kH - 1.0);
            glm::dvec4 a = inv * glm::dvec4(ndc, -1.0, 1.0), b = inv * glm::dvec4(ndc, 1.0, 1.0);
            const glm::dvec3 p0 = glm::dvec3(a) / a.w, p1 = glm::dvec3(b) / b.w;
            if (p1.y >= p0.y) continue; // looks up: no ground
            const double t = p0.y / (p0.y - p1.y);
            if (t <= 0.0 || t >= 1.0) continue;
            const glm::dvec3 hit = p0 + t * (p1 - p0);
            // In front of the log's front face (z = 3.0), inside the 60 x 60 plane.
            if (hit.z < 3.2 || std::abs(hit.x) > 29.0 || hit.z > 29.0) continue;
            const glm::dvec4 c = viewProj * glm::dvec4(hit, 1.0);
            const double expected = 0.5 * (c.z / c.w) + 0.5;
            worst = std::max(worst, std::abs(double(s.depth[std::size_t(r) * kW + x]) - expected));
            ++checked;
        }
    ASSERT_GT(checked, kW * 10) << "the ground in front of the log should fill the bottom rows";
    // A 24-bit depth buffer stores steps of 2^-24 (6e-8); the rasterizer
    // interpolates z_ndc in float (2^-23 relative, 1.2e-7 at |z| ~ 1) and OGRE
    // builds its matrices in float. 1e-6 is ~5x those together; a camera off by
    // one centimetre at 10 m distance already moves depth by ~1e-5 here.
    EXPECT_LT(worst, 1.0e-6) << "over " << checked << " ground pixels";
    std::printf("ground pixels %d, worst depth error %.3g\n", checked, worst);
}

// The fire lights OGRE's ground (issue 27, item 3): OGRE's material includes
// shadowGlsl() and adds albedo x splatfx_emittedIrradiance / pi, its uniforms
// set as OGRE parameters. Frames without the splats (fire off, so nothing
// covers the ground), with and without the fire's light: every ground pixel in
// front of the log differs by what the CPU's emittedIrradiance gives the
// frame's lights at that pixel's ground point. A wrong array layout in OGRE's
// parameters (or size 0, as OGRE reads named sizes) would miss by far more.
TEST_F(OgreCampfireTest, TheFireLightsOgresGroundAsTheCpuPredicts) {
    const Shot dark = shot({.timeSec = kTime, .fire = false, .log = true, .fireLight = false});
    const Shot lit = shot({.timeSec = kTime, .fire = false, .log = true, .fireLight = true});
    ASSERT_FALSE(dark.rgba.empty() || lit.rgba.empty());
    const std::vector<splatfx::EmittedLight>& lights = sApp->frame().emittedLights();
    ASSERT_EQ(lights.size(), 2u);
    const glm::dvec3 albedo(0.45, 0.42, 0.36); // the ground's material (ogre_campfire.cpp)
    const splatfx::Camera cam = sApp->camera();
    const glm::dmat4 inv = glm::inverse(glm::dmat4(cam.proj) * glm::dmat4(cam.view));
    int checked = 0;
    double worst = 0.0, largest = 0.0;
    for (int r = 0; r < kH; ++r)
        for (int x = 0; x < kW; ++x) {
            const int y = glRow(r);
            const glm::dvec2 ndc(2.0 * (x + 0.5) / kW - 1.0, 2.0 * (y + 0.5) / kH - 1.0);
            glm::dvec4 a = inv * glm::dvec4(ndc, -1.0, 1.0), b = inv * glm::dvec4(ndc, 1.0, 1.0);
            const glm::dvec3 p0 = glm::dvec3(a) / a.w, p1 = glm::dvec3(b) / b.w;
            if (p1.y >= p0.y) continue;
            const double t = p0.y / (p0.y - p1.y);
            if (t <= 0.0 || t >= 1.0) continue;
            const glm::dvec3 hit = p0 + t * (p1 - p0);
            if (hit.z < 3.2 || std::abs(hit.x) > 29.0 || hit.z > 29.0) continue; // in front of the log, on the plane
            // The shader's checker: 1 or 0.7 by floor(x) + floor(z); pixels within 1 mm of a
            // square's edge are left out (the interpolated position may fall either side).
            const double fx = hit.x - std::floor(hit.x), fz = hit.z - std::floor(hit.z);
            if (std::min({fx, 1.0 - fx, fz, 1.0 - fz}) < 1e-3) continue;
            const double checker = (long(std::floor(hit.x)) + long(std::floor(hit.z))) % 2 == 0 ? 1.0 : 0.7;
            const glm::vec3 e = splatfx::emittedIrradiance(lights, glm::vec3(hit), glm::vec3(0.0f, 1.0f, 0.0f));
            const std::size_t p = std::size_t(r) * kW + x;
            for (int c = 0; c < 3; ++c) {
                const double expected = albedo[c] * checker * double(e[c]) / 3.14159265358979;
                const double before = dark.rgba[p * 4 + c] / 255.0;
                if (before + expected > 254.0 / 255.0) continue; // clamped by the 8-bit target
                // Each frame is rounded to 8 bits (half a step each way): the difference is
                // within one step, plus the shader's float arithmetic (~1e-6 below 1).
                const double diff = (int(lit.rgba[p * 4 + c]) - int(dark.rgba[p * 4 + c])) / 255.0;
                worst = std::max(worst, std::abs(diff - expected));
                largest = std::max(largest, expected);
                ++checked;
            }
        }
    ASSERT_GT(checked, kW * 10) << "the ground in front of the log should fill the bottom rows";
    EXPECT_LE(worst, 1.0 / 255.0 + 1e-5) << "over " << checked << " ground channel values";
    EXPECT_GT(largest, 10.0 / 255.0) << "the fire's light should be well above one 8-bit step";
    std::printf("fire light on OGRE's ground: %d channel values, largest %.4f, worst error %.5f\n", checked, largest, worst);
}

// shadow.glsl's splatfx_shadowIn in double, on the frame's own table (FrameShadow):
// a point outside the table moves along its ray to the light to where the ray
// enters the table (one that misses it is unshadowed); trilinear between nodes,
// node i of n at table coordinate i / (n - 1).
double cpuShadow(const splatfx::FrameShadow& s, const glm::dvec3& world) {
    const glm::dvec3 p = glm::dvec3(glm::dmat4(s.worldToTable) * glm::dvec4(world, 1.0));
    const glm::dvec4 light(s.lightInTable);
    const bool isPoint = light.w > 0.5;
    const glm::dvec3 d = isPoint ? glm::dvec3(light) - p : -glm::dvec3(light);
    double tNear = 0.0, tFar = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) {
        const double inv = (d[i] >= 0.0 ? 1.0 : -1.0) / std::max(std::abs(d[i]), 1e-30);
        const double ta = -p[i] * inv, tb = (1.0 - p[i]) * inv;
        tNear = std::max(tNear, std::min(ta, tb));
        tFar = std::min(tFar, std::max(ta, tb));
    }
    if (isPoint) tFar = std::min(tFar, 1.0);
    if (tNear > tFar) return 1.0;
    const glm::dvec3 q = glm::clamp(p + d * tNear, glm::dvec3(0.0), glm::dvec3(1.0));
    const glm::ivec3 n = s.dims;
    const glm::dvec3 g = q * glm::dvec3(n - 1);
    const glm::ivec3 i0 = glm::min(glm::ivec3(glm::floor(g)), glm::max(n - 2, glm::ivec3(0)));
    const glm::dvec3 f = g - glm::dvec3(i0);
    auto at = [&](int x, int y, int z) {
        x = std::min(x, n.x - 1), y = std::min(y, n.y - 1), z = std::min(z, n.z - 1);
        return double(s.depth[(std::size_t(z) * n.y + y) * n.x + x]);
    };
    double depth = 0.0;
    for (int c = 0; c < 8; ++c) {
        const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
        depth += (dx ? f.x : 1.0 - f.x) * (dy ? f.y : 1.0 - f.y) * (dz ? f.z : 1.0 - f.z) * at(i0.x + dx, i0.y + dy, i0.z + dz);
    }
    return std::exp2(-depth);
}

// The largest optical-depth difference between neighbouring nodes (log2 units).
double maxNeighbourStep(const splatfx::FrameShadow& s) {
    const glm::ivec3 n = s.dims;
    double step = 0.0;
    auto at = [&](int x, int y, int z) { return double(s.depth[(std::size_t(z) * n.y + y) * n.x + x]); };
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                if (x + 1 < n.x) step = std::max(step, std::abs(at(x + 1, y, z) - at(x, y, z)));
                if (y + 1 < n.y) step = std::max(step, std::abs(at(x, y + 1, z) - at(x, y, z)));
                if (z + 1 < n.z) step = std::max(step, std::abs(at(x, y, z + 1) - at(x, y, z)));
            }
    return step;
}

// The smoke's shadow on OGRE's ground (issue 27, items 1 and 3: shadowGlsl() in
// a host's own material): OGRE's material multiplies the sun's Lambert term by
// splatfx_shadowTo(0, ...), its table the frame's scene-shadow table for the
// sun, handed to OGRE as a 3D texture on the pass's texture unit and OGRE
// parameters. Frames without the splats and the fire's light, with and without
// the shadow: every ground pixel differs by albedo x checker x sun x cos x (T - 1),
// T the CPU's transmittance from the same table. A transposed matrix, a wrong
// texture unit, format or filtering would miss by far more than the bound.
TEST_F(OgreCampfireTest, TheSmokeShadowsOgresGroundAsTheCpuTableSays) {
    const Shot sunlit = shot({.timeSec = kTime, .fire = false, .log = true, .fireLight = false, .smokeShadow = false});
    const Shot shaded = shot({.timeSec = kTime, .fire = false, .log = true, .fireLight = false, .smokeShadow = true});
    ASSERT_FALSE(sunlit.rgba.empty() || shaded.rgba.empty());
    const splatfx::FrameShadow& table = sApp->frame().shadows()[0];
    ASSERT_TRUE(table.valid) << "the smoke should cast a scene shadow";
    ASSERT_EQ(table.light, 0);
    const glm::dvec3 albedo(0.45, 0.42, 0.36); // the ground's material (ogre_campfire.cpp)
    const glm::dvec3 sunColour(ogrefx::kSunColour[0], ogrefx::kSunColour[1], ogrefx::kSunColour[2]);
    const double cosine = glm::normalize(glm::dvec3(ogrefx::kSunTowards[0], ogrefx::kSunTowards[1], ogrefx::kSunTowards[2])).y;
    // Bound on T (tests/lighting/shadow_gl_test.cpp's): GL may filter with 8-bit weights, an error of
    // 3/256 of the largest node step in depth, ln 2 times that in transmittance (T <= 1); the shader's
    // interpolated world position (float, within 2^-20 x 20 m of the pixel centre's ground point) moves
    // the lookup by at most 2e-5 m, times the steepest slope ln 2 x step / node spacing; float rounding.
    const double step = maxNeighbourStep(table);
    double spacing = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) {
        const glm::dmat4 m(table.worldToTable);
        const double perWorld = glm::length(glm::dvec3(m[0][i], m[1][i], m[2][i]));
        spacing = std::min(spacing, 1.0 / (perWorld * std::max(table.dims[i] - 1, 1)));
    }
    const double tolT = std::log(2.0) * (3.0 / 256.0 * step + 2e-5 * step / spacing) + 1e-5;
    const splatfx::Camera cam = sApp->camera();
    const glm::dmat4 viewProj = glm::dmat4(cam.proj) * glm::dmat4(cam.view);
    const glm::dmat4 inv = glm::inverse(viewProj);
    int checked = 0, underSmoke = 0;
    double worst = 0.0, darkest = 1.0;
    for (int r = 0; r < kH; ++r)
        for (int x = 0; x < kW; ++x) {
            const int y = glRow(r);
            const glm::dvec2 ndc(2.0 * (x + 0.5) / kW - 1.0, 2.0 * (y + 0.5) / kH - 1.0);
            glm::dvec4 a = inv * glm::dvec4(ndc, -1.0, 1.0), b = inv * glm::dvec4(ndc, 1.0, 1.0);
            const glm::dvec3 p0 = glm::dvec3(a) / a.w, p1 = glm::dvec3(b) / b.w;
            if (p1.y >= p0.y) continue;
            const double t = p0.y / (p0.y - p1.y);
            if (t <= 0.0 || t >= 1.0) continue;
            const glm::dvec3 hit = p0 + t * (p1 - p0);
            if (std::abs(hit.x) > 29.0 || std::abs(hit.z) > 29.0) continue;
            // OGRE drew the ground here (not the log or the wall in front of it): its depth is the
            // ground point's (within 1e-6, OgresDepthMatchesTheConvertedCameraOnTheGround).
            const std::size_t p = std::size_t(r) * kW + x;
            const glm::dvec4 c = viewProj * glm::dvec4(hit, 1.0);
            if (std::abs(double(sunlit.depth[p]) - (0.5 * (c.z / c.w) + 0.5)) > 1e-6) continue;
            const double fx = hit.x - std::floor(hit.x), fz = hit.z - std::floor(hit.z);
            if (std::min({fx, 1.0 - fx, fz, 1.0 - fz}) < 1e-3) continue;
            const double checker = (long(std::floor(hit.x)) + long(std::floor(hit.z))) % 2 == 0 ? 1.0 : 0.7;
            const double T = cpuShadow(table, hit);
            darkest = std::min(darkest, T);
            for (int ch = 0; ch < 3; ++ch) {
                const double sun = albedo[ch] * checker * sunColour[ch] * cosine;
                if (sunlit.rgba[p * 4 + ch] >= 255) continue; // clamped by the 8-bit target
                const double expected = sun * (T - 1.0);
                // Each frame rounded to 8 bits (half a step each way): within one step of the exact difference.
                const double diff = (int(shaded.rgba[p * 4 + ch]) - int(sunlit.rgba[p * 4 + ch])) / 255.0;
                const double bound = 1.0 / 255.0 + sun * tolT;
                worst = std::max(worst, std::abs(diff - expected) / bound);
                EXPECT_LE(std::abs(diff - expected), bound) << "pixel " << x << "," << r << " channel " << ch << ", T " << T << ": GL " << diff << ", CPU " << expected;
                underSmoke += ch == 0 && expected < -3.0 / 255.0;
                ++checked;
            }
        }
    ASSERT_GT(checked, kW * 10) << "the ground should fill the lower rows";
    EXPECT_LT(darkest, 0.8) << "the smoke's shadow should reach the visible ground";
    EXPECT_GT(underSmoke, 100) << "ground pixels darker by more than three 8-bit steps";
    std::printf("smoke shadow on OGRE's ground: %d channel values, %d pixels darker by > 3/255, darkest T %.3f, "
                "worst error / bound %.3f (T bound %.5f, node step %.3f)\n",
                checked, underSmoke, darkest, worst, tolT, step);
}

// A: log, no fire; B: log and fire; C: no log, no fire; D: fire, no log.
// Where OGRE's surface is nearer than every splat fragment can be, the fire
// leaves OGRE's pixel untouched (bit for bit); where the log is absent, the
// frame is the same with or without it; the fire shows, warm, over the wall
// and the ground behind it. `edge`: pixels within this many pixels of a
// pixel of the other kind are not judged (0 at full resolution; at reduced
// resolution the depth-aware upsampling reads the 2x2 reduced texels around
// a pixel, which reach 2 * scale full-resolution pixels from it).
template <int Scale>
void expectOccludedExactly(OgreApp<Scale>& t, int edge) {
    using T = OgreApp<Scale>;
    const Shot a = T::shot({.timeSec = kTime, .fire = false, .log = true});
    const Shot b = T::shot({.timeSec = kTime, .fire = true, .log = true});
    const splatfx::Camera cam = T::sApp->camera();
    // The fire's splats span [near, far] along the view direction: a splat
    // is a disc through its centre, inside the sphere of its longer half-axis.
    double nearest = std::numeric_limits<double>::infinity(), farthest = 0.0;
    for (const splatfx::Splat& sp : T::sApp->frame().splats()) {
        const double f = -(glm::dmat4(cam.view) * glm::dvec4(glm::dvec3(sp.center), 1.0)).z;
        const double radius = std::max(glm::length(sp.axisU), glm::length(sp.axisV));
        nearest = std::min(nearest, f - radius);
        farthest = std::max(farthest, f + radius);
    }
    const Shot c = T::shot({.timeSec = kTime, .fire = false, .log = false});
    const Shot d = T::shot({.timeSec = kTime, .fire = true, .log = false});
    ASSERT_FALSE(a.rgba.empty() || b.rgba.empty() || c.rgba.empty() || d.rgba.empty());
    ASSERT_LT(nearest, farthest);
    (void)t;

    const glm::dmat4 proj(cam.proj);
    // 1 mm: far above the depth buffer's resolution at 10-15 m (~1e-5 m).
    const double margin = 1.0e-3;
    const std::size_t n = std::size_t(kW) * kH;
    std::vector<char> inFront(n), logHere(n);
    for (std::size_t p = 0; p < n; ++p) {
        inFront[p] = forwardOf(proj, a.depth[p]) < nearest - margin;
        logHere[p] = a.depth[p] != c.depth[p];
    }
    // Is every pixel within `edge` of (x, y) of the given kind?
    auto all = [&](const std::vector<char>& m, int x, int y, bool v) {
        for (int j = std::max(0, y - edge); j <= std::min(kH - 1, y + edge); ++j)
            for (int i = std::max(0, x - edge); i <= std::min(kW - 1, x + edge); ++i)
                if (bool(m[std::size_t(j) * kW + i]) != v) return false;
        return true;
    };
    int occludedFire = 0, fireShown = 0, fireBehind = 0, logPixels = 0, judgedOccluded = 0, judgedFree = 0;
    int changedWhereOccluded = 0, changedWithoutLog = 0;
    double warmth = 0.0, brightening = 0.0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const std::size_t p = std::size_t(y) * kW + x;
            const bool behind = forwardOf(proj, a.depth[p]) > farthest + margin;
            // The fire is visible here when nothing hides it (no log: D vs C).
            // 3/255: well above 8-bit rounding (1/255), below the faintest
            // visible fire edge the footprint leaves.
            const bool fire = T::maxChannelDiff(d, c, p) >= 3;
            logPixels += logHere[p];
            if (inFront[p] && all(inFront, x, y, true)) {
                ++judgedOccluded;
                if (!T::samePixel(a, b, p)) ++changedWhereOccluded;
            }
            if (!logHere[p] && all(logHere, x, y, false)) {
                ++judgedFree;
                if (!T::samePixel(b, d, p)) ++changedWithoutLog;
            }
            if (fire) {
                ++fireShown;
                if (inFront[p] && logHere[p]) ++occludedFire;
                if (behind) ++fireBehind;
                warmth += (int(d.rgba[p * 4]) - int(c.rgba[p * 4])) - (int(d.rgba[p * 4 + 2]) - int(c.rgba[p * 4 + 2]));
                for (int ch = 0; ch < 3; ++ch) brightening += int(d.rgba[p * 4 + ch]) - int(c.rgba[p * 4 + ch]);
            }
        }
    std::printf("scale %d: fire shown %d px, hidden by the log %d px, over the wall/background %d px; log %d px; "
                "judged %d occluded, %d free; fire near %.3f far %.3f m\n",
                Scale, fireShown, occludedFire, fireBehind, logPixels, judgedOccluded, judgedFree, nearest, farthest);
    // Not vacuous: the fire covers a good part of the 320x180 frame and the
    // log hides a visible part of it (the scene puts it across the fire's
    // lower left: ~1/6 of the fire's area).
    EXPECT_GT(fireShown, kW * kH / 40);
    EXPECT_GT(occludedFire, fireShown / 20);
    EXPECT_GT(fireBehind, fireShown / 2);
    EXPECT_GT(judgedOccluded, logPixels / 2);
    // Exact: a fragment failing the depth test writes nothing.
    EXPECT_EQ(changedWhereOccluded, 0) << "the fire leaked through OGRE's nearer geometry";
    EXPECT_EQ(changedWithoutLog, 0) << "the log changed pixels it does not cover";
    // The fire adds light, more red than blue (its colour table).
    EXPECT_GT(brightening, 0.0);
    EXPECT_GT(warmth, 0.0);

    // The screenshot: frame B (fire and log), for a person looking at a failure.
    splatfx::Image image{.width = kW, .height = kH, .channels = 4, .pixels = {}};
    for (std::uint8_t v : b.rgba) image.pixels.push_back(float(v) / 255.0f);
    const splatfx::Status st = splatfx::writeImage(splatfx::test::outputDir() + "/ogre_campfire_scale" + std::to_string(Scale) + ".png", image);
    EXPECT_TRUE(st) << st.error();
}

TEST_F(OgreCampfireTest, OgresGeometryOccludesTheFireExactly) { expectOccludedExactly(*this, 0); }
TEST_F(OgreCampfireHalfResTest, OgresGeometryOccludesTheFireThroughTheDepthCopy) { expectOccludedExactly(*this, 2 * 2); }

// OGRE's GL3Plus caches GL state (bindings, blend, depth, masks, its active
// program); had splatfx left any of it changed, OGRE's next frames would draw
// with stale assumptions. Same inputs, same pixels: before and after splatfx
// (also when the next frame draws different geometry: without splatfx's
// guard OGRE's depth clear is skipped, see NegativeControl below), and
// splatfx's second frame equal to its first.
template <int Scale>
void expectOgreUnchanged() {
    using T = OgreApp<Scale>;
    const Shot before = T::shot({.timeSec = kTime, .fire = false, .log = false});
    const Shot fire1 = T::shot({.timeSec = kTime, .fire = true, .log = true});
    const Shot fire2 = T::shot({.timeSec = kTime, .fire = true, .log = true});
    const Shot after = T::shot({.timeSec = kTime, .fire = false, .log = false});
    ASSERT_FALSE(before.rgba.empty() || after.rgba.empty() || fire1.rgba.empty() || fire2.rgba.empty());
    EXPECT_TRUE(before.rgba == after.rgba) << "OGRE drew differently after splatfx";
    EXPECT_TRUE(before.depth == after.depth) << "OGRE's depth differs after splatfx";
    EXPECT_TRUE(fire1.rgba == fire2.rgba) << "splatfx's second frame in OGRE differs from its first";
    EXPECT_FALSE(before.rgba == fire1.rgba);
}
TEST_F(OgreCampfireTest, OgreRendersTheSamePixelsAfterSplatfx) { expectOgreUnchanged<1>(); }
TEST_F(OgreCampfireHalfResTest, OgreRendersTheSamePixelsAfterSplatfx) { expectOgreUnchanged<2>(); }

// The control: with splatfx's state guard off (RendererDesc::restoreState =
// false) splatfx leaves glDepthMask(GL_FALSE) behind; OGRE's state cache
// still says GL_TRUE, so its next clear does not re-enable depth writes and
// the depth buffer keeps the log, which then cuts a hole of background
// colour into the ground and wall when the log is gone. This is why the
// sample keeps the guard on, and shows the test above can fail.
TEST(OgreCampfireNegativeControl, WithoutTheStateGuardOgresDepthClearIsSkipped) {
    auto app = ogrefx::OgreCampfire::create({.width = kW, .height = kH, .restoreState = false});
    ASSERT_TRUE(app) << app.error();
    auto colour = [&](bool fire, bool log) {
        const splatfx::Status st = (*app)->render({.timeSec = kTime, .fire = fire, .log = log});
        EXPECT_TRUE(st) << st.error();
        auto c = (*app)->readColour();
        return c ? c->pixels : std::vector<float>{};
    };
    const std::vector<float> before = colour(false, false);
    (void)colour(true, true);
    const std::vector<float> after = colour(false, false);
    ASSERT_EQ(before.size(), after.size());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < before.size(); i += 4)
        differing += before[i] != after[i] || before[i + 1] != after[i + 1] || before[i + 2] != after[i + 2];
    std::printf("without the guard: %zu pixels differ after one splatfx frame\n", differing);
    EXPECT_GT(differing, std::size_t(kW * kH / 100)) << "the log's stale depth should cut a visible hole";
}

} // namespace
