// The embedded GLSL files and their include resolver (sdk/src/glsl): every
// program variant assembles, shared includes appear once, and the host's
// GLSL (fogGlsl, shadowGlsl, transparentGlsl, partialGlsl) is the files' text.
#include <gtest/gtest.h>

#include <string>

#include "glsl/glsl_files.hpp"
#include "glsl/programs.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/footprint.hpp"
#include "splatfx/lighting.hpp"
#include "splatfx/transparency.hpp"

namespace splatfx {
namespace {

std::size_t count(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

TEST(GlslFiles, EveryVariantAssemblesWithItsIncludesResolved) {
    const Fog fog = *Fog::create(paperFig6Fog());
    const std::string fogSource = fogGlsl(fog)->source, partial = partialGlsl(Footprint(FootprintDesc{}), 2);
    int variants = 0;
    for (int p = 0; p < int(glsl::ProgramId::Count); ++p)
        glsl::forEachVariant(glsl::ProgramId(p), [&](const std::array<int, glsl::kMaxDefines>& values) {
            const glsl::ProgramKey key{glsl::ProgramId(p), values, 0};
            auto stages = glsl::programSources(key, {.fog = fogSource, .partial = partial});
            ASSERT_TRUE(stages) << stages.error();
            for (const glsl::StageSource& s : *stages) {
                EXPECT_EQ(s.text.rfind("#version 450 core\n", 0), 0u) << glsl::variantName(key);
                EXPECT_EQ(s.text.find("#include"), std::string::npos) << glsl::variantName(key) << " " << s.file;
            }
            ++variants;
        });
    // splat 3 fog states (none, per fragment, per splat) x 7 cut states x 2 cross-fade = 42; sections
    // 6 kinds x 3 section counts = 18; tetrahedra 16 (perspective, host depth, fog, an RGB source per
    // vertex); fog pass 3; resolve: every K a budget of 1 to
    // 128 fragments per pixel can ask for x 2 programs = 256; the eight programs without defines 8
    // (the host depth sample one among them).
    EXPECT_EQ(variants, 42 + 18 + 16 + 3 + 256 + 8);
}

TEST(GlslFiles, AnIncludeAppearsOncePerExpansion) {
    // list_section.frag includes transparent.glsl, which includes transparent_lists.glsl.
    auto text = glsl::expand("list_section.frag");
    ASSERT_TRUE(text) << text.error();
    EXPECT_EQ(count(*text, "struct splatfx_Node {"), 1u);
    EXPECT_EQ(count(*text, "bool splatfx_splat_plane("), 1u);
}

TEST(GlslFiles, AMissingFileIsNamed) {
    auto text = glsl::expand("no_such_file.glsl");
    ASSERT_FALSE(text);
    EXPECT_NE(text.error().find("\"no_such_file.glsl\" is not embedded"), std::string::npos) << text.error();
    EXPECT_TRUE(glsl::file("no_such_file.glsl").empty());
    // A variant that reads a generated include it was not given is named.
    glsl::ProgramKey key{glsl::ProgramId::FogPass, {0}, 0};
    auto stages = glsl::programSources(key, {});
    ASSERT_FALSE(stages);
    EXPECT_NE(stages.error().find("fog pass [MODE=0]: needs the fog's GLSL"), std::string::npos) << stages.error();
}

// The build compiles exactly forEachVariant's list with glslangValidator (warnings fail it too), so a
// pass asking for any other variant would reach a driver unchecked: programSources refuses it.
TEST(GlslFiles, AVariantTheBuildDoesNotCheckIsRefused) {
    const glsl::ProgramKey outside{glsl::ProgramId::FogPass, {7}, 0}; // MODE takes 0, 1, 2
    EXPECT_FALSE(glsl::isCheckedVariant(outside));
    auto stages = glsl::programSources(outside, {.fog = "x"});
    ASSERT_FALSE(stages);
    EXPECT_NE(stages.error().find("fog pass [MODE=7]: not among the variants the build checks"), std::string::npos) << stages.error();
    // A value for a define the program does not have.
    EXPECT_FALSE(glsl::isCheckedVariant({glsl::ProgramId::DepthSample, {1}, 0}));
    int listed = 0;
    for (int p = 0; p < int(glsl::ProgramId::Count); ++p)
        glsl::forEachVariant(glsl::ProgramId(p), [&](const std::array<int, glsl::kMaxDefines>& values) {
            EXPECT_TRUE(glsl::isCheckedVariant({glsl::ProgramId(p), values, 0}));
            ++listed;
        });
    EXPECT_EQ(listed, 42 + 18 + 16 + 3 + 256 + 8);
}

TEST(GlslFiles, SubstituteReplacesWholeWordsOnly) { EXPECT_EQ(glsl::substitute("A A_B xA A", {{"A", "1"}}), "1 A_B xA 1"); }

TEST(GlslFiles, TheHostIncludesAreTheFilesText) {
    EXPECT_EQ(shadowGlsl(), std::string(glsl::file("shadow.glsl")));
    const std::string transparent = transparentGlsl();
    EXPECT_NE(transparent.find(std::string(glsl::file("transparent_lists.glsl"))), std::string::npos);
    EXPECT_EQ(transparent.find("#include"), std::string::npos);
    const Fog fog = *Fog::create(paperFig8Fog());
    const std::string fogSource = fogGlsl(fog)->source;
    EXPECT_EQ(fogSource.rfind(std::string(glsl::file("fog.glsl")), 0), 0u) << "fogGlsl starts with fog.glsl's text";
    const std::string partial = partialGlsl(Footprint({.partialRadialSize = 16, .partialDepthSize = 40}), 5);
    EXPECT_EQ(partial.find("SPLATFX_PARTIAL_"), std::string::npos) << "every constant substituted";
}

TEST(GlslFiles, FogKeysFollowTheStructureNotTheParameters) {
    FogDesc a;
    a.terms.push_back(FogTerm::constant(0.1));
    a.terms.push_back(FogTerm::point(0.3, {0.5, 0.2, -2.0}, 1.0, 2.0));
    FogDesc b = a;
    b.terms[0].weight = 0.2;
    b.terms[1].centre = {4.0, 0.0, 1.0};
    FogDesc c = a;
    c.terms.push_back(FogTerm::sphere(0.3, {1.0, 0.0, 0.0}, 2.0, 1.0, 2.0));
    const Fog fa = *Fog::create(a), fb = *Fog::create(b), fc = *Fog::create(c);
    EXPECT_NE(fa.glslKey(), 0u);
    EXPECT_EQ(fa.glslKey(), fb.glslKey());
    EXPECT_EQ(fogGlsl(fa)->source, fogGlsl(fb)->source);
    EXPECT_NE(fa.glslKey(), fc.glslKey());
}

} // namespace
} // namespace splatfx
