// Texture-set folders (manifest.json plus images) in and out of files:
// loadTextureSet and saveTextureSet. They read and write images through
// OpenImageIO, so they live in splatfx::io, not in the GL-free, file-free
// core (sdk/src/texture holds the in-memory and procedural parts).
#include "splatfx/texture_set_io.hpp"

#include "splatfx/image_io.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include <nlohmann/json.hpp>

namespace splatfx {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {
constexpr std::uintmax_t kMaxManifestBytes = 1u << 20; // 1 MiB: 4096 names and provenance fit with room to spare
} // namespace

Result<TextureSet> loadTextureSet(const std::string& folder) {
    const fs::path dir(folder);
    const fs::path manifestPath = dir / "manifest.json";
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) return makeError("texture set '" + folder + "': no such folder");
    // The manifest is small text: a FIFO, a device or a huge file is refused before reading.
    if (fs::exists(manifestPath, ec) && !fs::is_regular_file(manifestPath, ec)) return makeError(manifestPath.string() + ": not a regular file");
    if (fs::is_regular_file(manifestPath, ec) && fs::file_size(manifestPath, ec) > kMaxManifestBytes)
        return makeError(manifestPath.string() + ": larger than " + std::to_string(kMaxManifestBytes) + " bytes; not a texture-set manifest");
    std::ifstream in(manifestPath);
    if (!in) return makeError("texture set '" + folder + "': cannot open manifest.json");
    json m;
    try {
        m = json::parse(in);
    } catch (const json::exception& e) { return makeError(manifestPath.string() + ": not valid JSON (" + e.what() + ")"); }
    const std::string where = manifestPath.string() + ": ";
    if (!m.is_object()) return makeError(where + "expected a JSON object at the top level");
    if (m.value("format", std::string()) != "splatfx-texture-set") return makeError(where + "field 'format' must be \"splatfx-texture-set\"");
    if (!m.contains("version") || !m["version"].is_number_integer() || m["version"].get<int>() != 1)
        return makeError(where + "field 'version' must be 1 (this build reads texture-set version 1)");
    if (!m.contains("textures") || !m["textures"].is_array() || m["textures"].empty())
        return makeError(where + "field 'textures' must be a non-empty array of image file names");
    if (m["textures"].size() > 4096) return makeError(where + "field 'textures' lists more than 4096 images");
    // Every field the manifest states is checked against the files, not trusted.
    for (const char* flag : {"color", "windowed"})
        if (m.contains(flag) && !m[flag].is_boolean()) return makeError(where + "field '" + flag + "' must be true or false");
    const bool color = m.contains("color") && m["color"].get<bool>();
    const bool windowed = m.contains("windowed") && m["windowed"].get<bool>();
    int statedSize = 0;
    if (m.contains("size")) {
        if (!m["size"].is_number_integer() || m["size"].get<long long>() < 1 || m["size"].get<long long>() > 4096)
            return makeError(where + "field 'size' must be a whole number of pixels in [1, 4096]");
        statedSize = m["size"].get<int>();
    }
    if (m.contains("count") && (!m["count"].is_number_integer() || m["count"].get<long long>() != (long long)m["textures"].size()))
        return makeError(where + "field 'count' says " + m["count"].dump() + " but 'textures' lists " + std::to_string(m["textures"].size()));
    std::vector<Image> images;
    for (size_t i = 0; i < m["textures"].size(); ++i) {
        const json& t = m["textures"][i];
        const std::string at = where + "textures[" + std::to_string(i) + "]";
        if (!t.is_string()) return makeError(at + " must be a file name string");
        // Entries are confined to the set's folder: a plain file name, never a path out of it.
        const std::string name = t.get<std::string>();
        if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos || name.find('\\') != std::string::npos)
            return makeError(at + " '" + name + "' must be a file name inside the set's folder (no '/', not '..')");
        const fs::path file = dir / name;
        // Windowed sets store straight colour with opacity in alpha; raw sets
        // made from photos keep alpha as coverage (composited over black).
        auto img = readImage(file.string(), windowed ? Alpha::Straight : Alpha::Premultiplied);
        if (!img) return makeError("texture set '" + folder + "': " + img.error());
        if (statedSize > 0 && (img->width != statedSize || img->height != statedSize))
            return makeError(at + " '" + name + "' is " + std::to_string(img->width) + "x" + std::to_string(img->height) +
                             ", but field 'size' says " + std::to_string(statedSize));
        if (windowed && img->channels != 4 && img->channels != 2)
            return makeError(at + " '" + name + "' has no alpha channel, but field 'windowed' says the detail is stored in alpha");
        images.push_back(std::move(*img));
    }
    auto set = TextureSet::fromImages(images, color);
    if (!set) return makeError("texture set '" + folder + "': " + set.error());
    if (windowed) {
        // A windowed set stores the footprint-weighted detail in alpha.
        for (size_t k = 0; k < images.size(); ++k) {
            const Image& img = images[k];
            for (int p = 0; p < set->size * set->size; ++p) {
                float* t = &set->layers[k][size_t(p) * 4];
                const float a = img.channels == 4 ? img.pixels[size_t(p) * 4 + 3] : img.pixels[size_t(p) * img.channels];
                t[3] = a;
                // Alpha is opacity here, not coverage: colour stays as stored.
                for (int c = 0; c < 3; ++c)
                    t[c] = !color ? 1.0f : std::clamp(img.pixels[size_t(p) * img.channels + size_t(std::min(c, img.channels - 1))], 0.0f, 1.0f);
            }
        }
        set->isWindowed = true;
    }
    return set;
}

