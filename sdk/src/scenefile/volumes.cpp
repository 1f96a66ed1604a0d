// [clouds, issue 17] The top-level "volumes" block: LOD volumes drawn as
// projected tetrahedra (docs/scene-format.md, `volumes[i]`). Two kinds:
// "clouds" (makeCloudVolume + makeCloudTransfer, Roettger & Ertl 2002 sec. 5)
// and "groundFog" (GroundFog over a heightmap, sec. 6).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>

#include "scenefile/reader.hpp"
#include "splatfx/cloud.hpp"
#include "splatfx/image_io.hpp"
#include "splatfx/volume.hpp"

namespace splatfx::scenefile {
namespace {

// Grid points a scene may ask for: 1 GiB is LodVolumeDesc's own budget; this
// keeps a typo from building a field for minutes first.
constexpr double kMaxVolumePoints = 64.0 * 1024 * 1024;

// What one tetrahedron a volume emits costs a frame: 80 bytes in
// LodFrame::tets, 160 in the tetrahedron pass's records and 160 in the GL's
// copy of them (tetra_pass.cpp: ten vec4 a tetrahedron).
constexpr std::uint64_t kFrameBytesPerTetrahedron = 80 + 160 + 160;

// Adds a volume's estimate to the scene's and checks the sum against
// Budgets::volumeBytes; false (reported at `where`) when it is over.
bool addVolumeBytes(Context& c, const std::string& where, const std::string& what, std::uint64_t bytes) {
    c.volumeBytes += bytes;
    if (Status s = checkBudget("the scene's volumes with " + what, c.volumeBytes, "bytes", c.budgets.volumeBytes, "volumeBytes"); !s) {
        c.d.error(where, s.error());
        return false;
    }
    return true;
}

// The cloud generator's vertical axis is grid z; scenes are y-up. The field is
// generated with (x, z, y) dims and re-indexed so grid y is world up.
ScalarVolume yUp(const ScalarVolume& zUp) {
    const glm::ivec3 d = zUp.dims; // x, horizontal 2, height
    ScalarVolume out;
    out.dims = {d.x, d.z, d.y};
    out.scalar.resize(zUp.scalar.size());
    out.lengthScale.resize(zUp.lengthScale.size());
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) {
                const std::size_t src = std::size_t(x) + std::size_t(d.x) * (std::size_t(y) + std::size_t(d.y) * std::size_t(z));
                const std::size_t dst = std::size_t(x) + std::size_t(d.x) * (std::size_t(z) + std::size_t(d.z) * std::size_t(y));
                out.scalar[dst] = zUp.scalar[src];
                if (!zUp.lengthScale.empty()) out.lengthScale[dst] = zUp.lengthScale[src];
            }
    return out;
}

std::string vec(glm::vec3 v) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "[%g, %g, %g]", double(v.x), double(v.y), double(v.z));
    return buf;
}

// A "heightmap" geometry as a ground-fog layer's terrain ("terrainGeometry"):
// the layer takes the geometry's heightmap, spacing, heightScale and position,
// so the terrain the host draws from the layer is the geometry's own. Keys the
// layer gives itself must agree exactly; a geometry the layer cannot follow
// (rotated, scaled, moving: a layer is static and axis-aligned) is refused.
struct TerrainSource {
    std::string path; // resolved heightmap file
    float spacing = 1.0f, heightScale = 1.0f;
    glm::vec3 position{0.0f};
};

