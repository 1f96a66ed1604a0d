// The one-medium reference (integrateRayWithFog, renderTetraExact)
// against the closed form of a constant fog through one homogeneous
// tetrahedron: fog only, cloud and fog together, fog only again.
#include <cmath>
#include <optional>

#include <gtest/gtest.h>

#include "splatfx/reference.hpp"

using namespace splatfx;

namespace {

struct OneTetInFog {
    Tetrahedron tet;
    std::optional<TransferFunction> transfer;
    std::optional<Fog> fog;
    double sigmaC = 0.0, sigmaF = 0.05;
    glm::dvec3 kappa{0.9, 0.5, 0.1}, fogColour{0.2, 0.4, 0.8};
    OneTetInFog() {
        tet.position = {glm::vec3(-6, -6, 4), glm::vec3(6, -6, 4), glm::vec3(0, 9, 4), glm::vec3(0.5f, 0.3f, 12)};
        if (glm::dot(tet.position[1] - tet.position[0], glm::cross(tet.position[2] - tet.position[0], tet.position[3] - tet.position[0])) < 0.0f)
            std::swap(tet.position[2], tet.position[3]);
        tet.scalar = {0.5f, 0.5f, 0.5f, 0.5f};
        tet.lengthScale = {1.0f, 1.0f, 1.0f, 1.0f};
        // kappa constant, extinction 0.3 at scalar 0.5 (linear 0 -> 0.6).
        transfer.emplace(*TransferFunction::create({{0.0f, glm::vec3(kappa), 0.0f}, {1.0f, glm::vec3(kappa), 0.6f}}));
        // The transfer function stores float: the closed form uses the stored values.
        sigmaC = 0.5 * double(0.6f);
        kappa = glm::dvec3(glm::vec3(kappa));
        FogDesc fd;
        fd.terms = {FogTerm::constant(sigmaF)};
        fd.colour = fogColour;
        fog.emplace(*Fog::create(fd));
    }
    // Where the ray o + t d enters and leaves the tetrahedron (plane tests in double).
    void chord(glm::dvec3 o, glm::dvec3 d, double& a, double& b) const {
        a = -1e300, b = 1e300;
        for (int k = 0; k < 4; ++k) {
            const glm::dvec3 p0(tet.position[std::size_t((k + 1) % 4)]), p1(tet.position[std::size_t((k + 2) % 4)]),
                p2(tet.position[std::size_t((k + 3) % 4)]), q(tet.position[std::size_t(k)]);
            glm::dvec3 n = glm::cross(p1 - p0, p2 - p0);
            if (glm::dot(n, q - p0) < 0.0) n = -n;
            const double t = glm::dot(n, p0 - o) / glm::dot(n, d);
            if (glm::dot(n, d) > 0.0) a = std::max(a, t);
            else b = std::min(b, t);
        }
    }
};

} // namespace

