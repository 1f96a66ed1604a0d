// libFuzzer target for meshes through the scene host's loader
// (tools/scenehost/mesh.cpp, assimp behind it). The bytes are written to a
// file whose extension follows their first word (ply, OFF, solid/binary STL,
// else OBJ), then loaded. Any bytes must give a mesh or a message.
#include <cstddef>
#include <cstdint>

#include "fuzz_common.hpp"
#include "mesh.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using fuzz::startsWith;
    const char* ext = startsWith(data, size, "ply")                                     ? ".ply"
                      : startsWith(data, size, "OFF") || startsWith(data, size, "COFF") ? ".off"
                      : startsWith(data, size, "solid") || (size >= 84 && data[0] == 0) ? ".stl"
                                                                                        : ".obj";
    const std::string path = fuzz::writeFile(std::string("mesh") + ext, data, size);
    // The mesh library's child process is held well inside libFuzzer's limits (-timeout=10,
    // -malloc_limit_mb=2048), so what it contains is never reported as this process's finding.
    splatfx::Budgets budgets;
    budgets.meshImportSeconds = 5;
    budgets.meshImportBytes = 1ull << 30;
    auto mesh = scenehost::loadMesh(path, budgets);
    if (!mesh && mesh.error().empty()) __builtin_trap();
    if (mesh)
        for (unsigned i : mesh->indices)
            if (i >= mesh->positions.size()) __builtin_trap(); // an index past the vertices would crash the renderer
    return 0;
}
