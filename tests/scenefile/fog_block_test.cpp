// The scene file's "fog" block (fog_block.cpp, docs/scene-format.md): read,
// scaled and validated; every error names its field.
#include <gtest/gtest.h>

#include "splatfx/scene_file.hpp"

namespace {

splatfx::Result<splatfx::SceneFile> parseFog(const std::string& fog) {
    splatfx::Materials m(splatfx::Footprint{});
    return splatfx::parseSceneFile(R"({"format": "splatfx-scene", "version": 1, "fog": )" + fog + "}", "dir/scene.json", m);
}

std::string errorOf(const std::string& fog) {
    auto r = parseFog(fog);
    return r ? std::string("(parsed)") : r.error();
}

TEST(FogBlock, EveryTermKindIsReadAndMatchesTheApi) {
    auto r = parseFog(R"({"colour": [0.5, 0.6, 0.7], "farDistance": 300, "wind": [1, 0, 0.5], "terms": [
        {"kind": "constant", "weight": 2},
        {"kind": "cosine", "weight": 0.5, "k": 3, "direction": [0, 2, 0], "phase": 0.1},
        {"kind": "cosineProduct", "weight": 0.2, "k": 1, "direction": [1, 0, 0], "k2": 0.5, "direction2": [0, 0, 1]},
        {"kind": "polynomial", "weight": 0.3, "axis": "z", "coeffs": [0.8, -1, 0, 0, 1], "halfSize": 10, "mode": "periodic"},
        {"kind": "point", "weight": 1, "centre": [1, 2, 3], "c": 1, "d": 4, "windFactor": 0},
        {"kind": "line", "weight": 1, "point": [0, 0, 0], "axis": [0, 1, 0], "c": 2, "d": 1},
        {"kind": "sphere", "weight": 1, "centre": [0, 1, 0], "radius": 2, "c": 1, "d": 1}]})");
    ASSERT_TRUE(r) << r.error();
    const splatfx::Fog* fog = r->scene.fog();
    ASSERT_NE(fog, nullptr);
    ASSERT_EQ(fog->desc().terms.size(), 7u);
    EXPECT_DOUBLE_EQ(fog->desc().farDistanceWorld, 300.0);
    EXPECT_NEAR(fog->desc().colour.y, 0.6, 1e-7);
    splatfx::FogDesc d;
    d.terms = {splatfx::FogTerm::constant(2),
               splatfx::FogTerm::cosine(0.5, 3, {0, 1, 0}, 0.1),
               splatfx::FogTerm::cosineProduct(0.2, 1, {1, 0, 0}, 0, 0.5, {0, 0, 1}, 0),
               splatfx::FogTerm::polynomial1D(0.3, 2, {0.8, -1, 0, 0, 1}, 10),
               splatfx::FogTerm::point(1, {1, 2, 3}, 1, 4),
               splatfx::FogTerm::line(1, {0, 0, 0}, {0, 1, 0}, 2, 1),
               splatfx::FogTerm::sphere(1, {0, 1, 0}, 2, 1, 1)};
    d.terms[4].windFactor = 0;
    d.wind = splatfx::FogWind::constant({1, 0, 0.5});
    auto api = splatfx::Fog::create(d);
    ASSERT_TRUE(api) << api.error();
    for (double t : {0.0, 2.5}) EXPECT_NEAR(fog->opticalDepth({-3, 0.2, 1}, {4, 1.5, -7}, t), api->opticalDepth({-3, 0.2, 1}, {4, 1.5, -7}, t), 1e-9);
}

TEST(FogBlock, ScaleKeepsTheOpticalDepthOfAScaledPath) {
    auto paper = parseFog(R"({"preset": "fig6"})");
    auto scaled = parseFog(R"({"preset": "fig6", "scale": 50, "density": 2})");
    ASSERT_TRUE(paper && scaled);
    const glm::dvec3 o{0.1, 0.2, -0.3}, p{1.3, 0.4, 0.9};
    EXPECT_NEAR(scaled->scene.fog()->opticalDepth(50.0 * o, 50.0 * p, 0.0), 2.0 * paper->scene.fog()->opticalDepth(o, p, 0.0), 1e-9);
}