Status saveTextureSet(const TextureSet& set, const std::string& folder, const std::string& provenanceJson) {
    if (set.layers.empty()) return makeError("cannot save texture set '" + folder + "': it has no textures");
    json provenance;
    try {
        provenance = json::parse(provenanceJson);
    } catch (const json::exception& e) {
        return makeError("cannot save texture set '" + folder + "': provenance is not valid JSON (" + e.what() + ")");
    }
    const fs::path target = fs::path(folder).lexically_normal();
    const fs::path parent = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    std::error_code ec;
    fs::create_directories(parent, ec);
    // Built with append() rather than "." + name: GCC 12 warns falsely (-Wrestrict) on the latter.
    std::string tmpName = ".";
    tmpName.append(target.filename().string()).append(".tmp-").append(std::to_string(getpid()));
    const fs::path tmp = parent / tmpName;
    fs::remove_all(tmp, ec);
    if (!fs::create_directory(tmp, ec)) return makeError("cannot create '" + tmp.string() + "': " + ec.message());
    auto fail = [&](const std::string& why) {
        fs::remove_all(tmp, ec);
        return Status(makeError("cannot save texture set '" + folder + "': " + why));
    };
    json m;
    m["format"] = "splatfx-texture-set";
    m["version"] = 1;
    m["color"] = set.color;
    m["windowed"] = set.isWindowed;
    m["size"] = set.size;
    m["textures"] = json::array();
    for (size_t k = 0; k < set.layers.size(); ++k) {
        char name[32];
        std::snprintf(name, sizeof name, "t%03zu.png", k);
        Image img;
        img.width = img.height = set.size;
        img.channels = set.isWindowed ? 4 : (set.color ? 3 : 1);
        img.pixels.resize(size_t(set.size) * set.size * img.channels);
        for (int p = 0; p < set.size * set.size; ++p)
            for (int c = 0; c < img.channels; ++c) {
                const float* t = &set.layers[k][size_t(p) * 4];
                img.pixels[size_t(p) * img.channels + c] = t[img.channels == 1 ? 0 : c];
            }
        // Windowed RGBA: alpha is opacity, colour is independent of it.
        if (Status s = writeImage((tmp / name).string(), img, Alpha::Straight); !s) return fail(s.error());
        m["textures"].push_back(name);
    }
    m["provenance"] = provenance;
    {
        std::ofstream out(tmp / "manifest.json");
        out << m.dump(2) << "\n";
        if (!out) return fail("cannot write manifest.json");
    }
    std::string oldName = "."; // append(), not "." + name: the same false GCC 12 -Wrestrict as above
    oldName.append(target.filename().string()).append(".old-").append(std::to_string(getpid()));
    const fs::path old = parent / oldName;
    if (fs::exists(target, ec)) {
        fs::rename(target, old, ec);
        if (ec) return fail("cannot replace the existing folder: " + ec.message());
    }
    fs::rename(tmp, target, ec);
    if (ec) {
        fs::rename(old, target, ec);
        return fail("cannot move the finished set into place");
    }
    fs::remove_all(old, ec);
    return {};
}

} // namespace splatfx