TEST(TetraFogReference, MatchesTheClosedFormOfConstantFogAndCloud) {
    const OneTetInFog s;
    const glm::dvec3 o(0.1, 0.2, 0.0), d(0.0, 0.0, 1.0);
    double a = 0.0, b = 0.0;
    s.chord(o, d, a, b);
    ASSERT_GT(b, a);
    ASSERT_GT(a, 0.0);
    const double L = 30.0;
    const double sc = s.sigmaC, sf = s.sigmaF;
    // Physical: fog on [0, a], both on [a, b], fog on [b, L].
    const double T1 = std::exp(-sf * a), T2 = T1 * std::exp(-(sc + sf) * (b - a)), T3 = T2 * std::exp(-sf * (L - b));
    const glm::dvec3 c = s.fogColour * (1.0 - T1) + T1 * (sc * s.kappa + sf * s.fogColour) / (sc + sf) * (1.0 - std::exp(-(sc + sf) * (b - a))) +
                         T2 * s.fogColour * (1.0 - std::exp(-sf * (L - b)));
    RayFogStats st;
    const glm::dvec4 host = integrateRayWithFog({s.tet}, *s.transfer, o, d, 0.0, L, {.fog = &*s.fog, .fogHost = true, .tolerance = 1e-9}, &st);
    EXPECT_TRUE(st.converged);
    // Tolerance 1e-9 per piece; the constant-colour step rule is exact, so only rounding and the
    // halving's last difference remain: 1e-7 is far above both and far below any modelling error.
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(host[k], c[k], 1e-7) << k;
    EXPECT_NEAR(host.a, 1.0 - T3, 1e-7);
    EXPECT_NEAR(st.cloudTransmittance, std::exp(-sc * (b - a)), 1e-9);
    EXPECT_NEAR(st.fogTransmittance, std::exp(-sf * L), 1e-9);
    // Without the host fog pass: the fog reaching the background through the cloud is left out.
    const glm::dvec4 noHost = integrateRayWithFog({s.tet}, *s.transfer, o, d, 0.0, L, {.fog = &*s.fog, .fogHost = false, .tolerance = 1e-9});
    const double Tc = std::exp(-sc * (b - a));
    const glm::dvec3 cNoHost = c - Tc * (1.0 - std::exp(-sf * L)) * s.fogColour;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(noHost[k], cNoHost[k], 1e-7) << k;
    EXPECT_NEAR(noHost.a, 1.0 - Tc, 1e-9);
    // No fog: the cloud alone, as integrateRay.
    const glm::dvec4 clear = integrateRayWithFog({s.tet}, *s.transfer, o, d, 0.0, L, {.tolerance = 1e-9});
    const glm::dvec4 plain = integrateRay({s.tet}, *s.transfer, o, d, 0.0, L);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(clear[k], plain[k], 1e-7) << k;
}

TEST(TetraFogReference, FarCutOffTurnsTheRestIntoFogColour) {
    OneTetInFog s;
    FogDesc fd = s.fog->desc();
    fd.farDistanceWorld = 20.0;
    const Fog farFog = *Fog::create(fd);
    const glm::dvec3 o(0.1, 0.2, 0.0), d(0.0, 0.0, 1.0);
    double a = 0.0, b = 0.0;
    s.chord(o, d, a, b);
    ASSERT_LT(b, 20.0);
    const double sc = s.sigmaC, sf = s.sigmaF, T1 = std::exp(-sf * a), T2 = T1 * std::exp(-(sc + sf) * (b - a));
    const glm::dvec3 upToWall = s.fogColour * (1.0 - T1) +
                                T1 * (sc * s.kappa + sf * s.fogColour) / (sc + sf) * (1.0 - std::exp(-(sc + sf) * (b - a))) +
                                T2 * s.fogColour * (1.0 - std::exp(-sf * (20.0 - b)));
    const double Twall = T2 * std::exp(-sf * (20.0 - b));
    const glm::dvec4 r = integrateRayWithFog({s.tet}, *s.transfer, o, d, 0.0, 50.0, {.fog = &farFog, .tolerance = 1e-9});
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(r[k], upToWall[k] + Twall * s.fogColour[k], 1e-7) << k;
    EXPECT_NEAR(r.a, 1.0, 1e-12) << "fully fogged beyond the cut-off";
}

TEST(TetraFogReference, RenderTetraExactChecksItsInput) {
    const OneTetInFog s;
    const Camera persp = Camera::lookAt({0, 0, -5}, {0, 0, 5}, {0, 1, 0}, 0.8f, {8, 6});
    EXPECT_FALSE(renderTetraExact({s.tet}, *s.transfer, persp, {.tolerance = 0.0}));
    EXPECT_FALSE(renderTetraExact({s.tet}, *s.transfer, persp, {.maxHalvings = 0}));
    const Camera ortho = Camera::fromMatrices(glm::mat4(1.0f), glm::mat4(1.0f), {8, 6});
    auto r = renderTetraExact({s.tet}, *s.transfer, ortho);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("perspective"), std::string::npos) << r.error();
    auto ok = renderTetraExact({s.tet}, *s.transfer, persp, {.fog = &*s.fog});
    ASSERT_TRUE(ok) << ok.error();
    for (float v : ok->pixels) EXPECT_TRUE(std::isfinite(v));
    // Bad rays give zero, not NaN.
    const glm::dvec4 bad = integrateRayWithFog({s.tet}, *s.transfer, glm::dvec3(NAN), {0, 0, 1}, 0.0, 10.0, {.fog = &*s.fog});
    EXPECT_EQ(bad, glm::dvec4(0.0));
}
