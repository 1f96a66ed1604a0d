// Scene files: the geometry list and attachment chains. Each type's own keys
// are read by its row in kinds.cpp (kinds/mesh.cpp, ...).
#include <algorithm>

#include "scenefile/kinds.hpp"
#include "scenefile/reader.hpp"

namespace splatfx::scenefile {

std::optional<Anchor> resolveAnchor(Context& c, const std::vector<RawGeometry>& geo, const std::map<std::string, std::size_t>& byName,
                                    const std::string& name, const std::string& atPath) {
    Anchor a;
    std::vector<std::size_t> chain;
    std::string cur = name;
    for (int depth = 0; !cur.empty(); ++depth) {
        auto it = byName.find(cur);
        if (it == byName.end()) {
            std::vector<std::string> names;
            for (const auto& [n, i] : byName) names.push_back(n);
            const std::string near = closest(cur, names);
            c.d.error(atPath, "no geometry named '" + cur + "'" + (near.empty() ? "" : " (did you mean '" + near + "'?)") +
                                  "; attachTo names an entry of \"geometry\"");
            return std::nullopt;
        }
        if (depth >= kMaxAttachDepth || std::find(chain.begin(), chain.end(), it->second) != chain.end()) {
            c.d.error(atPath, "attachment chain through '" + name + "' loops or is deeper than " + std::to_string(kMaxAttachDepth));
            return std::nullopt;
        }
        chain.push_back(it->second);
        cur = geo[it->second].attachTo;
    }
    // Root first: world = rootMotion(t) * T_root * ... * T_parent.
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) a.transform = a.transform * geo[*it].desc.transform;
    a.motion = geo[chain.back()].desc.motion;
    return a;
}

std::vector<RawGeometry> readGeometryList(Context& c, const std::string& path, const Json& v) {
    std::vector<RawGeometry> out;
    if (!v.is_array() || v.size() > kMaxGeometry) {
        c.d.error(path, "expected an array of at most " + std::to_string(kMaxGeometry) + " objects, got " + typeName(v) + " " + brief(v));
        return out;
    }
    const std::vector<std::string> types = geometryKindNames();
    std::string typeList; // "\"plane\", \"box\", ... or \"empty\""
    for (std::size_t i = 0; i < types.size(); ++i) typeList += (i == 0 ? "" : i + 1 == types.size() ? " or " : ", ") + ("\"" + types[i] + "\"");
    for (std::size_t i = 0; i < v.size() && !c.d.full(); ++i) {
        RawGeometry g;
        g.path = index(path, i);
        ObjectReader o(c.d, g.path, v[i]);
        if (!o.valid()) continue;
        g.desc.name = "geometry[" + std::to_string(i) + "]";
        o.string("name", g.desc.name);
        // A missing or unknown type is reported; the object is read on as a box.
        const GeometryKind* kind = findGeometryKind("box");
        if (!o.has("type")) c.d.error(g.path, "missing \"type\" (" + typeList + ")");
        if (const Json* t = o.get("type"))
            if (auto s = readChoice(c.d, o.at("type"), *t, types)) kind = findGeometryKind(*s);
        g.desc.type = kind->type;
        if (kind->read) kind->read(c, o, g.desc);
        o.vec3("size", g.desc.size, 1e-4, kMaxCoord, true);
        g.desc.transform = readPlacement(o, true);
        o.color3("color", g.desc.color);
        o.number("opacity", g.desc.opacity, 0.0, 1.0); // (issue 15) transparent surfaces
        if (const Json* m = o.get("motion")) {
            g.hasOwnMotion = true;
            if (auto mo = readMotion(c, o.at("motion"), *m)) g.desc.motion = std::move(*mo);
        }
        o.string("attachTo", g.attachTo);
        if (g.hasOwnMotion && !g.attachTo.empty())
            c.d.error(o.at("attachTo"), "an object either has its own \"motion\" or is attached to another; not both");
        o.finish();
        out.push_back(std::move(g));
    }
    return out;
}

} // namespace splatfx::scenefile
