// Transfer function, the exact segment integral, and the pre-integration table:
// closed forms, the front == back division limit, lengths -> 0 and very large,
// and the table's trilinear error against its derived bound.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "splatfx/volume.hpp"

using namespace splatfx;

namespace {

TransferFunction linearTf() {
    // Linear extinction and colour: smooth table entries (no kinks inside [0, 1]).
    return *TransferFunction::create({{0.0f, {1.0f, 0.5f, 0.0f}, 0.2f}, {1.0f, {0.0f, 0.5f, 1.0f}, 3.0f}});
}

} // namespace

TEST(TransferFunction, BadPointsAreRejectedByIndex) {
    auto a = TransferFunction::create({});
    ASSERT_FALSE(a);
    EXPECT_NE(a.error().find("points"), std::string::npos);
    auto b = TransferFunction::create({{0.5f, {1, 1, 1}, 1.0f}, {0.2f, {1, 1, 1}, 1.0f}});
    ASSERT_FALSE(b);
    EXPECT_NE(b.error().find("points[1].scalar"), std::string::npos) << b.error();
    auto c = TransferFunction::create({{0.5f, {1, 1, 1}, -1.0f}});
    ASSERT_FALSE(c);
    EXPECT_NE(c.error().find("points[0].extinctionPerWorld"), std::string::npos) << c.error();
}

TEST(TransferFunction, ZeroOpacityIsExactOnIntervals) {
    auto tf = makeCloudTransfer({.threshold = 0.2f});
    ASSERT_TRUE(tf) << tf.error();
    EXPECT_TRUE(tf->zeroOpacity(0.0, 0.19));
    EXPECT_FALSE(tf->zeroOpacity(0.0, double(0.2f))); // the step is at 0.2f: rho(0.2f) > 0
    EXPECT_FALSE(tf->zeroOpacity(0.5, 0.6));
    // A bump strictly inside the interval (ends both zero) is found.
    auto bump = TransferFunction::create({{0.0f, {1, 1, 1}, 0.0f}, {0.5f, {1, 1, 1}, 1.0f}, {0.6f, {1, 1, 1}, 0.0f}});
    ASSERT_TRUE(bump);
    EXPECT_FALSE(bump->zeroOpacity(0.0, 1.0));
    EXPECT_TRUE(bump->zeroOpacity(0.7, 1.0));
}

TEST(PreIntegration, FrontEqualsBackIsTheDivisionLimit) {
    const TransferFunction tf = linearTf();
    for (double s : {0.0, 0.37, 1.0})
        for (double l : {1e-3, 0.5, 4.0}) {
            const double tau = tf.extinction(s);
            const glm::dvec3 c = tf.color(s);
            const glm::dvec4 r = integrateSegment(tf, s, s, l);
            const double a = -std::expm1(-tau * l);
            // Closed form for a constant medium; the integrator's 5-point Gauss rule on steps of
            // optical depth <= 1/4 errs ~1e-12 relative.
            EXPECT_NEAR(r.a, a, 1e-12 * std::max(a, 1e-3));
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(r[k], c[k] * a, 1e-12);
            // Continuity across the division: back scalar 1e-12 away.
            const glm::dvec4 near = integrateSegment(tf, s, std::min(1.0, s + 1e-12), l);
            const glm::dvec4 near2 = integrateSegment(tf, s, std::max(0.0, s - 1e-12), l);
            for (int k = 0; k < 4; ++k) {
                EXPECT_NEAR(near[k], r[k], 1e-10);
                EXPECT_NEAR(near2[k], r[k], 1e-10);
            }
        }
}

TEST(PreIntegration, LinearExtinctionHasClosedFormOpacity) {
    const TransferFunction tf = linearTf();
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < 200; ++i) {
        const double sf = u(rng), sb = u(rng), l = 3.0 * u(rng), mf = u(rng), mb = u(rng);
        // tau(s(x)) and m(x) linear in x: depth = l * integral of their product.
        const double tf0 = tf.extinction(sf), tb0 = tf.extinction(sb);
        const double depth = l * (tf0 * mf / 3.0 + (tf0 * mb + tb0 * mf) / 6.0 + tb0 * mb / 3.0);
        const glm::dvec4 r = integrateSegment(tf, sf, sb, l, mf, mb);
        EXPECT_NEAR(r.a, -std::expm1(-depth), 1e-13);
    }
}

