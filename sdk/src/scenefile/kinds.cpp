// The scene-file kinds: the one table of effect kinds and the one table of
// geometry types (see kinds.hpp). Each reader is defined in kinds/<kind>.cpp.
#include "scenefile/kinds.hpp"

namespace splatfx::scenefile {

// Effect readers, one a file in kinds/.
EffectReaderFn readFire, readSmoke, readSteam, readDust, readFireToSmoke, readGhosts, readGridKind, readGasKind, readParticlesKind;
#if SPLATFX_WITH_VDB
EffectReaderFn readVdbKind; // only when splatfx::vdb is built (OpenVDB found)
#endif
// Geometry readers, for the types with keys of their own.
GeometryReaderFn readMeshGeometry;
GeometryReaderFn readHeightmapGeometry;

namespace {

// The order is the order messages list them in (docs/scene-format.md).
constexpr EffectKind kEffectKinds[] = {
    {"fire", &readFire},               // kinds/fire.cpp
    {"smoke", &readSmoke},             // kinds/smoke.cpp
    {"steam", &readSteam},             // kinds/steam.cpp
    {"dust", &readDust},               // kinds/dust.cpp
    {"fireToSmoke", &readFireToSmoke}, // kinds/fire_to_smoke.cpp
    {"ghosts", &readGhosts},           // kinds/ghosts.cpp
    {"grid", &readGridKind},           // kinds/grid.cpp
    {"gas", &readGasKind},             // kinds/gas.cpp
    {"particles", &readParticlesKind}, // kinds/particles.cpp
#if SPLATFX_WITH_VDB
    {"vdb", &readVdbKind}, // kinds/vdb.cpp
#endif
};

constexpr GeometryKind kGeometryKinds[] = {
    {"plane", GeometryType::Plane, nullptr},
    {"box", GeometryType::Box, nullptr},
    {"cylinder", GeometryType::Cylinder, nullptr},
    {"sphere", GeometryType::Sphere, nullptr},
    {"mesh", GeometryType::Mesh, &readMeshGeometry},                // kinds/mesh.cpp
    {"heightmap", GeometryType::Heightmap, &readHeightmapGeometry}, // kinds/heightmap.cpp
    {"empty", GeometryType::Empty, nullptr},
};

template <class Row>
const Row* find(std::span<const Row> rows, std::string_view name) {
    for (const Row& r : rows)
        if (r.name == name) return &r;
    return nullptr;
}

template <class Row>
std::vector<std::string> names(std::span<const Row> rows) {
    std::vector<std::string> out;
    for (const Row& r : rows) out.emplace_back(r.name);
    return out;
}

} // namespace

std::span<const EffectKind> effectKinds() { return kEffectKinds; }
std::span<const GeometryKind> geometryKinds() { return kGeometryKinds; }
const EffectKind* findEffectKind(std::string_view name) { return find(effectKinds(), name); }
const GeometryKind* findGeometryKind(std::string_view name) { return find(geometryKinds(), name); }
std::vector<std::string> effectKindNames() { return names(effectKinds()); }
std::vector<std::string> geometryKindNames() { return names(geometryKinds()); }

} // namespace splatfx::scenefile
