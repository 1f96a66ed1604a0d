// Geometry type "heightmap": a terrain grid from an image the host
// turns into triangles (docs/scene-format.md; GeometryDesc::heightmapPath).
#include <filesystem>

#include "scenefile/kinds.hpp"
#include "splatfx/image_io.hpp"

namespace splatfx::scenefile {

void readHeightmapGeometry(Context& c, ObjectReader& o, GeometryDesc& desc) {
    std::string file;
    if (!o.has("heightmap")) c.d.error(o.path(), "missing \"heightmap\" (an image file, e.g. a 16-bit PGM, relative to the scene file)");
    o.string("heightmap", file);
    if (!file.empty()) {
        desc.heightmapPath = resolvePath(c, file);
        std::error_code ec;
        if (!std::filesystem::is_regular_file(desc.heightmapPath, ec)) {
            c.d.error(o.at("heightmap"), "heightmap file '" + file + "' not found (looked for '" + desc.heightmapPath + "')");
        } else if (auto info = readImageInfo(desc.heightmapPath); !info) {
            c.d.error(o.at("heightmap"), info.error());
        } else {
            // The host builds a vertex per sample: its cost follows from the
            // header alone, checked before the image is decoded.
            const std::uint64_t vertices = std::uint64_t(info->width) * std::uint64_t(info->height);
            if (Status s = checkBudget("'" + file + "' (" + std::to_string(info->width) + "x" + std::to_string(info->height) + ") as a mesh",
                                       vertices, "vertices", c.budgets.heightmapVertices, "heightmapVertices");
                !s)
                c.d.error(o.at("heightmap"), s.error());
        }
    }
    o.number("spacing", desc.heightmapSpacing, 1e-4, 1e4);
    o.number("heightScale", desc.heightmapScale, -1e6, 1e6);
}

} // namespace splatfx::scenefile
