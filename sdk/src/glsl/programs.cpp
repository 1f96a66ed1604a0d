// The GL backend's programs as data (programs.hpp).
#include "glsl/programs.hpp"

#include <algorithm>
#include <array>

#include "glsl/glsl_files.hpp"

namespace splatfx::glsl {
namespace {

using Values = std::array<int, kMaxDefines>;

constexpr int kBool[] = {0, 1};
constexpr int kZero[] = {0};
constexpr int kOne[] = {1};
constexpr int kModes[] = {0, 1, 2};
constexpr int kSections[] = {2, 4, 8}; // FragmentListPass: 2, 4 and kTransparentMaxSections targets
// FragmentListPass's resolve keeps K = 1, 2, 4, ... up to its budget and the
// budget itself (FrameRendererDesc::fragmentsPerPixel, 1 to 128): every K is a
// variant a pass may ask for, so every one is listed (and compiled by the build's check).
constexpr auto kResolveK = [] {
    std::array<int, 128> k{};
    for (int i = 0; i < 128; ++i) k[std::size_t(i)] = i + 1;
    return k;
}();

constexpr const char* kSplatUniforms[] = {"uViewProj", "uOctagon", "uCut",   "uFogEye", "splatfx_fog_params", "splatfx_fog_colour", "splatfx_fog_far",
                                          "uEye",      "uForward", "uNearZ", "uPersp",  "uKernelRadius",      "uHostDepthMap",      "uInvViewProj",
                                          "uViewport", "uNdcZ"};
static_assert(std::size(kSplatUniforms) == splat::UniformCount);
constexpr const char* kDepthTilesUniforms[] = {"uHostDepthMap", "uTarget"};
static_assert(std::size(kDepthTilesUniforms) == depth_tiles::UniformCount);
constexpr const char* kDownsampleUniforms[] = {"uHostRect", "uScale", "uReversed"};
static_assert(std::size(kDownsampleUniforms) == downsample::UniformCount);
constexpr const char* kCompositeUniforms[] = {"uHostRect", "uViewportOrigin", "uScale", "uUseDepth", "uThreshold", "uHostDepthMap"};
static_assert(std::size(kCompositeUniforms) == composite::UniformCount);
constexpr const char* kFogPassUniforms[] = {"uRay",  "uDepthAxis", "uHostDepthMap", "uOrigin", "uSize", "splatfx_fog_params", "splatfx_fog_colour", "splatfx_fog_far",
                                            "uFogSize", "uThreshold"};
static_assert(std::size(kFogPassUniforms) == fog_pass::UniformCount);
constexpr const char* kTetraUniforms[] = {"uViewProjRel", "uFirst",     "uForward",           "uHostDepthMap",       "uTexScale",
                                          "uTexOffset",   "uMaxLength", "splatfx_fog_params", "splatfx_fog_colour", "splatfx_fog_far",
                                          "uSampleRay",   "uInvViewProjRel", "uViewport", "uNdcZ"};
static_assert(std::size(kTetraUniforms) == tetra::UniformCount);
constexpr const char* kSectionUniforms[] = {"uViewProj", "uOctagon", "uCut",          "uOrigin",      "uEye",         "uForward",
                                            "uNearZ",    "uPersp",   "uKernelRadius", "uHostDepthMap", "uInvViewProj", "uViewport",
                                            "uNdcZ",     "uReversed"};
static_assert(std::size(kSectionUniforms) == section::UniformCount);
constexpr const char* kListUniforms[] = {"uSize", "uLayers", "uTiles", "uOrigin", "uSectionCount", "uReversed"};
static_assert(std::size(kListUniforms) == lists::UniformCount);
constexpr const char* kDepthSampleUniforms[] = {"uSample", "uSamples", "uReversed"};
static_assert(std::size(kDepthSampleUniforms) == depth_sample::UniformCount);

// Renderer::Impl::program: FOG_PER_SPLAT only with FOG; the cut's variants only with CUT; GENERAL implies NEAR_CUT.
bool splatValid(const Values& v) {
    using namespace splat;
    if (v[FOG_PER_SPLAT] && !v[FOG]) return false;
    if (!v[CUT] && (v[HOST_DEPTH] || v[NEAR_CUT] || v[GENERAL])) return false;
    return !v[GENERAL] || v[NEAR_CUT];
}
unsigned splatGenerated(const Values& v) { return (v[splat::FOG] ? kFogTerms : 0u) | (v[splat::CUT] ? kPartialConstants : 0u); }
// FragmentListPass::Impl::buildSections: kinds plain, and cut with any of the
// near and host cuts; the general kind has both.
bool sectionValid(const Values& v) {
    using namespace section;
    if (!v[CUT] && (v[HOST_DEPTH] || v[NEAR_CUT] || v[GENERAL])) return false;
    return !v[GENERAL] || (v[NEAR_CUT] && v[HOST_DEPTH]);
}
unsigned sectionGenerated(const Values& v) { return v[section::CUT] ? kPartialConstants : 0u; }
unsigned fogAlways(const Values&) { return kFogTerms; }
unsigned tetraGenerated(const Values& v) { return v[tetra::FOG] ? kFogTerms : 0u; }

const ProgramDesc kDescs[] = {
    {.name = "splat",
     .vertex = "splat.vert",
     .fragment = "splat.frag",
     .defines = {"FOG", "FOG_PER_SPLAT", "CUT", "HOST_DEPTH", "NEAR_CUT", "GENERAL", "CROSSFADE"},
     .uniforms = kSplatUniforms,
     .values = {kBool, kBool, kBool, kBool, kBool, kBool, kBool},
     .valid = splatValid,
     .generated = splatGenerated},
    {.name = "splat depth cut (host depth tiles)", .vertex = "fullscreen.vert", .fragment = "depth_tiles.frag", .uniforms = kDepthTilesUniforms},
    {.name = "depth downsample", .vertex = "fullscreen.vert", .fragment = "depth_downsample.frag", .uniforms = kDownsampleUniforms},
    {.name = "upsample composite", .vertex = "fullscreen.vert", .fragment = "scaled_composite.frag", .uniforms = kCompositeUniforms},
    {.name = "fog pass",
     .vertex = "fullscreen.vert",
     .fragment = "fog_pass.frag",
     .defines = {"MODE"},
     .uniforms = kFogPassUniforms,
     .values = {kModes},
     .generated = fogAlways},
    {.name = "tetrahedra",
     .vertex = "tetra.vert",
     .fragment = "tetra.frag",
     .defines = {"PERSPECTIVE", "HAS_DEPTH", "FOG", "RGB"},
     .uniforms = kTetraUniforms,
     .values = {kBool, kBool, kBool, kBool},
     .generated = tetraGenerated},
    {.name = "fragment lists (splat sections)",
     .vertex = "splat.vert",
     .fragment = "list_section.frag",
     .defines = {"FOG", "FOG_PER_SPLAT", "CUT", "HOST_DEPTH", "NEAR_CUT", "GENERAL", "CROSSFADE", "SECTIONS"},
     .uniforms = kSectionUniforms,
     .values = {kZero, kZero, kBool, kBool, kBool, kBool, kOne, kSections},
     .valid = sectionValid,
     .generated = sectionGenerated},
    {.name = "fragment lists (prepare)", .compute = "list_prepare.comp", .uniforms = kListUniforms},
    {.name = "fragment lists (tile depth range)", .compute = "list_tile_range.comp", .uniforms = kListUniforms},
    {.name = "fragment lists (host depth tiles)", .compute = "list_host_tiles.comp", .uniforms = kListUniforms},
    {.name = "fragment lists (resolve)", .compute = "list_resolve.comp", .defines = {"K"}, .uniforms = kListUniforms, .values = {kResolveK}},
    {.name = "fragment lists (resolve, fragment)",
     .vertex = "fullscreen.vert",
     .fragment = "list_resolve.frag",
     .defines = {"K"},
     .uniforms = kListUniforms,
     .values = {kResolveK}},
    {.name = "fragment lists (composite)", .vertex = "fullscreen.vert", .fragment = "list_composite.frag", .uniforms = kListUniforms},
    {.name = "host depth sample", .vertex = "fullscreen.vert", .fragment = "depth_sample.frag", .uniforms = kDepthSampleUniforms},
};
static_assert(std::size(kDescs) == std::size_t(ProgramId::Count));

} // namespace

const ProgramDesc& programDesc(ProgramId id) { return kDescs[std::size_t(id)]; }

unsigned generatedParts(ProgramId id, const Values& values) {
    const ProgramDesc& d = programDesc(id);
    return d.generated ? d.generated(values) : kNoGenerated;
}

std::string variantName(const ProgramKey& key) {
    const ProgramDesc& d = programDesc(key.id);
    std::string s = d.name;
    if (!d.defines[0]) return s;
    s += " [";
    for (int i = 0; i < kMaxDefines && d.defines[std::size_t(i)]; ++i)
        s += std::string(i ? " " : "") + d.defines[std::size_t(i)] + "=" + std::to_string(key.values[std::size_t(i)]);
    return s + "]";
}

bool isCheckedVariant(const ProgramKey& key) {
    const ProgramDesc& d = programDesc(key.id);
    for (int i = 0; i < kMaxDefines; ++i) {
        const int v = key.values[std::size_t(i)];
        if (!d.defines[std::size_t(i)]) {
            if (v != 0) return false; // a value for a define the program does not have
            continue;
        }
        const auto& allowed = d.values[std::size_t(i)];
        if (std::find(allowed.begin(), allowed.end(), v) == allowed.end()) return false;
    }
    return !d.valid || d.valid(key.values);
}

Result<std::vector<StageSource>> programSources(const ProgramKey& key, const ProgramData& data) {
    const ProgramDesc& d = programDesc(key.id);
    // Only the variants the build's glslangValidator step compiled (forEachVariant) may reach a
    // driver: a pass asking for another is a bug, named here rather than compiled unchecked.
    if (!isCheckedVariant(key))
        return makeError(variantName(key) + ": not among the variants the build checks with glslangValidator (glsl/programs.cpp's values)");
    std::string head = "#version 450 core\n";
    for (int i = 0; i < kMaxDefines && d.defines[std::size_t(i)]; ++i)
        head += std::string("#define ") + d.defines[std::size_t(i)] + " " + std::to_string(key.values[std::size_t(i)]) + "\n";
    const unsigned gen = generatedParts(key.id, key.values);
    if ((gen & kFogTerms) && data.fog.empty()) return makeError(variantName(key) + ": needs the fog's GLSL (ProgramData::fog)");
    if ((gen & kPartialConstants) && data.partial.empty()) return makeError(variantName(key) + ": needs the footprint's GLSL (ProgramData::partial)");
    std::vector<StageSource> out;
    auto add = [&](Stage stage, const char* name) -> Status {
        if (!name) return {};
        // A generated include replaces its file only where the variant reads
        // it; elsewhere the file's own text sits in a skipped #if block.
        auto text = expand(name, {{(gen & kFogTerms) ? "fog.glsl" : "", data.fog}, {(gen & kPartialConstants) ? "partial.glsl" : "", data.partial}});
        if (!text) return makeError(variantName(key) + ": " + text.error());
        out.push_back({stage, name, head + *text});
        return {};
    };
    for (auto [stage, name] : {std::pair{Stage::Vertex, d.vertex}, {Stage::Fragment, d.fragment}, {Stage::Compute, d.compute}})
        if (Status s = add(stage, name); !s) return makeError(s.error());
    return out;
}

void forEachVariant(ProgramId id, const std::function<void(const Values&)>& fn) {
    const ProgramDesc& d = programDesc(id);
    int n = 0;
    while (n < kMaxDefines && d.defines[std::size_t(n)]) ++n;
    std::array<std::size_t, kMaxDefines> at{};
    for (;;) {
        Values v{};
        for (int i = 0; i < n; ++i) v[std::size_t(i)] = d.values[std::size_t(i)][at[std::size_t(i)]];
        if (!d.valid || d.valid(v)) fn(v);
        int i = 0;
        while (i < n && ++at[std::size_t(i)] == d.values[std::size_t(i)].size()) at[std::size_t(i++)] = 0;
        if (i == n) return;
    }
}

} // namespace splatfx::glsl