TEST(PreIntegration, LengthToZeroAndVeryLarge) {
    const TransferFunction tf = linearTf();
    // l -> 0: alpha / l -> mean extinction, colour / alpha -> mean colour weighting.
    const double sf = 0.2, sb = 0.8;
    const double l = 1e-9;
    const glm::dvec4 tiny = integrateSegment(tf, sf, sb, l);
    const double mean = 0.5 * (tf.extinction(sf) + tf.extinction(sb));
    EXPECT_NEAR(tiny.a / l, mean, 1e-6 * mean); // next term is O(l) relative
    EXPECT_EQ(integrateSegment(tf, sf, sb, 0.0), glm::dvec4(0.0));
    EXPECT_EQ(integrateSegment(tf, sf, sb, -1.0), glm::dvec4(0.0));
    EXPECT_EQ(integrateSegment(tf, std::nan(""), sb, 1.0), glm::dvec4(0.0));
    // Very large: opaque, and the colour is the front's (the ray saturates within ~1e-11 of the length).
    for (double big : {1e6, 1e12, 1e30, std::numeric_limits<double>::infinity()}) {
        const glm::dvec4 r = integrateSegment(tf, sf, sb, big);
        EXPECT_EQ(r.a, 1.0);
        const glm::dvec3 c = tf.color(sf);
        for (int k = 0; k < 3; ++k) {
            EXPECT_TRUE(std::isfinite(r[k]));
            // Colour change over the saturation depth (~40 / tau of l) is O(40 / (tau l)).
            // Plus a few double ulps of the accumulated sum.
            EXPECT_NEAR(r[k], c[k], 100.0 / (tf.extinction(sf) * std::min(big, 1e30)) + 1e-14);
        }
    }
    // Table: length 0 is zero, and lengths beyond the last slice compose exactly-split pieces.
    auto table = PreIntegrationTable::create(tf, {.maxLengthWorld = 1.0f});
    ASSERT_TRUE(table) << table.error();
    EXPECT_EQ(table->lookup(0.3f, 0.7f, 0.0f), glm::vec4(0.0f));
    const glm::vec4 far = table->lookup(0.3f, 0.7f, 1e20f);
    EXPECT_NEAR(far.a, 1.0f, 1e-6f);
    EXPECT_TRUE(std::isfinite(far.r) && std::isfinite(far.b));
}

