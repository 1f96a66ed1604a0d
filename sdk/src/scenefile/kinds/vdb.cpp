// Effect kind "vdb": a baked simulation from OpenVDB files (splatfx/vdb.hpp),
// played back by Effect::fromSequence with texture propagation along its
// velocity. Compiled in only when splatfx::vdb is built (SPLATFX_WITH_VDB);
// otherwise the kind is not in the table and a file naming it is told why.
#include "scenefile/kinds.hpp"

#if SPLATFX_WITH_VDB

#include "splatfx/vdb.hpp"

namespace splatfx::scenefile {
namespace {

struct GridNames {
    std::string density = "density", temperature = "temperature", velocity = "velocity";
};

void readGridNames(Context&, ObjectReader& o, GridNames& g) {
    o.string("density", g.density);
    o.string("temperature", g.temperature);
    o.string("velocity", g.velocity);
}

} // namespace

std::optional<Effect> readVdbKind(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    std::string files;
    if (!o.has("files")) c.d.error(o.path(), "missing \"files\" (a .vdb file, or a numbered sequence such as \"data/fluid_data_####.vdb\")");
    o.string("files", files);
    int firstFrame = 1, lastFrame = 0;
    o.integer("firstFrame", firstFrame, -1000000, 1000000);
    o.integer("lastFrame", lastFrame, -1000000, 1000000);
    VdbImportDesc imp;
    if (const Json* g = o.get("grids"))
        if (auto names = readObject<GridNames>(c, o.at("grids"), *g, readGridNames)) {
            imp.densityGrid = names->density;
            imp.temperatureGrid = names->temperature;
            imp.velocityGrid = names->velocity;
        }
    o.integer("voxelsPerCell", imp.voxelsPerCell, 0, kMaxAxis);
    o.integer("maxCellsPerAxis", imp.maxCellsPerAxis, 1, kMaxAxis);
    o.number("extinction", imp.extinctionPerDensity, 0.0, 1e6);
    if (o.has("temperatureHot") != o.has("temperatureCold"))
        c.d.error(o.path(), "give both \"temperatureHot\" and \"temperatureCold\", or neither (the range of the data)");
    o.number("temperatureHot", imp.temperatureHot, -1e9, 1e9);
    o.number("temperatureCold", imp.temperatureCold, -1e9, 1e9);
    if (const Json* u = o.get("velocityUnit"))
        if (auto s = readChoice(c.d, o.at("velocityUnit"), *u, {"world", "voxels"}))
            imp.velocityUnit = *s == "world" ? VdbImportDesc::VelocityUnit::WorldPerSec : VdbImportDesc::VelocityUnit::VoxelsPerSec;
    o.number("velocityScale", imp.velocityScale, -1e6, 1e6);
    o.number("fps", imp.framesPerSec, 1e-3, 1e4);
    if (const Json* m = o.get("end"))
        if (auto s = readChoice(c.d, o.at("end"), *m, {"loop", "clamp"})) imp.end = *s == "loop" ? SequenceEnd::Loop : SequenceEnd::Clamp;
    EffectDesc desc;
    o.number("minOpacity", desc.sparse.minOpacity, 0.0, 1.0);
    const glm::mat4 local = readPlacement(o, true);
    std::optional<TextureSpec> tex;
    if (const Json* t = o.get("textureSet")) tex = readTextureSpec(c, o.at("textureSet"), *t, 8, e.seed, false);
    else {
        tex.emplace();
        tex->seed = e.seed;
    }
    std::optional<ColorTable> table = ColorTable::smoke();
    if (const Json* t = o.get("colorTable")) table = readColorTable(c, o.at("colorTable"), *t);
    desc.textures.seed = e.seed;
    desc.textures.propagation.mode = Propagation::Velocity;
    if (const Json* p = o.get("propagation"))
        if (auto x = readObject<PropagationDesc>(c, o.at("propagation"), *p,
                                                 [](Context& c2, ObjectReader& o2, PropagationDesc& v) { readPropagation(c2, o2, v, true); }))
            desc.textures.propagation = *x;
    if (const Json* p = o.get("cycling"))
        if (auto x = readObject<CyclingDesc>(c, o.at("cycling"), *p, readCycling)) desc.textures.cycling = *x;
    bool crossfade = true;
    o.boolean("crossfade", crossfade);
    if (!c.d.ok() || !tex || !table) return std::nullopt;

    const std::string path = resolvePath(c, files);
    Result<GridSequence> seq = path.find('#') != std::string::npos ? loadVdbSequence(path, firstFrame, lastFrame, imp) : loadVdb(path, imp);
    if (!seq) return c.d.error(join(e.path, "files"), seq.error()), std::nullopt;
    seq->transform = pl.parent * local * seq->transform;

    Result<TextureSet> set = buildTextureSet(*tex);
    if (!set) return c.d.error(join(e.path, "textureSet"), set.error()), std::nullopt;
    if (set->count() == 0) return c.d.error(join(e.path, "textureSet"), "the texture set is empty"), std::nullopt;
    desc.name = e.name;
    desc.motion = pl.motion;
    desc.footprintRadius = c.materials.footprint().radius();
    const std::uint32_t setId = c.materials.addTextureSet(*set);
    const std::uint32_t tableId = c.materials.addColorTable(*table);
    desc.layers = {{.style = {.textureSet = setId, .colorTable = tableId, .textured = true, .crossfade = crossfade}}};
    Result<Effect> r = Effect::fromSequence(std::move(*seq), std::move(desc));
    if (!r) return c.d.error(e.path, r.error()), std::nullopt;
    return std::move(*r);
}

} // namespace splatfx::scenefile

#endif // SPLATFX_WITH_VDB