// Biri et al.'s eq. 9 as printed: "form": "segment" on a potential; its
// weight is a depth, so "scale" leaves it alone ("density" still multiplies it).
TEST(FogBlock, ThePapersSegmentFormIsReadAndScaledAsADepth) {
    auto r = parseFog(R"({"scale": 10, "density": 2, "terms": [{"kind": "point", "weight": 0.5, "centre": [0, 1, 0], "c": 1, "d": 4, "form": "segment"}]})");
    ASSERT_TRUE(r) << r.error();
    const splatfx::FogTerm& t = r->scene.fog()->desc().terms.at(0);
    EXPECT_EQ(t.form, splatfx::FogPotentialForm::Segment);
    // The same path in the file's own units (scaled by 10): r = 1 there, 10 in the world.
    EXPECT_NEAR(r->scene.fog()->opticalDepth({-30, 0, 0}, {30, 0, 0}, 0.0), 2.0 * 0.5 / (1.0 + 4.0 * 1.0), 1e-12);
    EXPECT_NE(errorOf(R"({"terms": [{"kind": "point", "form": "sideways"}]})").find("fog.terms[0].form"), std::string::npos);
    EXPECT_NE(errorOf(R"({"terms": [{"kind": "constant", "weight": 1}, {"kind": "point", "weight": -0.1, "form": "segment"}]})").find("terms[1].weight"),
              std::string::npos);
}

TEST(FogBlock, ErrorsNameTheField) {
    EXPECT_NE(errorOf(R"({"terms": [{"kind": "fluffy"}]})").find("fog.terms[0].kind"), std::string::npos);
    EXPECT_NE(errorOf(R"({"terms": [{"weight": 1}]})").find("fog.terms[0].kind"), std::string::npos);
    EXPECT_NE(errorOf(R"({"terms": [{"kind": "point", "c": 0}]})").find("fog.terms[0].c"), std::string::npos);
    EXPECT_NE(errorOf(R"({"terms": [{"kind": "polynomial"}]})").find("fog.terms[0].coeffs"), std::string::npos);
    EXPECT_NE(errorOf(R"({"terms": [{"kind": "cosine", "direction": [0, 0, 0]}]})").find("fog.terms[0].direction"), std::string::npos);
    EXPECT_NE(errorOf(R"({"colour": [1, 2]})").find("fog.colour"), std::string::npos);
    EXPECT_NE(errorOf(R"({"wind": [{"timeSec": 2, "velocity": [1, 0, 0]}, {"timeSec": 1}]})").find("fog.wind[1].timeSec"), std::string::npos);
    EXPECT_NE(errorOf(R"({"fogginess": 3})").find("fog.fogginess"), std::string::npos);
    EXPECT_NE(errorOf(R"({"preset": "fig99"})").find("fog.preset"), std::string::npos);
    // A density that goes negative: Fog::create's message, under the block's name.
    const std::string neg = errorOf(R"({"terms": [{"kind": "constant", "weight": 0.1}, {"kind": "cosine", "weight": 0.5}]})");
    EXPECT_NE(neg.find("fog"), std::string::npos);
    EXPECT_NE(neg.find("terms[1]"), std::string::npos) << neg;
}

TEST(FogBlock, NoBlockNoFog) {
    splatfx::Materials m(splatfx::Footprint{});
    auto r = splatfx::parseSceneFile(R"({"format": "splatfx-scene", "version": 1})", "dir/scene.json", m);
    ASSERT_TRUE(r) << r.error();
    EXPECT_EQ(r->scene.fog(), nullptr);
}

} // namespace