std::optional<TerrainSource> terrainFromGeometry(Context& c, ObjectReader& o, const std::string& name, const SceneFile& out) {
    const auto g = std::find_if(out.geometry.begin(), out.geometry.end(), [&](const GeometryDesc& x) { return x.name == name; });
    if (g == out.geometry.end() || g->type != GeometryType::Heightmap) {
        c.d.error(o.at("terrainGeometry"), "names no heightmap geometry ('" + name + "')");
        return std::nullopt;
    }
    const std::string gp = "geometry[" + std::to_string(g - out.geometry.begin()) + "]";
    const glm::mat4 m = g->motion.matrix(0.0) * g->transform;
    if (!g->motion.isStatic()) {
        c.d.error(o.at("terrainGeometry"), "geometry '" + name + "' (" + gp +
                                               ") moves (its own \"motion\" or what it is attached to); a ground-fog layer's terrain is static");
        return std::nullopt;
    }
    if (glm::mat3(m) != glm::mat3(1.0f)) {
        c.d.error(o.at("terrainGeometry"), "geometry '" + name + "' (" + gp +
                                               ") is rotated or scaled (rotationDeg, scale, or what it is attached to); a ground-fog layer's "
                                               "terrain is axis-aligned at scale 1: give the geometry only a \"position\"");
        return std::nullopt;
    }
    TerrainSource t{g->heightmapPath, g->heightmapSpacing, g->heightmapScale, glm::vec3(m[3])};
    const std::string why = "; leave it out to take the geometry's";
    if (const Json* v = o.get("heightmap"))
        if (auto file = readString(c.d, o.at("heightmap"), *v)) {
            std::error_code ec; // a file that does not exist is not the geometry's
            if (!std::filesystem::equivalent(resolvePath(c, *file), t.path, ec))
                c.d.error(o.at("heightmap"),
                          "'" + *file + "' is not the file of terrainGeometry '" + name + "' ('" + t.path + "', " + gp + ".heightmap)" + why);
        }
    auto agree = [&](const char* key, float theirs, const char* theirKey) {
        if (const Json* v = o.get(key))
            if (auto x = readNumber(c.d, o.at(key), *v, -1e9, 1e9); x && float(*x) != theirs)
                c.d.error(o.at(key), num(*x) + " disagrees with terrainGeometry '" + name + "': its " + theirKey + " is " + num(theirs) + " (" + gp +
                                         "." + theirKey + ")" + why);
    };
    agree("spacing", t.spacing, "spacing");
    agree("heightScale", t.heightScale, "heightScale");
    if (const Json* v = o.get("position"))
        if (auto p = readVec3(c.d, o.at("position"), *v, -kMaxCoord, kMaxCoord); p && *p != t.position)
            c.d.error(o.at("position"), vec(*p) + " disagrees with terrainGeometry '" + name + "': its position is " + vec(t.position) + " (" + gp +
                                            ".position)" + why);
    return t;
}

