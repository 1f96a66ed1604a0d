// Scene files: a solver effect's "obstacles" (obstacle.hpp), solids the gas
// flows around. An entry names a piece of the file's geometry (the host
// draws it, the solver flows around it: one description for both), or gives
// a shape of its own in the geometry list's keys.
#include "scenefile/reader.hpp"

#include "splatfx/obstacle.hpp"

namespace splatfx::scenefile {
namespace {

constexpr std::size_t kMaxObstacleVertices = 3 * 65536;

// An entry's "triangles": [[x, y, z], ...], three vertices a triangle.
std::vector<glm::vec3> readTriangles(Context& c, const std::string& path, const Json& v) {
    std::vector<glm::vec3> out;
    if (!v.is_array() || v.size() > kMaxObstacleVertices) {
        c.d.error(path, "expected an array of at most " + std::to_string(kMaxObstacleVertices) + " vertices ([x, y, z], three a triangle), got " +
                            typeName(v) + " " + brief(v));
        return out;
    }
    for (std::size_t i = 0; i < v.size() && !c.d.full(); ++i)
        if (auto p = readVec3(c.d, index(path, i), v[i], -kMaxCoord, kMaxCoord)) out.push_back(*p);
    return out;
}

std::optional<Obstacle> readObstacle(Context& c, const std::string& path, const Json& v) {
    ObjectReader o(c.d, path, v);
    if (!o.valid()) return std::nullopt;
    const std::size_t before = c.d.count();
    Obstacle ob;
    std::string slip = "free";
    if (const Json* s = o.get("slip"))
        if (auto choice = readChoice(c.d, o.at("slip"), *s, {"free", "none"})) slip = *choice;
    ob.desc.slip = slip == "none" ? Slip::None : Slip::Free;

    if (o.has("geometry")) {
        // The host's own object: its shape, placement and motion.
        for (const char* key : {"type", "size", "position", "rotationDeg", "scale", "triangles", "motion", "attachTo"})
            if (o.has(key)) c.d.error(o.at(key), "an obstacle naming \"geometry\" takes its shape and placement from it; remove \"" + std::string(key) + "\"");
        std::string name;
        o.string("geometry", name);
        o.finish();
        if (c.d.count() != before || !c.geometry) return std::nullopt;
        const std::optional<Anchor> a = resolveAnchor(c, *c.geometry, *c.geometryByName, name, o.at("geometry"));
        if (!a) return std::nullopt;
        const GeometryDesc& g = (*c.geometry)[c.geometryByName->at(name)].desc;
        switch (g.type) {
        case GeometryType::Box: ob.desc.shape = ObstacleShape::Box; break;
        case GeometryType::Plane: ob.desc.shape = ObstacleShape::Plane; break;
        case GeometryType::Sphere: ob.desc.shape = ObstacleShape::Sphere; break;
        case GeometryType::Cylinder: ob.desc.shape = ObstacleShape::Cylinder; break;
        default:
            c.d.error(o.at("geometry"), "geometry '" + name +
                                            "' is a mesh, heightmap or empty anchor, which the SDK does not load; name a box, plane, sphere or "
                                            "cylinder, or give the solid inline (\"type\": \"mesh\" with \"triangles\")");
            return std::nullopt;
        }
        ob.desc.size = g.size;
        ob.desc.transform = a->transform;
        ob.motion = a->motion;
    } else {
        o.touch("geometry"); // listed among the keys allowed when one is unknown
        if (!o.has("type")) c.d.error(path, "missing \"type\" (\"box\", \"plane\", \"sphere\", \"cylinder\" or \"mesh\") or \"geometry\" (a name)");
        if (const Json* t = o.get("type")) {
            if (auto s = readChoice(c.d, o.at("type"), *t, {"box", "plane", "sphere", "cylinder", "mesh"})) {
                const std::string& k = *s;
                ob.desc.shape = k == "box"      ? ObstacleShape::Box
                                : k == "plane"  ? ObstacleShape::Plane
                                : k == "sphere" ? ObstacleShape::Sphere
                                : k == "cylinder" ? ObstacleShape::Cylinder
                                                  : ObstacleShape::Mesh;
            }
        }
        o.vec3("size", ob.desc.size, 1e-4, kMaxCoord, true);
        ob.desc.transform = readPlacement(o, true);
        if (const Json* t = o.get("triangles")) {
            if (ob.desc.shape != ObstacleShape::Mesh) c.d.error(o.at("triangles"), "\"triangles\" belongs to \"type\": \"mesh\"");
            ob.desc.triangles = readTriangles(c, o.at("triangles"), *t);
        } else if (ob.desc.shape == ObstacleShape::Mesh && o.has("type")) {
            c.d.error(path, "missing \"triangles\" (the mesh's vertices, [x, y, z], three a triangle)");
        }
        std::string attachTo;
        o.string("attachTo", attachTo);
        if (const Json* m = o.get("motion")) {
            if (!attachTo.empty()) c.d.error(o.at("motion"), "an obstacle either has its own \"motion\" or is attached to geometry; not both");
            if (auto mo = readMotion(c, o.at("motion"), *m)) ob.motion = std::move(*mo);
        }
        o.finish();
        if (c.d.count() != before) return std::nullopt;
        if (!attachTo.empty()) {
            if (!c.geometry) return std::nullopt;
            const std::optional<Anchor> a = resolveAnchor(c, *c.geometry, *c.geometryByName, attachTo, o.at("attachTo"));
            if (!a) return std::nullopt;
            ob.motion = a->motion;
            ob.desc.transform = a->transform * ob.desc.transform;
        }
    }
    if (Status st = validateObstacle(ob.desc); !st) {
        // The SDK names the desc field; the file's key is what the user edits.
        std::string msg = st.error();
        if (msg.rfind("ObstacleDesc.", 0) == 0) msg = msg.substr(13);
        c.d.error(path, msg);
        return std::nullopt;
    }
    return ob;
}

} // namespace

std::optional<std::vector<Obstacle>> readObstacles(Context& c, const std::string& path, const Json& v) {
    if (!v.is_array() || v.size() > 4096) {
        c.d.error(path, "expected an array of at most 4096 obstacles, got " + typeName(v) + " " + brief(v));
        return std::nullopt;
    }
    std::vector<Obstacle> out;
    const std::size_t before = c.d.count();
    for (std::size_t i = 0; i < v.size() && !c.d.full(); ++i)
        if (auto ob = readObstacle(c, index(path, i), v[i])) out.push_back(std::move(*ob));
    if (c.d.count() != before) return std::nullopt;
    return out;
}

} // namespace splatfx::scenefile