TEST(PreIntegration, TableMatchesExactIntegralWithinTrilinearBound) {
    const TransferFunction tf = linearTf();
    const PreIntegrationDesc desc{}; // the paper's 64 x 64 x 128
    auto table = PreIntegrationTable::create(tf, desc);
    ASSERT_TRUE(table) << table.error();
    EXPECT_EQ(table->dims(), glm::ivec3(64, 64, 128));
    EXPECT_EQ(table->bytes(), std::size_t(64 * 64 * 128 * 4 * 4));
    const double hs = 1.0 / 63.0, hl = double(desc.maxLengthWorld) / 127.0;
    // Trilinear interpolation errs at most (1/8) sum_i h_i^2 max|d2f/dx_i^2|. The second
    // derivatives are estimated by central differences of the exact integral on a grid of
    // spacing h/2 (the entries are smooth for a linear transfer function); 25% margin for
    // the sampled maximum.
    glm::dvec4 m2s(0.0), m2b(0.0), m2l(0.0);
    const int N = 24;
    for (int i = 1; i < N; ++i)
        for (int j = 1; j < N; ++j)
            for (int k = 1; k < N; ++k) {
                const double sf = double(i) / N, sb = double(j) / N, l = double(k) / N * desc.maxLengthWorld;
                const double e = 0.5 * hs, el = 0.5 * hl;
                const glm::dvec4 c = integrateSegment(tf, sf, sb, l);
                const glm::dvec4 ds = (integrateSegment(tf, sf + e, sb, l) - 2.0 * c + integrateSegment(tf, sf - e, sb, l)) / (e * e);
                const glm::dvec4 db = (integrateSegment(tf, sf, sb + e, l) - 2.0 * c + integrateSegment(tf, sf, sb - e, l)) / (e * e);
                const glm::dvec4 dl = (integrateSegment(tf, sf, sb, l + el) - 2.0 * c + integrateSegment(tf, sf, sb, l - el)) / (el * el);
                m2s = glm::max(m2s, glm::abs(ds));
                m2b = glm::max(m2b, glm::abs(db));
                m2l = glm::max(m2l, glm::abs(dl));
            }
    const glm::dvec4 bound = 1.25 * (hs * hs * m2s + hs * hs * m2b + hl * hl * m2l) / 8.0 + 1e-6; // + float storage
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    glm::dvec4 worst(0.0);
    for (int i = 0; i < 3000; ++i) {
        const double sf = u(rng), sb = u(rng), l = u(rng) * desc.maxLengthWorld;
        const glm::dvec4 e = integrateSegment(tf, sf, sb, l);
        const glm::dvec4 t(table->lookup(float(sf), float(sb), float(l)));
        worst = glm::max(worst, glm::abs(e - t));
    }
    for (int ch = 0; ch < 4; ++ch) {
        EXPECT_LE(worst[ch], bound[ch]) << "channel " << ch;
        EXPECT_GT(worst[ch], 0.0); // the comparison ran on interpolated values
    }
    // Beyond the last slice: three pieces, each within the bound, composited (errors add).
    for (int i = 0; i < 200; ++i) {
        const double sf = u(rng), sb = u(rng), l = 2.5 * desc.maxLengthWorld;
        const glm::dvec4 e = integrateSegment(tf, sf, sb, l);
        const glm::dvec4 t(table->lookup(float(sf), float(sb), float(l)));
        for (int ch = 0; ch < 4; ++ch) EXPECT_NEAR(t[ch], e[ch], 3.0 * bound[ch]);
    }
}

TEST(PreIntegration, TableZeroOpacityTestIsConservative) {
    auto tf = makeCloudTransfer({});
    ASSERT_TRUE(tf);
    auto table = PreIntegrationTable::create(*tf, {.scalarResolution = 32, .lengthResolution = 16});
    ASSERT_TRUE(table) << table.error();
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 0.15f); // around the 0.08 threshold
    int zero = 0;
    for (int i = 0; i < 2000; ++i) {
        float a = u(rng), b = u(rng);
        if (a > b) std::swap(a, b);
        if (table->zeroOpacity(a, b)) {
            ++zero;
            EXPECT_TRUE(tf->zeroOpacity(a, b)) << a << " " << b; // never discards a visible range
        }
    }
    EXPECT_GT(zero, 100);
}

TEST(PreIntegration, BadDescIsRejected) {
    const TransferFunction tf = linearTf();
    auto a = PreIntegrationTable::create(tf, {.scalarResolution = 1});
    ASSERT_FALSE(a);
    EXPECT_NE(a.error().find("scalarResolution"), std::string::npos);
    auto b = PreIntegrationTable::create(tf, {.maxLengthWorld = std::nanf("")});
    ASSERT_FALSE(b);
    EXPECT_NE(b.error().find("maxLengthWorld"), std::string::npos);
}

// A NaN scalar (a degenerate segment's 0/0) holds no material: zero colour and
// extinction, and no look-up past the table's end (found by ASan through the
// one-medium reference on a ray grazing a face).
TEST(TransferFunction, ANanScalarHasNoMaterial) {
    const TransferFunction tf = *TransferFunction::create(
        {{0.0f, {0, 0, 0}, 0.0f}, {0.3f, {1.0f, 0.9f, 0.8f}, 2.0f}, {0.7f, {0.5f, 0.5f, 0.5f}, 4.0f}, {1.0f, {0, 0, 1}, 1.0f}});
    EXPECT_EQ(tf.extinction(std::nan("")), 0.0);
    EXPECT_EQ(tf.color(std::nan("")), glm::dvec3(0.0));
    EXPECT_DOUBLE_EQ(tf.extinction(0.5), 3.0); // and ordinary look-ups are unchanged
}
