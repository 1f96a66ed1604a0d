// The generated fog GLSL, compiled into a compute shader on the headless
// context, evaluated on segments and compared with the double CPU integral.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "splatfx/fog.hpp"

namespace splatfx {
namespace {

constexpr double kEps = 5.9604644775390625e-08; // 2^-24: float rounding, relative

struct Seg {
    glm::dvec3 o, p; // world
};

// 0 and the driver's log in `log` when it does not build.
GLuint compile(const std::string& src, std::string& log) {
    auto p = gl::linkComputeProgram({src.c_str()}, "fog test");
    if (!p) return log = p.error(), 0u;
    return *p;
}

struct GpuResult {
    std::vector<float> depth, transmittance;
    double cosErr = 0, atanRelErr = 0, expRelErr = 0; // measured accuracy of the shader's transcendentals
};

// Runs the fog's GLSL on segments (relative to `ref`) and probes cos, atan and exp on the same device.
GpuResult runGpu(const Fog& fog, const FogGlsl& glsl, double tSec, glm::dvec3 ref, const std::vector<Seg>& segs, std::string& error) {
    const std::string src = "#version 450\nlayout(local_size_x = 64) in;\n"
                            "layout(std430, binding = 0) readonly buffer Segs { vec4 segs[]; };\n"
                            "layout(std430, binding = 1) writeonly buffer Outs { vec4 outs[]; };\n"
                            "uniform int uCount;\n" +
                            glsl.source +
                            "void main() {\n"
                            "    uint i = gl_GlobalInvocationID.x;\n"
                            "    if (i >= uint(uCount)) return;\n"
                            "    vec4 a = segs[2u * i], b = segs[2u * i + 1u];\n"
                            "    outs[2u * i] = vec4(splatfx_fog_optical_depth(a.xyz, b.xyz), "
                            "splatfx_fog_transmittance(a.xyz, b.xyz), 0.0, 0.0);\n"
                            "    outs[2u * i + 1u] = vec4(cos(a.w), atan(b.w, 1.0 + a.w), exp(-abs(b.w)), 0.0);\n"
                            "}\n";
    GpuResult r;
    GLuint prog = compile(src, error);
    if (!prog) return r;
    // Segments as vec4 pairs; .w carries probe arguments for the transcendental accuracy check.
    std::mt19937 rng(99);
    std::uniform_real_distribution<double> uw(-1.0, 1.0);
    std::vector<glm::vec4> in;
    std::vector<float> probeA, probeB;
    for (const Seg& s : segs) {
        // cos over the phases the shader can see (up to |w| * 1e5), atan over a wide ratio range.
        const float a = float(uw(rng) * std::pow(10.0, 6.0 * std::abs(uw(rng))));
        const float b = float(uw(rng) * std::pow(10.0, 3.0 * uw(rng)));
        probeA.push_back(a);
        probeB.push_back(b);
        in.push_back({glm::vec3(s.o - ref), a});
        in.push_back({glm::vec3(s.p - ref), b});
    }
    const std::vector<glm::vec4> params = fog.glslParameters(tSec, ref);
    GLuint bufs[2];
    glCreateBuffers(2, bufs);
    glNamedBufferData(bufs[0], GLsizeiptr(in.size() * sizeof(glm::vec4)), in.data(), GL_STATIC_DRAW);
    glNamedBufferData(bufs[1], GLsizeiptr(in.size() * sizeof(glm::vec4)), nullptr, GL_STATIC_READ);
    glUseProgram(prog);
    glUniform4fv(glGetUniformLocation(prog, glsl.uniformName.c_str()), GLsizei(params.size()), &params[0].x);
    glUniform1i(glGetUniformLocation(prog, "uCount"), GLint(segs.size()));
    glUniform1f(glGetUniformLocation(prog, "splatfx_fog_far"), float(fog.desc().farDistanceWorld));
    glUniform3f(glGetUniformLocation(prog, "splatfx_fog_colour"), 1.0f, 1.0f, 1.0f);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, bufs[0]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bufs[1]);
    glDispatchCompute(GLuint((segs.size() + 63) / 64), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<glm::vec4> out(in.size());
    glGetNamedBufferSubData(bufs[1], 0, GLsizeiptr(out.size() * sizeof(glm::vec4)), out.data());
    glDeleteBuffers(2, bufs);
    glDeleteProgram(prog);
    for (size_t i = 0; i < segs.size(); ++i) {
        r.depth.push_back(out[2 * i].x);
        r.transmittance.push_back(out[2 * i].y);
        const glm::vec4 pr = out[2 * i + 1];
        const double a = probeA[i], b = probeB[i];
        r.cosErr = std::max(r.cosErr, std::abs(pr.x - std::cos(a)));
        const double at = std::atan2(b, double(1.0f + probeA[i]));
        if (at != 0.0) r.atanRelErr = std::max(r.atanRelErr, std::abs(pr.y - at) / std::abs(at));
        const double ex = std::exp(-std::abs(b));
        if (ex > 1e-30) r.expRelErr = std::max(r.expRelErr, std::abs(pr.z - ex) / ex);
    }
    return r;
}

// An error bound for the float shader against the exact integral, from the
// fog's parameters and the segment (all computed in double):
//  - every term's integral is a few dozen float operations, each within
//    eps of its operands: (64 eps) times the term's magnitude S_i;
//  - transcendentals are only as good as the device's (measured above):
//    cos absolute error times |amp| L, atan relative error times the potential's integral;
//  - the float positions and parameters are rounded by eps relative: moving an
//    endpoint by dx changes tau by K(endpoint) dx, moving a term's field by dx
//    changes it by at most L max|grad K_i| dx; a phase argument of size |w| |x|
//    is itself rounded by eps |w| |x|.
double errorBound(const Fog& fog, const Seg& s, glm::dvec3 ref, double tSec, const GpuResult& g) {
    const glm::dvec3 oR = s.o - ref, pR = s.p - ref;
    const double L = glm::length(s.p - s.o);
    const double posErr = kEps * (glm::length(oR) + glm::length(pR) + 1.0);
    double bound = posErr * (fog.density(s.o, tSec) + fog.density(s.p, tSec));
    const glm::dvec3 D = fog.windDisplacement(tSec);
    for (const FogTerm& t : fog.desc().terms) {
        const double w = std::abs(t.weightOverTime.at(tSec, t.weight));
        switch (t.kind) {
        case FogTermKind::Constant: bound += 64 * kEps * w * L; break;
        case FogTermKind::Cosine:
        case FogTermKind::CosineProduct: {
            const double k = glm::length(t.wave) + (t.kind == FogTermKind::CosineProduct ? glm::length(t.wave2) : 0.0);
            const double arg = k * (glm::length(oR) + glm::length(pR)) + 8.0;
            bound += w * L * (64 * kEps + 2 * g.cosErr + kEps * arg);
            break;
        }
        case FogTermKind::Polynomial: {
            double sumA = 0, sumNA = 0;
            for (const FogMonomial& m : t.monomials) {
                sumA += std::abs(m.coeff);
                sumNA += std::abs(m.coeff) * (m.px + m.py + m.pz);
            }
            bool used[3] = {false, false, false};
            for (const FogMonomial& m : t.monomials) {
                used[0] = used[0] || m.px > 0;
                used[1] = used[1] || m.py > 0;
                used[2] = used[2] || m.pz > 0;
            }
            const int nUsed = int(used[0]) + int(used[1]) + int(used[2]);
            const int a = used[0] ? 0 : used[1] ? 1 : 2;
            double h = 1e300;
            for (int b = 0; b < 3; ++b)
                if (used[b]) h = std::min(h, t.cellHalfSize[b]);
            const double U = (glm::length(oR) + glm::length(pR)) / std::min(h, 1e300) + 4.0;
            bound += w * L * sumA * 64 * kEps;
            // Cell coordinates carry an error eps U (cell units) and the slope is at most
            // sum n |a_n|: in 1D only the two partial cells see it, together at most 4 half-sizes
            // along the axis (a path of min(L, 4 h / |e_a|)); a multi-variable walk, the whole L.
            const double ea = L > 0.0 ? std::abs((s.p - s.o)[a]) / L : 0.0;
            const double path = nUsed > 1 || ea == 0.0 ? L : std::min(L, 4.0 * h / ea);
            bound += w * sumNA * kEps * U * path;
            break;
        }
        case FogTermKind::Point:
        case FogTermKind::Line:
        case FogTermKind::Sphere: {
            if (t.form == FogPotentialForm::Segment) {
                // V = w / (c + d r^2) in float. The nearest point moves with the float
                // positions (delta each, relative to the reference) and with L (eps L along
                // the ray at a clamped end); |d r^2 / dx| <= 2 r, so r^2 is off by
                // 4 r (delta + eps L) + delta^2 + 8 eps r^2 (its own rounding), and V by
                // w d / (c + d r^2)^2 times that, plus 8 eps V for the division.
                const glm::dvec3 q = t.centre + t.windFactor * D - ref;
                const double delta = 4.0 * kEps * (glm::length(q) + glm::length(oR) + glm::length(pR) + 1.0);
                FogDesc one;
                one.terms.push_back(t);
                one.terms.back().weight = 1.0;
                one.terms.back().weightOverTime = {};
                one.wind = fog.desc().wind;
                auto single = Fog::create(one);
                const double V = single ? single->opticalDepth(s.o, s.p, tSec) : 0.0; // 1 / (c + d r^2)
                const double r2 = std::max(0.0, (1.0 / std::max(V, 1e-300) - t.c) / std::max(t.d, 1e-300));
                const double r = std::sqrt(r2 + t.radius * t.radius);
                const double r2Err = 4.0 * r * (delta + kEps * L) + delta * delta + 8.0 * kEps * (r2 + t.radius * t.radius);
                bound += w * (t.d * V * V * r2Err + 8.0 * kEps * V);
                break;
            }
            FogDesc one;
            one.terms.push_back(t);
            one.terms.back().weight = 1.0;
            one.terms.back().weightOverTime = {};
            one.wind = fog.desc().wind;
            auto single = Fog::create(one);
            const double I = single ? single->opticalDepth(s.o, s.p, tSec) : 0.0;
            bound += w * I * (128 * kEps + 2 * g.atanRelErr);
            // The centre's float position: |q - ref| eps, times L max|grad| = L 0.65 sqrt(d) / c^1.5.
            const glm::dvec3 q = t.centre + t.windFactor * D - ref;
            bound += w * (glm::length(q) + 1.0) * kEps * L * 0.65 * std::sqrt(t.d) / std::pow(t.c, 1.5);
            break;
        }
        }
    }
    return bound;
}

std::vector<Seg> segmentsFrom(glm::dvec3 eye, int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Seg> out;
    for (int i = 0; i < n; ++i) {
        const glm::dvec3 dir = glm::normalize(glm::dvec3(u(rng), 0.3 * u(rng), u(rng)) + glm::dvec3(0, 0, 1e-3));
        const double dist = std::pow(10.0, -0.3 + 5.3 * (0.5 + 0.5 * u(rng))); // 0.5 to 1e5 units
        if (i % 4 == 3) {
            // Not from the eye: a splat-to-splat piece somewhere along the view.
            const glm::dvec3 a = eye + dir * (0.3 * dist);
            out.push_back({a, a + dist * 0.01 * glm::normalize(dir + glm::dvec3(0.2, 0.1, 0))});
        } else {
            out.push_back({eye, eye + dist * dir});
        }
    }
    out.push_back({eye, eye}); // zero length
    // Axis-aligned rays (a polynomial's other variables stay fixed: the O(1) cell count).
    out.push_back({eye, eye + glm::dvec3(3.7e4, 0, 0)});
    out.push_back({eye, eye + glm::dvec3(0, 0, -6.1e4)});
    out.push_back({eye, eye + glm::dvec3(0, 2.2e3, 0)});
    return out;
}

class FogGlslGL : public test::GLTest {
protected:
    void check(const FogDesc& desc, glm::dvec3 eye, double tSec, const char* what) {
        auto fog = Fog::create(desc);
        ASSERT_TRUE(fog.ok()) << fog.error();
        auto glsl = fogGlsl(*fog);
        ASSERT_TRUE(glsl.ok()) << glsl.error();
        const std::vector<Seg> segs = segmentsFrom(eye, 255, 7);
        std::string error;
        const GpuResult g = runGpu(*fog, *glsl, tSec, eye, segs, error);
        ASSERT_TRUE(error.empty()) << what << ": " << error << "\n" << glsl->source;
        ASSERT_EQ(g.depth.size(), segs.size());
        double worst = 0.0;
        for (size_t i = 0; i < segs.size(); ++i) {
            const double exact = fog->opticalDepth(segs[i].o, segs[i].p, tSec);
            const double tol = errorBound(*fog, segs[i], eye, tSec, g);
            const double err = std::abs(double(g.depth[i]) - exact);
            worst = std::max(worst, err / std::max(tol, 1e-300));
            EXPECT_LE(err, tol) << what << " segment " << i << ": gpu " << g.depth[i] << " exact " << exact << " length "
                                << glm::length(segs[i].p - segs[i].o);
            // Transmittance: exp's measured relative error plus the depth error propagated (df = f dtau).
            const double f = fog->transmittance(segs[i].o, segs[i].p, tSec);
            EXPECT_NEAR(g.transmittance[i], f, f * (tol + 2 * g.expRelErr + 4 * kEps) + 1e-37) << what << " segment " << i;
            EXPECT_FALSE(std::isnan(g.depth[i]));
        }
        std::printf("[ fog glsl ] %-28s worst error / bound %.3g (device cos abs err %.2g, atan rel err %.2g)\n", what, worst, g.cosErr,
                    g.atanRelErr);
    }
};

TEST_F(FogGlslGL, PaperFigure6NearAndFarFromTheOrigin) {
    check(paperFig6Fog(), {0.3, 0.5, -0.2}, 0.0, "fig6 near origin");
    check(paperFig6Fog(), {1e6 + 0.3, 1e6 + 0.5, 1e6 - 0.2}, 0.0, "fig6 eye at 1e6");
}

TEST_F(FogGlslGL, PaperFigure7Polynomials) {
    check(paperFig7Fog(10.0), {3.0, 1.7, -4.0}, 0.0, "fig7");
    check(paperFig7Fog(10.0), {2.5e5, 1.7, -3.1e5}, 0.0, "fig7 eye far away");
}

TEST_F(FogGlslGL, PaperFigure8Equipotentials) { check(paperFig8Fog(), {0.0, 1.7, 0.0}, 0.0, "fig8"); }

TEST_F(FogGlslGL, EveryTermKindWithWind) {
    FogDesc d;
    d.terms.push_back(FogTerm::constant(0.05));
    d.terms.push_back(FogTerm::cosine(0.02, 0.7, {0.3, 1, 0}, 0.1));
    d.terms.push_back(FogTerm::polynomial1D(0.02, 1, {0.8, -1, 0, 0, 1}, 3.0, FogCellMode::ZeroOutside, 1.0));
    d.terms.push_back(FogTerm::line(0.3, {4, 0, 10}, {0, 1, 0}, 1.0, 0.5));
    d.terms.push_back(FogTerm::sphere(0.3, {-3, 1, 20}, 6.0, 0.5, 2.0)); // kappa <= 0 through the ball
    d.terms.push_back(FogTerm::sphere(0.2, {5, 2, 8}, 0.5, 1.0, 1.0));
    d.terms.push_back(FogTerm::point(0.4, {0, 1.7, 0}, 1.0, 1.0)); // at the eye: r -> 0
    d.wind = FogWind::ramp(0.0, {0.5, 0, 0.2}, 10.0, {-1, 0, 0.3});
    d.farDistanceWorld = 5e4;
    check(d, {0.0, 1.7, 0.0}, 0.0, "all kinds t=0");
    check(d, {0.0, 1.7, 0.0}, 37.5, "all kinds t=37.5 (wind)");
}

// Biri et al.'s eq. 9 as printed (FogPotentialForm::Segment) for each kind, beside a
// density term of every potential kind, near the eye and far from the origin.
TEST_F(FogGlslGL, PaperEquation9SegmentFormForEveryPotentialKind) {
    FogDesc d;
    d.terms.push_back(FogTerm::constant(0.01));
    d.terms.push_back(FogTerm::point(0.8, {2, 1.5, 30}, 0.5, 0.02));
    d.terms.push_back(FogTerm::line(0.6, {-5, 0, 12}, {0.2, 1, 0}, 1.0, 0.1));
    d.terms.push_back(FogTerm::sphere(0.7, {6, 2, -40}, 8.0, 0.4, 0.01));
    d.terms.push_back(FogTerm::point(0.3, {0, 1.7, 0}, 1.0, 1.0)); // at the eye: r = 0 on every ray
    for (std::size_t i = 1; i < d.terms.size(); ++i) d.terms[i].form = FogPotentialForm::Segment;
    d.terms.push_back(FogTerm::sphere(0.05, {-3, 1, 20}, 3.0, 0.5, 2.0)); // a density term beside them
    d.wind = FogWind::constant({0.4, 0, -0.1});
    check(d, {0.0, 1.7, 0.0}, 0.0, "eq. 9 segment form");
    check(d, {0.0, 1.7, 0.0}, 25.0, "eq. 9 segment form, wind");
    for (FogTerm& t : d.terms) t.centre += glm::dvec3(3e5, 0, -2e5);
    check(d, {3e5, 1.7, -2e5}, 0.0, "eq. 9 segment form at 3e5");
}

TEST_F(FogGlslGL, ZeroTermsCompiles) { check(FogDesc{}, {1, 2, 3}, 0.0, "no terms"); }

TEST_F(FogGlslGL, PolynomialsInThreeVariables) {
    // Periodic: cells large enough that no test ray crosses more than maxPolynomialCells (1024):
    // a 1e5 ray crosses at most 1e5 (1/400 + 1/300 + 1/500) < 800 cells.
    FogTerm t;
    t.kind = FogTermKind::Polynomial;
    t.cellHalfSize = {200.0, 150.0, 250.0};
    t.monomials = {{0.02, 0, 0, 0}, {-0.005, 2, 1, 0}, {0.003, 1, 1, 1}, {0.002, 0, 0, 4}, {0.001, 3, 0, 2}};
    FogDesc d;
    d.terms.push_back(t);
    check(d, {10.0, 1.7, -30.0}, 0.0, "3-variable periodic");
    // Zero outside, small cell around the eye, with wind.
    t.cellMode = FogCellMode::ZeroOutside;
    t.cellHalfSize = {20.0, 10.0, 30.0};
    FogDesc z;
    z.terms.push_back(t);
    z.wind = FogWind::constant({0.7, 0.0, -0.4});
    check(z, {3.0, 1.7, -5.0}, 4.0, "3-variable zero outside");
}

TEST_F(FogGlslGL, BadOptionsAreNamed) {
    auto fog = Fog::create(paperFig6Fog());
    ASSERT_TRUE(fog.ok());
    auto glsl = fogGlsl(*fog, {.maxPolynomialCells = 0});
    ASSERT_FALSE(glsl.ok());
    EXPECT_NE(glsl.error().find("maxPolynomialCells"), std::string::npos) << glsl.error();
    auto bad = fogGlsl(*fog, {.prefix = "my fog"});
    ASSERT_FALSE(bad.ok());
    EXPECT_NE(bad.error().find("FogGlslOptions.prefix must be a GLSL identifier"), std::string::npos) << bad.error();
    // A custom prefix compiles: every emitted name carries it.
    auto custom = fogGlsl(*fog, {.prefix = "hostfog", .uniformLocation = 3});
    ASSERT_TRUE(custom.ok());
    EXPECT_EQ(custom->uniformName, "hostfog_params");
    std::string log;
    const GLuint prog = compile("#version 450\nlayout(local_size_x = 1) in;\n" + custom->source +
                                    "layout(std430, binding = 0) buffer O { float o[]; };\n"
                                    "void main() { o[0] = hostfog_transmittance(vec3(0.0), vec3(1.0, 2.0, 3.0)); }\n",
                                log);
    EXPECT_NE(prog, 0u) << log;
    if (prog) glDeleteProgram(prog);
}

} // namespace
} // namespace splatfx
