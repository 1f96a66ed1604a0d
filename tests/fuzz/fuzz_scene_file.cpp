// libFuzzer target for the scene-file parser: any bytes must give a scene or
// an error message, never a crash, hang or sanitizer report. Relative paths
// are anchored at samples/fuzz-anchor/ (a folder that need not exist, beside
// the samples): the seeds in corpus/scene_file/ are the samples' scenes with
// bare file names rewritten to ../NN-sample/name, so texture sets, images and
// meshes resolve and the loaders behind the parser run too.
#include <cstddef>
#include <cstdint>
#include <string>

#include "splatfx/scene_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    splatfx::Materials materials(splatfx::Footprint{});
    auto file = splatfx::parseSceneFile(text, SPLATFX_FUZZ_SCENE_ANCHOR, materials);
    if (!file && file.error().empty()) __builtin_trap(); // every failure must explain itself
    return 0;
}