// (issue 17) kind "groundFog": prisms over a heightmap terrain
// (Roettger & Ertl sec. 6), the terrain placed as a "heightmap" geometry with
// the same heightmap, spacing, heightScale and position is (heightmapPoint);
// with "terrainGeometry" those four come from the named geometry.
void readGroundFog(Context& c, const std::string& p, ObjectReader& o, const std::string& name, SceneFile& out) {
    const std::size_t before = c.d.count();
    std::string file;
    bool enabled = true;
    glm::vec3 position{0.0f}, colour{0.85f, 0.87f, 0.9f};
    float spacing = 1.0f, heightScale = 1.0f, fogTop = 0.0f, density = 1.0f, extinction = 0.5f;
    int step = 1, scalarRes = 32, lengthRes = 128;
    std::string terrainGeometry;
    o.string("terrainGeometry", terrainGeometry);
    std::string path; // the heightmap, resolved
    if (!terrainGeometry.empty()) {
        // The geometry block is read before the volumes. Its four keys are compared there, or moot when it is refused.
        for (const char* key : {"heightmap", "position", "spacing", "heightScale"}) o.touch(key);
        if (auto t = terrainFromGeometry(c, o, terrainGeometry, out)) {
            path = file = t->path;
            spacing = t->spacing, heightScale = t->heightScale, position = t->position;
        }
    } else {
        if (!o.has("heightmap")) c.d.error(p, "missing \"heightmap\" (an image file, e.g. a 16-bit PGM, relative to the scene file)");
        o.string("heightmap", file);
        o.vec3("position", position, -kMaxCoord, kMaxCoord);
        o.number("spacing", spacing, 1e-4, 1e4);
        o.number("heightScale", heightScale, -1e6, 1e6);
        if (!file.empty()) path = resolvePath(c, file);
    }
    if (!o.has("fogTop")) c.d.error(p, "missing \"fogTop\" (the world height of the fog's top)");
    o.boolean("enabled", enabled);
    o.integer("step", step, 1, 64);
    o.number("fogTop", fogTop, -kMaxCoord, kMaxCoord);
    o.number("density", density, 0.0, 1.0);
    o.number("extinctionPerWorld", extinction, 0.0, 1e4);
    o.color3("colour", colour);
    o.integer("tableScalars", scalarRes, 2, 256);
    o.integer("tableLengths", lengthRes, 2, 512);
    bool sortFree = false;
    o.boolean("sortFree", sortFree);
    // The LOD terrain (GroundFogDesc::lod; c and morphing are per frame, EffectOptions::refine).
    bool lod = false, morph = true;
    float detailC = 1.0f, minAccuracyC = 4.0f;
    o.boolean("lod", lod);
    o.number("detailC", detailC, 0.0, 1e6);
    o.number("minAccuracyC", minAccuracyC, 1e-3, 1e6);
    o.boolean("morph", morph);
    float densityDepth = 0.0f;
    o.number("densityDepthWorld", densityDepth, 0.0, 1e6);
    // Lit by the scene's sun (issue 27; GroundFog::setLighting): the same
    // "lighting" object as the effects' and the clouds' (its gas desc), the
    // layer's "colour" and "extinctionPerWorld" as the fog's own.
    EffectLighting lighting;
    const Json* lit = o.get("lighting");
    if (lit) readEffectLighting(c, o.at("lighting"), *lit, lighting);
    lighting.selfShadow = SelfShadow::Off; // it shadows itself through its own field: no tables to budget
    if (!lod)
        for (const char* key : {"detailC", "minAccuracyC", "morph", "terrainGeometry"})
            if (o.has(key)) c.d.error(o.at(key), std::string("only with \"lod\": true (the full-resolution layer has no LOD)"));
    o.finish();
    if (c.d.count() != before || path.empty()) return;
    const char* imageKey = terrainGeometry.empty() ? "heightmap" : "terrainGeometry"; // where the image was named
    // The header first: a huge image is refused before anything is decoded.
    auto info = readImageInfo(path);
    if (!info) {
        c.d.error(o.at(imageKey), info.error());
        return;
    }
    if (double(info->width) * info->height > 16.0 * 1024 * 1024) {
        c.d.error(o.at(imageKey), "'" + file + "' is " + std::to_string(info->width) + "x" + std::to_string(info->height) +
                                      ", more than the 16 Mi samples a ground-fog heightmap may have");
        return;
    }
    {
        // Before the image is decoded: the decoded image (float RGBA), the
        // desc's two arrays, what the layer keeps, its table, and the
        // tetrahedra of its full resolution (what a fully refined LOD emits
        // too), three a triangle, two triangles a cell.
        const std::uint64_t sx = std::uint64_t((info->width - 1) / step + 1), sz = std::uint64_t((info->height - 1) / step + 1);
        std::uint64_t cells = (sx - 1) * (sz - 1);
        if (lod) {
            std::uint64_t n = 2;
            while (n < std::max(sx, sz)) n = 2 * (n - 1) + 1;
            cells = (n - 1) * (n - 1);
        }
        const std::uint64_t tets = 6 * cells;
        // Lit: the sun's transmittance at each point's terrain and top (8 bytes a point, the LOD's padded grid at most 4 x the points) and a 2 x 2 x tableLengths table.
        const std::uint64_t litBytes = lit ? 8 * (lod ? 4 : 1) * sx * sz + 16ull * 4 * lengthRes : 0;
        const std::uint64_t bytes = 16 * std::uint64_t(info->width) * std::uint64_t(info->height) + 8 * sx * sz +
                                    GroundFog::bytesFor(glm::ivec2(int(sx), int(sz)), lod) + 16ull * scalarRes * scalarRes * lengthRes +
                                    kFrameBytesPerTetrahedron * tets + litBytes;
        if (!addVolumeBytes(c, p,
                            "groundFog '" + name + "' (" + std::to_string(sx) + "x" + std::to_string(sz) + " points, up to " + std::to_string(tets) +
                                " tetrahedra a frame, a " + dimsText({scalarRes, scalarRes, lengthRes}) + " table)",
                            bytes))
            return;
    }
    auto img = readImage(path, Alpha::Straight);
    if (!img) {
        c.d.error(o.at(imageKey), img.error());
        return;
    }
    const int w = img->width, h = img->height;
    // Every step-th sample (step divides the cells, checked below, so the last row and column are kept).
    auto samples = [&](int n) { return (n - 1) / step + 1; };
    auto source = [&](int k, int n) { return std::min(k * step, n - 1); };
    GroundFogDesc gd;
    gd.dims = {samples(w), samples(h)};
    if (gd.dims.x < 2 || gd.dims.y < 2) {
        c.d.error(o.at(imageKey), "needs at least 2x2 samples after \"step\", got " + std::to_string(gd.dims.x) + "x" + std::to_string(gd.dims.y));
        return;
    }
    if (double(gd.dims.x) * gd.dims.y > 4.0 * 1024 * 1024) {
        c.d.error(o.at("step"), "more than 4 Mi samples: raise \"step\"");
        return;
    }
    // The grid is uniform only if the last sample lands on a multiple of step.
    if ((w - 1) % step != 0 || (h - 1) % step != 0) {
        c.d.error(o.at("step"),
                  "must divide the heightmap's " + std::to_string(w - 1) + "x" + std::to_string(h - 1) + " cells so the layer's grid stays uniform");
        return;
    }
    const glm::vec3 corner = position + heightmapPoint(0, 0, w, h, 0.0f, spacing, 0.0f);
    gd.originWorld = corner;
    gd.spacingWorld = spacing * float(step);
    gd.density = density;
    gd.sortFree = sortFree;
    gd.lod = lod;
    gd.minAccuracyC = minAccuracyC;
    gd.densityDepthWorld = densityDepth;
    gd.terrainHeight.resize(std::size_t(gd.dims.x) * gd.dims.y);
    gd.fogTop.resize(gd.terrainHeight.size());
    float lowest = 1e30f;
    for (int j = 0; j < gd.dims.y; ++j)
        for (int i = 0; i < gd.dims.x; ++i) {
            const float v = img->at(source(i, w), source(j, h), 0);
            const std::size_t k = std::size_t(i) + std::size_t(gd.dims.x) * std::size_t(j);
            gd.terrainHeight[k] = position.y + heightScale * v;
            gd.fogTop[k] = fogTop;
            lowest = std::min(lowest, gd.terrainHeight[k]);
        }
    auto layer = GroundFog::create(gd);
    if (!layer) {
        c.d.error(p, layer.error());
        return;
    }
    auto tf = makeGroundFogTransfer(colour, extinction);
    if (!tf) {
        c.d.error(p, tf.error());
        return;
    }
    // The longest segment in one prism: its base diagonal and full height.
    const float cell = gd.spacingWorld, tall = std::max(fogTop - lowest, 0.0f);
    const float longest = std::max(std::sqrt(2.0f * cell * cell + tall * tall), 1e-3f);
    auto table = PreIntegrationTable::create(*tf, {.scalarResolution = scalarRes, .lengthResolution = lengthRes, .maxLengthWorld = longest});
    if (!table) {
        c.d.error(p, table.error());
        return;
    }
    LodRefineDesc refine;
    refine.detailC = detailC;
    refine.morph = morph;
    const EffectId id = out.scene.add(std::move(*layer), std::move(*tf), std::move(*table),
                                      {.name = name, .enabled = enabled, .lighting = lighting, .refine = refine, .keepTerrain = !terrainGeometry.empty()});
    out.volumes.push_back({id, name, "groundFog"});
    if (!terrainGeometry.empty()) out.groundFogTerrain.push_back({terrainGeometry, id});
}

} // namespace

