// libFuzzer target for texture-set manifests: the input is written as
// manifest.json into a folder beside 16 real 32x32 textures (t000.png ...
// t015.png, copied once from textures/turbulence-16x32), then
// loadTextureSet reads the folder. Any manifest must give a set or a
// message, never a crash, hang or sanitizer report.
#include <cstddef>
#include <cstdint>
#include <filesystem>

#include "fuzz_common.hpp"
#include "splatfx/texture_set_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    namespace fs = std::filesystem;
    static const fs::path folder = [] {
        const fs::path f = fuzz::scratchDir() / "set";
        fs::create_directories(f);
        for (const auto& e : fs::directory_iterator(fs::path(SPLATFX_SOURCE_DIR) / "textures" / "turbulence-16x32"))
            if (e.path().extension() == ".png") fs::copy_file(e.path(), f / e.path().filename(), fs::copy_options::overwrite_existing);
        return f;
    }();
    fuzz::writeFile("set/manifest.json", data, size);
    auto set = splatfx::loadTextureSet(folder.string());
    if (!set && set.error().empty()) __builtin_trap();
    return 0;
}
