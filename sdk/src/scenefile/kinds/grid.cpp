// Effect kind "grid" (Fig. 9, 11): a hand-shaped grid with the full
// Effect::fromGrid control. The shapes are voxelized by voxelizeShapes
// (splatfx/shapes.hpp); this file reads them.
#include "scenefile/kinds.hpp"
#include "splatfx/shapes.hpp"

namespace splatfx::scenefile {
namespace {

// One entry of "shapes", in lattice cells.
void readShape(Context& c, ObjectReader& o, Shape& s) {
    const std::string& path = o.path();
    std::string type;
    if (const Json* t = o.get("type")) {
        if (auto x = readChoice(c.d, o.at("type"), *t, {"box", "sphere", "cylinder", "cone"})) type = *x;
    } else {
        c.d.error(path, "missing \"type\" (\"box\", \"sphere\", \"cylinder\" or \"cone\")");
    }
    const double L = kMaxAxis;
    auto need = [&](const char* key) {
        if (!o.has(key)) c.d.error(path, std::string("missing \"") + key + "\" for a " + type);
    };
    if (type == "box") {
        s.type = ShapeType::Box;
        need("min"), need("max");
        o.vec3("min", s.from, -L, L);
        o.vec3("max", s.to, -L, L);
    } else if (type == "sphere") {
        s.type = ShapeType::Sphere;
        need("center"), need("radius");
        o.vec3("center", s.from, -L, L);
        o.number("radius", s.radiusFrom, 0.0, L);
    } else if (type == "cylinder" || type == "cone") {
        s.type = ShapeType::Cone;
        need("from"), need("to");
        o.vec3("from", s.from, -L, L);
        o.vec3("to", s.to, -L, L);
        if (type == "cylinder") {
            need("radius");
            o.number("radius", s.radiusFrom, 0.0, L);
            s.radiusTo = s.radiusFrom;
        } else {
            need("radiusFrom"), need("radiusTo");
            o.number("radiusFrom", s.radiusFrom, 0.0, L);
            o.number("radiusTo", s.radiusTo, 0.0, L);
        }
    }
    o.number("opacity", s.opacity, 0.0, 1.0);
    o.number("softCells", s.softCells, 0.05, L);
}

} // namespace

// A hand-shaped grid effect: the full Effect::fromGrid control.
std::optional<Effect> readGridKind(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    glm::ivec3 dims{7, 20, 5};
    glm::vec3 spacing(0.5f);
    if (!o.has("dims")) c.d.error(o.path(), "missing \"dims\" (lattice cells [x, y, z]) for kind \"grid\"");
    readDims(c, o, dims, c.budgets.effectCells, "effectCells", "grid effects");
    o.vec3("spacing", spacing, 1e-4, 1e3, true);
    const glm::mat4 local = readPlacement(o, false);
    std::vector<Shape> shapes;
    if (const Json* s = o.get("shapes")) {
        if (!s->is_array() || s->size() > 256) c.d.error(o.at("shapes"), "expected an array of at most 256 shapes, got " + brief(*s));
        else
            for (std::size_t i = 0; i < s->size(); ++i)
                if (auto sh = readObject<Shape>(c, index(o.at("shapes"), i), (*s)[i], readShape)) shapes.push_back(*sh);
    }
    float opacity = 0.5f, fadeTo = 1.0f;
    glm::vec3 colorAxis(0, 1, 0);
    o.number("opacity", opacity, 0.0, 1.0);
    o.vec3("colorAxis", colorAxis, -1.0, 1.0);
    o.number("fadeTo", fadeTo, 0.0, 1.0);
    if (glm::length(colorAxis) < 1e-6f) c.d.error(o.at("colorAxis"), "must be non-zero");
    std::optional<TextureSpec> tex;
    if (const Json* t = o.get("textureSet")) tex = readTextureSpec(c, o.at("textureSet"), *t, 8, e.seed, false);
    else {
        tex.emplace();
        tex->seed = e.seed;
    }
    std::optional<ColorTable> table = ColorTable::fire();
    if (const Json* t = o.get("colorTable")) table = readColorTable(c, o.at("colorTable"), *t);
    EffectDesc desc;
    desc.textures.seed = e.seed;
    if (const Json* p = o.get("propagation"))
        if (auto x = readObject<PropagationDesc>(c, o.at("propagation"), *p,
                                                 [](Context& c2, ObjectReader& o2, PropagationDesc& v) { readPropagation(c2, o2, v, false); }))
            desc.textures.propagation = *x;
    if (const Json* p = o.get("cycling"))
        if (auto x = readObject<CyclingDesc>(c, o.at("cycling"), *p, readCycling)) desc.textures.cycling = *x;
    bool crossfade = true;
    o.boolean("crossfade", crossfade);
    if (!c.d.ok() || !tex || !table) return std::nullopt;

    // Every field voxelizeShapes checks was checked above with the file's own
    // message, so the one failure left is a lattice the shapes miss.
    Result<Grid> grid = voxelizeShapes(shapes, {.dims = dims, .spacing = spacing, .opacity = opacity, .fadeAxis = colorAxis, .fadeTo = fadeTo});
    if (!grid) return c.d.error(join(e.path, "shapes"), grid.error()), std::nullopt;
    grid->transform = pl.parent * local;

    Result<TextureSet> set = buildTextureSet(*tex);
    if (!set) return c.d.error(join(e.path, "textureSet"), set.error()), std::nullopt;
    if (set->count() == 0) return c.d.error(join(e.path, "textureSet"), "the texture set is empty"), std::nullopt;
    desc.name = e.name;
    desc.motion = pl.motion;
    desc.footprintRadius = c.materials.footprint().radius();
    const std::uint32_t setId = c.materials.addTextureSet(*set);
    const std::uint32_t tableId = c.materials.addColorTable(*table);
    desc.layers = {{.style = {.textureSet = setId, .colorTable = tableId, .textured = true, .crossfade = crossfade}}};
    Result<Effect> r = Effect::fromGrid(std::move(*grid), std::move(desc));
    if (!r) return c.d.error(e.path, r.error()), std::nullopt;
    return std::move(*r);
}

} // namespace splatfx::scenefile