void readVolumes(Context& c, const std::string& path, const Json& v, SceneFile& out) {
    if (!v.is_array() || v.size() > 64) {
        c.d.error(path, "expected an array of at most 64 volume objects, got " + brief(v));
        return;
    }
    for (std::size_t i = 0; i < v.size(); ++i) {
        const std::string p = index(path, i);
        ObjectReader o(c.d, p, v[i]);
        if (!o.valid()) continue;
        const std::size_t before = c.d.count();
        std::string name = "volume" + std::to_string(i), kind;
        o.string("name", name);
        o.string("kind", kind);
        if (kind == "groundFog") {
            readGroundFog(c, p, o, name, out);
            continue;
        }
        if (kind != "clouds")
            c.d.error(o.at("kind"),
                      kind.empty() ? "required: \"clouds\" or \"groundFog\"" : "unknown kind '" + kind + "' (known: clouds, groundFog)");
        bool enabled = true, morph = true;
        glm::ivec3 dims{129, 17, 129};
        glm::vec3 origin{0.0f}, sun{0.3f, 1.0f, 0.2f};
        float spacing = 1.0f, detailC = 10.0f, minC = 4.0f;
        std::uint32_t localSeed = std::uint32_t(i);
        CloudDesc cd;
        CloudTransferDesc td;
        int scalarRes = 64, lengthRes = 128;
        o.boolean("enabled", enabled);
        o.ivec3("dims", dims, 2, 1025);
        o.vec3("position", origin, -kMaxCoord, kMaxCoord);
        o.number("spacing", spacing, 1e-4, 1e4);
        o.seed("seed", localSeed);
        o.number("featureCells", cd.featureCells, 1.0, 1e4);
        o.integer("octaves", cd.octaves, 1, 8);
        o.number("coverage", cd.coverage, 0.0, 1.0);
        o.number("sharpness", cd.sharpness, 0.01, 100.0);
        o.vec3("sunDirection", sun, -1e3, 1e3);
        o.number("ambient", cd.ambient, 0.0, 1.0);
        o.number("diffuse", cd.diffuse, 0.0, 1.0);
        o.number("lightExtinctionPerCell", cd.lightExtinctionPerCell, 0.0, 100.0);
        o.number("threshold", td.threshold, 0.0, 1.0);
        o.number("extinctionPerWorld", td.maxExtinctionPerWorld, 0.0, 1e4);
        o.color3("bright", td.bright);
        o.color3("dark", td.dark);
        o.number("detailC", detailC, 1e-3, 1e9);
        o.number("minAccuracyC", minC, 1.7320509, 1e4); // eq. 4 holds for C > sqrt(3)
        o.boolean("morph", morph);
        o.integer("tableScalars", scalarRes, 2, 256);
        o.integer("tableLengths", lengthRes, 2, 512);
        // Lit by the scene (issue 27): a relightable Cloud that follows the
        // scene's first directional light and casts into the scene shadow.
        EffectLighting lighting;
        const Json* lit = o.get("lighting");
        if (lit) readEffectLighting(c, o.at("lighting"), *lit, lighting);
        // A cloud shadows itself by its own sweep: no self-shadowing tables to budget.
        lighting.selfShadow = SelfShadow::Off;
        std::string lightModel = "roettger";
        o.string("lightModel", lightModel);
        if (lightModel != "roettger" && lightModel != "lowAlbedo")
            c.d.error(o.at("lightModel"), "expected \"roettger\" or \"lowAlbedo\", got '" + lightModel + "'");
        o.finish();
        if (c.d.count() != before) continue;
        if (double(dims.x) * dims.y * dims.z > kMaxVolumePoints) {
            c.d.error(o.at("dims"), "more than 64 Mi grid points");
            continue;
        }
        if (!(glm::length(sun) > 0.0f)) {
            c.d.error(o.at("sunDirection"), "must not be zero");
            continue;
        }
        {
            // Before the field is generated: the generated field and its y-up
            // copy (two floats a point each), what the volume keeps, its
            // table, and the tetrahedra of a full refinement (five a cell).
            const std::uint64_t points = std::uint64_t(dims.x) * std::uint64_t(dims.y) * std::uint64_t(dims.z);
            const std::uint64_t tets = 5 * std::uint64_t(dims.x - 1) * std::uint64_t(dims.y - 1) * std::uint64_t(dims.z - 1);
            // A lit cloud also keeps its density, sun transmittance and cast
            // field (12 bytes a point) and builds the field from 40-byte voxels.
            const std::uint64_t bytes = (lit ? 68 : 16) * points + LodVolume::bytesFor(dims, true) + 16ull * scalarRes * scalarRes * lengthRes +
                                        kFrameBytesPerTetrahedron * tets;
            if (!addVolumeBytes(c, p,
                                "clouds '" + name + "' (" + dimsText(dims) + " points, up to " + std::to_string(tets) + " tetrahedra a frame, a " +
                                    dimsText({scalarRes, scalarRes, lengthRes}) + " table)",
                                bytes))
                continue;
        }
        cd.dims = {dims.x, dims.z, dims.y}; // generator: z up
        cd.sunDirection = {sun.x, sun.z, sun.y};
        cd.seed = c.sceneSeed * 1000003u + 7919u + localSeed; // like effects: --seed changes them all
        if (lit) {
            CloudCreateDesc ccd{.cloud = cd,
                                .lighting = {.model = lightModel == "lowAlbedo" ? CloudLightModel::LowAlbedo : CloudLightModel::Roettger,
                                             .sun = Light::directional(-sun),
                                             .ambient = cd.ambient,
                                             .diffuse = cd.diffuse,
                                             .gas = lighting.gas},
                                .transfer = td,
                                .volume = {.originWorld = origin, .spacingWorld = spacing, .minAccuracyC = minC},
                                .table = {.scalarResolution = scalarRes, .lengthResolution = lengthRes},
                                .yUp = true};
            auto cloud = Cloud::create(ccd);
            if (!cloud) {
                c.d.error(p, cloud.error());
                continue;
            }
            const EffectId id = out.scene.add(std::move(*cloud), {.name = name,
                                                                  .enabled = enabled,
                                                                  .lighting = lighting,
                                                                  .refine = {.detailC = detailC, .morph = morph}});
            out.volumes.push_back({id, name, "clouds"});
            continue;
        }
        auto field = makeCloudVolume(cd);
        if (!field) {
            c.d.error(p, field.error());
            continue;
        }
        auto vol = LodVolume::create(yUp(*field), {.originWorld = origin, .spacingWorld = spacing, .minAccuracyC = minC});
        if (!vol) {
            c.d.error(p, vol.error());
            continue;
        }
        auto tf = makeCloudTransfer(td);
        if (!tf) {
            c.d.error(p, tf.error());
            continue;
        }
        // The longest segment a root cube can hold (its diagonal; length scales are <= 1).
        const float longest = std::sqrt(3.0f) * float(1 << vol->rootLevel()) * spacing;
        auto table = PreIntegrationTable::create(*tf, {.scalarResolution = scalarRes, .lengthResolution = lengthRes, .maxLengthWorld = longest});
        if (!table) {
            c.d.error(p, table.error());
            continue;
        }
        const EffectId id = out.scene.add(std::move(*vol), std::move(*tf), std::move(*table),
                                          {.name = name, .enabled = enabled, .refine = {.detailC = detailC, .morph = morph}});
        out.volumes.push_back({id, name, "clouds"});
    }
}

} // namespace splatfx::scenefile
