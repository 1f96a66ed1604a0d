// Geometry type "mesh": a model file the host loads (docs/scene-format.md).
#include <filesystem>

#include "scenefile/kinds.hpp"

namespace splatfx::scenefile {

void readMeshGeometry(Context& c, ObjectReader& o, GeometryDesc& desc) {
    std::string mesh;
    if (!o.has("mesh")) c.d.error(o.path(), "missing \"mesh\" (a model file, relative to the scene file)");
    o.string("mesh", mesh);
    if (!mesh.empty()) {
        desc.meshPath = resolvePath(c, mesh);
        std::error_code ec;
        if (!std::filesystem::is_regular_file(desc.meshPath, ec))
            c.d.error(o.at("mesh"), "mesh file '" + mesh + "' not found (looked for '" + desc.meshPath + "')");
    }
    o.number("fitSize", desc.fitSize, 0.0, kMaxCoord);
}

} // namespace splatfx::scenefile
