// splatfx/budget.hpp: the resource budgets loaders check before they allocate.
//
// A scene file, a mesh or a texture request states sizes that cost memory and
// time in proportion (a lattice's cells, a solver's cells simulated every
// step, texels cut from an image, texture layers the GL must hold, a mesh's
// vertices and faces). Every loader estimates that cost from what the input
// states, before reading the data, and refuses an estimate over its budget
// with a message naming the input, the estimate, the budget and the field of
// Budgets that raises it. The defaults fit a 2-core, 8 GB machine with room
// to spare; raise a field explicitly (SceneFileOptions::budgets, or
// `splatfx-render --budget NAME=N`) for bigger work. Hard limits that are not
// budgets stay constants: kMaxVoxels (grid.hpp, a grid builder's cap: beyond
// it a size is a unit mistake), kMaxImageSide / kMaxImagePixels (image.hpp,
// checked on every image header).
// It does not measure memory in use or time anything.
//
//   splatfx::SceneFileOptions o;
//   o.budgets.solverCells = 1u << 20;                    // a bigger smoke domain, knowingly
//   auto file = splatfx::loadSceneFile(path, materials, o);
//
// Threading: plain values and pure functions.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "splatfx/grid.hpp"
#include "splatfx/result.hpp"

namespace splatfx {

struct Budgets {
    // Cells one grid or gas effect evaluates per update, and all of a
    // scene's effects together; at most kMaxVoxels. Default kMaxVoxels (2^24).
    std::uint64_t effectCells = kMaxVoxels;
    // Cells of one solver effect: every cell is simulated every step. Default 2^18.
    std::uint64_t solverCells = 1ull << 18;
    // Texels one effect's sampleImage cuts (count x size^2). Default 2^24.
    std::uint64_t sampledTexels = 1ull << 24;
    // Distinct texture layers a scene's materials hold: 2048 is every GL 4.5's
    // GL_MAX_ARRAY_TEXTURE_LAYERS minimum. Default 2048.
    std::uint64_t textureLayers = 2048;
    // Vertices or faces a mesh file's header may claim (checked before the
    // mesh library reads it). Default 2 * 10^7.
    std::uint64_t meshElements = 20'000'000;
    // Bytes of one mesh file. Default 512 MiB.
    std::uint64_t meshFileBytes = 512ull << 20;
    // Memory and wall-clock seconds the mesh library may use on one file: it
    // runs in a child process held to these, so a file that makes it crash,
    // hang or allocate without bound is an error. Defaults 4 GiB and 60 s.
    std::uint64_t meshImportBytes = 4ull << 30;
    std::uint64_t meshImportSeconds = 60;
    // Bytes of GLSL a scene's fog terms generate (fogGlsl's source less the
    // closed forms every fog shares): polynomials are generated code (about
    // 1.7 KB a degree-9 term), cosines and potentials one loop each whatever
    // their count. Every pass that fogs compiles it, in time growing faster
    // than its size (docs/fog.md, "What a fog's shader costs"). Default 2^15
    // (32 KiB, about 18 degree-9 polynomial terms).
    std::uint64_t fogShaderBytes = 1ull << 15;
    // Vertices of one heightmap geometry's mesh (the image's width x height,
    // read from its header before it is decoded); a host's mesh costs about
    // 100 bytes a vertex (positions, normals, indices, the GL's copy).
    // Default 2 * 10^7 (a 4097^2 heightmap fits).
    std::uint64_t heightmapVertices = 20'000'000;
    // Bytes of a scene's shadow tables: every light x every table-lit
    // effect's self-shadowing table, plus the scene shadow, each at
    // ShadowTable::memoryBytes (17 bytes an entry). Default 1 GiB.
    std::uint64_t lightingBytes = 1ull << 30;
    // Bytes of a scene's volumes (clouds and ground fog), summed: what each
    // keeps (LodVolume::bytesFor, GroundFog::bytesFor, its pre-integration
    // table) plus the tetrahedra one frame emits when fully refined (the
    // worst a camera can ask for), at what the frame and the GL pass hold
    // for each. Default 2 GiB.
    std::uint64_t volumeBytes = 2ull << 30;
};

// The fields by name, in declaration order, for messages and command lines.
std::vector<std::string> budgetNames();

// OK when estimate <= budget; otherwise the error
// "<what> needs <estimate> <unit>, over the budget of <budget> (raise Budgets::<field>)".
Status checkBudget(std::string_view what, std::uint64_t estimate, std::string_view unit, std::uint64_t budget, std::string_view field);

// "NAME=N" (NAME a field of Budgets, N a whole number >= 1) into budgets.
// Fails naming the unknown field or the bad number; budgets is unchanged then.
Status setBudget(Budgets& budgets, std::string_view assignment);

} // namespace splatfx
