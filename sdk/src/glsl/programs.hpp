// The GL backend's programs as plain data: which GLSL files each one is built
// from, which #defines select its variants, the uniforms it looks up once,
// and every variant a pass may ask for. GL-free, so the build-time check
// (sdk/glsl_check, glslangValidator) assembles exactly the text the passes
// compile; render/gl/program_library.hpp links it.
//
//   glsl::ProgramKey key{glsl::ProgramId::Tetra, {1, 0, 1}, fogKey};  // PERSPECTIVE 1, HAS_DEPTH 0, FOG 1
//   auto stages = glsl::programSources(key, {.fog = fogSource});
//
// Threading: pure functions; any thread.
#pragma once

#include <array>
#include <compare>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "splatfx/result.hpp"

namespace splatfx::glsl {

enum class ProgramId : std::uint8_t {
    Splat,           // splat.vert + splat.frag (Renderer)
    DepthTiles,      // fullscreen.vert + depth_tiles.frag (Renderer, the cut's host depth tiles)
    DepthDownsample, // fullscreen.vert + depth_downsample.frag (ScaledRenderer)
    ScaledComposite, // fullscreen.vert + scaled_composite.frag (ScaledRenderer)
    FogPass,         // fullscreen.vert + fog_pass.frag (FogPass)
    Tetra,           // tetra.vert + tetra.frag (TetraPass)
    ListSection,     // splat.vert + list_section.frag (FragmentListPass)
    ListPrepare,     // list_prepare.comp
    ListTileRange,   // list_tile_range.comp
    ListHostTiles,   // list_host_tiles.comp
    ListResolve,     // list_resolve.comp
    ListResolveFrag, // fullscreen.vert + list_resolve.frag
    ListComposite,   // fullscreen.vert + list_composite.frag
    DepthSample,     // fullscreen.vert + depth_sample.frag (HostPass: a multisampled host depth, one sample at a time)
    Count
};

inline constexpr int kMaxDefines = 8;

// Which generated include a program reads (ProgramData).
enum Generated : unsigned { kNoGenerated = 0, kFogTerms = 1, kPartialConstants = 2 };

struct ProgramDesc {
    const char* name = "";        // in messages
    const char* vertex = nullptr; // file names; compute alone, or vertex + fragment
    const char* fragment = nullptr;
    const char* compute = nullptr;
    std::array<const char*, kMaxDefines> defines{}; // the #defines of the key's values, in order (nullptr: unused)
    std::span<const char* const> uniforms;          // looked up once per program, in this order (the U* enums below)
    // Values each define may take in a variant a pass asks for (the build check's list).
    std::array<std::span<const int>, kMaxDefines> values{};
    bool (*valid)(const std::array<int, kMaxDefines>&) = nullptr; // which combinations a pass asks for (nullptr: all)
    // Which generated includes a variant reads, from its define values.
    unsigned (*generated)(const std::array<int, kMaxDefines>&) = nullptr;
};
const ProgramDesc& programDesc(ProgramId id);

// One variant: the program, its define values, and a key of the generated
// includes it was built from (0: none). Cheap to compare: the program library's cache key.
struct ProgramKey {
    ProgramId id = ProgramId::Splat;
    std::array<int, kMaxDefines> values{};
    std::uint64_t dataKey = 0;
    auto operator<=>(const ProgramKey&) const = default;
};

// The generated includes (whichever the variant reads, by programDesc().generated).
struct ProgramData {
    std::string_view fog = {};     // fogGlsl(fog)->source: replaces fog.glsl
    std::string_view partial = {}; // partialGlsl(footprint, binding): replaces partial.glsl
};

enum class Stage { Vertex, Fragment, Compute };
struct StageSource {
    Stage stage;
    const char* file; // the stage's file (messages, the build check's names)
    std::string text; // complete: #version, the defines, the expanded file
};
// Every stage's full source for `key`.
Result<std::vector<StageSource>> programSources(const ProgramKey& key, const ProgramData& data);
// "splat [FOG=1 CUT=0 ...]", for messages.
std::string variantName(const ProgramKey& key);
// Whether the key is one forEachVariant lists (the build checks exactly those); programSources
// refuses any other.
bool isCheckedVariant(const ProgramKey& key);
// Calls fn with the define values of every variant of `id` a pass may ask for.
void forEachVariant(ProgramId id, const std::function<void(const std::array<int, kMaxDefines>&)>& fn);
// Which generated includes the variant reads.
unsigned generatedParts(ProgramId id, const std::array<int, kMaxDefines>& values);

// Uniform indices per program (ProgramDesc::uniforms order).
namespace splat {
enum Define { FOG, FOG_PER_SPLAT, CUT, HOST_DEPTH, NEAR_CUT, GENERAL, CROSSFADE };
enum Uniform {
    ViewProj,
    Octagon,
    Cut,
    FogEye,
    FogParams,
    FogColour,
    FogFar,
    Eye,
    Forward,
    NearZ,
    Persp,
    KernelRadius,
    HostDepthMap,
    InvViewProj,
    Viewport,
    NdcZ,
    UniformCount
};
} // namespace splat
namespace depth_tiles {
enum Uniform { HostDepthMap, Target, UniformCount };
}
namespace downsample {
enum Uniform { HostRect, Scale, Reversed, UniformCount };
}
namespace composite {
enum Uniform { HostRect, ViewportOrigin, Scale, UseDepth, Threshold, HostDepthMap, UniformCount };
}
namespace fog_pass {
enum Define { MODE };
enum Uniform { Ray, DepthAxis, HostDepthMap, Origin, Size, FogParams, FogColour, FogFar, FogSize, Threshold, UniformCount };
} // namespace fog_pass
namespace tetra {
enum Define { PERSPECTIVE, HAS_DEPTH, FOG, RGB };
enum Uniform { ViewProjRel, First, Forward, HostDepthMap, TexScale, TexOffset, MaxLength, FogParams, FogColour, FogFar, SampleRay, InvViewProjRel, Viewport, NdcZ, UniformCount };
} // namespace tetra
namespace section {
enum Define { FOG, FOG_PER_SPLAT, CUT, HOST_DEPTH, NEAR_CUT, GENERAL, CROSSFADE, SECTIONS };
enum Uniform { ViewProj, Octagon, Cut, Origin, Eye, Forward, NearZ, Persp, KernelRadius, HostDepthMap, InvViewProj, Viewport, NdcZ, Reversed, UniformCount };
} // namespace section
namespace depth_sample {
enum Uniform { Sample, Samples, Reversed, UniformCount };
}
namespace lists { // prepare, tile range, host tiles, resolve (both), composite
enum Define { K };
enum Uniform { Size, Layers, Tiles, Origin, SectionCount, Reversed, UniformCount };
} // namespace lists

} // namespace splatfx::glsl
