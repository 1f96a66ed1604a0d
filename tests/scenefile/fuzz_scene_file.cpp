// libFuzzer target for the scene-file parser: any bytes must give a scene or
// an error message, never a crash, hang or sanitizer report.
#include <cstddef>
#include <cstdint>
#include <string>

#include "splatfx/scene_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    splatfx::Materials materials(splatfx::Footprint{});
    // The path anchors relative paths at the corpus folder's samples if run from the repository root.
    auto file = splatfx::parseSceneFile(text, "fuzz/scene.json", materials);
    if (!file && file.error().empty()) __builtin_trap(); // every failure must explain itself
    return 0;
}
