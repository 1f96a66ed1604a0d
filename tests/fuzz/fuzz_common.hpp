// Shared by the fuzz targets: a scratch folder per process for targets whose
// code under test reads files (images, meshes, texture-set folders), removed
// at exit. The same targets run as plain regression tests (replay_main.cpp).
#pragma once

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace fuzz {

inline const std::filesystem::path& scratchDir() {
    static const std::filesystem::path dir = [] {
        // tmpfs where there is one: each input is written to a file, thousands a second.
        std::filesystem::path base = std::filesystem::exists("/dev/shm") ? "/dev/shm" : std::filesystem::temp_directory_path();
        auto d = base / ("splatfx-fuzz-" + std::to_string(getpid()));
        std::filesystem::create_directories(d);
        std::atexit([] {
            std::error_code ec;
            std::filesystem::remove_all(scratchDir(), ec);
        });
        return d;
    }();
    return dir;
}

inline std::string writeFile(const std::string& name, const std::uint8_t* data, std::size_t size) {
    const std::string path = (scratchDir() / name).string();
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    return path;
}

inline bool startsWith(const std::uint8_t* data, std::size_t size, std::string_view magic) {
    return size >= magic.size() && std::equal(magic.begin(), magic.end(), reinterpret_cast<const char*>(data));
}

} // namespace fuzz
