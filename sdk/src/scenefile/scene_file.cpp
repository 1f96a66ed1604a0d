// Scene files: versioned JSON to a Scene, geometry, camera path and output
// settings (docs/scene-format.md).
//
// [SECTION] Limits
// [SECTION] Text checks (size, nesting, syntax with line and column)
// [SECTION] Shared pieces: placement, motion, texture sets, colour tables
// [SECTION] Geometry (and attachment chains)
// [SECTION] Effects: presets and hand-shaped grids
// [SECTION] Camera and output
// [SECTION] Entry points
#include "splatfx/scene_file.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "scenefile/json_reader.hpp"
#include "splatfx/presets.hpp"

namespace splatfx {
namespace scenefile {
namespace {

namespace fs = std::filesystem;

// [SECTION] Limits

// Larger than any sensible scene, small enough that a typo (an extra zero,
// a unit mistake) is caught before it allocates gigabytes.
constexpr double kMaxCoord = 1.0e6;            // world units for positions and offsets
constexpr double kMaxSeconds = 1.0e6;          // key times
constexpr int kMaxAxis = 4096;                 // cells per lattice axis
constexpr std::uint64_t kMaxSolverCells = 1u << 18; // solver effects: every cell is simulated every step
constexpr std::size_t kMaxEffects = 4096;
constexpr std::size_t kMaxGeometry = 4096;
constexpr std::size_t kMaxKeys = 100000;
constexpr std::size_t kMaxFileBytes = 16u << 20;
constexpr int kMaxDepth = 64;
constexpr int kMaxAttachDepth = 16;

// [SECTION] Text checks

struct LineCol {
    std::size_t line = 1, column = 1;
};

LineCol lineColumn(const std::string& text, std::size_t byte) {
    LineCol lc;
    for (std::size_t i = 0; i < std::min(byte, text.size()); ++i) {
        if (text[i] == '\n') ++lc.line, lc.column = 1;
        else ++lc.column;
    }
    return lc;
}

// Rejects nesting deeper than kMaxDepth before the parser sees it (deep
// nesting is never meaningful here and costs stack elsewhere).
std::optional<std::size_t> tooDeep(const std::string& text) {
    int depth = 0;
    bool inString = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\') ++i;
            else if (c == '"') inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxDepth) return i;
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return std::nullopt;
}

// nlohmann's messages start with "[json.exception.parse_error.101] parse
// error at line L, column C: "; keep only the explanation after it.
std::string syntaxReason(const std::string& what) {
    const std::size_t p = what.find(": ");
    std::string reason = p == std::string::npos ? what : what.substr(p + 2);
    if (reason.rfind("syntax error while parsing ", 0) == 0) reason = reason.substr(27);
    return reason;
}

// [SECTION] Shared pieces

struct Context {
    Diagnostics& d;
    fs::path baseDir;
    Materials& materials;
    std::uint32_t sceneSeed = 1;
};

std::string resolvePath(const Context& c, const std::string& p) {
    fs::path q(p);
    if (q.is_relative()) q = c.baseDir / q;
    return q.lexically_normal().string();
}

glm::quat eulerDeg(glm::vec3 deg) {
    const glm::vec3 r = glm::radians(deg);
    // X first, then Y, then Z: R = Rz * Ry * Rx.
    return glm::angleAxis(r.z, glm::vec3(0, 0, 1)) * glm::angleAxis(r.y, glm::vec3(0, 1, 0)) * glm::angleAxis(r.x, glm::vec3(1, 0, 0));
}

// position / rotationDeg / scale of an object.
glm::mat4 readPlacement(ObjectReader& o, bool withScale) {
    glm::vec3 pos(0.0f), rot(0.0f), scale(1.0f);
    o.vec3("position", pos, -kMaxCoord, kMaxCoord);
    o.vec3("rotationDeg", rot, -36000.0, 36000.0);
    if (withScale) o.vec3("scale", scale, 1e-4, 1e4, true);
    return glm::translate(glm::mat4(1.0f), pos) * glm::mat4_cast(eulerDeg(rot)) * glm::scale(glm::mat4(1.0f), scale);
}

std::optional<Easing> readEasing(Diagnostics& d, const std::string& path, const Json& v) {
    auto s = readChoice(d, path, v, {"linear", "smooth", "step"});
    if (!s) return std::nullopt;
    return *s == "linear" ? Easing::Linear : *s == "smooth" ? Easing::Smooth : Easing::Step;
}

// A motion object: keys plus procedural motion (motion.hpp).
std::optional<Motion> readMotion(Context& c, const std::string& path, const Json& v) {
    ObjectReader o(c.d, path, v);
    if (!o.valid()) return std::nullopt;
    const std::size_t before = c.d.count();
    std::vector<Keyframe> keys;
    if (const Json* k = o.get("keys")) {
        if (!k->is_array() || k->size() > kMaxKeys) {
            c.d.error(o.at("keys"), "expected an array of at most " + std::to_string(kMaxKeys) + " keyframes, got " + typeName(*k) +
                                        " " + brief(*k));
        } else {
            for (std::size_t i = 0; i < k->size() && !c.d.full(); ++i) {
                ObjectReader ko(c.d, index(o.at("keys"), i), (*k)[i]);
                if (!ko.valid()) continue;
                Keyframe key;
                if (!ko.has("time")) c.d.error(ko.path(), "missing \"time\" (seconds)");
                ko.number("time", key.timeSec, 0.0, kMaxSeconds);
                glm::vec3 rot(0.0f);
                ko.vec3("position", key.pose.position, -kMaxCoord, kMaxCoord);
                ko.vec3("rotationDeg", rot, -36000.0, 36000.0);
                key.pose.rotation = eulerDeg(rot);
                ko.vec3("scale", key.pose.scale, 1e-4, 1e4, true);
                ko.number("opacity", key.pose.opacity, 0.0, 1e3);
                ko.number("growth", key.pose.growth, 0.0, 1.0);
                if (const Json* e = ko.get("easing"))
                    if (auto ea = readEasing(c.d, ko.at("easing"), *e)) key.easing = *ea;
                if (i > 0 && !keys.empty() && !(key.timeSec > keys.back().timeSec))
                    c.d.error(ko.at("time"), "key times must increase strictly; got " + std::to_string(key.timeSec) + " after " +
                                                 std::to_string(keys.back().timeSec));
                ko.finish();
                keys.push_back(key);
            }
        }
    }
    ProceduralMotion p;
    o.vec3("velocity", p.velocity, -1e4, 1e4);
    o.vec3("spinAxis", p.spinAxis, -1.0, 1.0);
    float spinDeg = 0.0f, phaseDeg = 0.0f;
    o.number("spinDegPerSec", spinDeg, -1e5, 1e5);
    o.vec3("bobAmplitude", p.bobAmplitude, -1e4, 1e4);
    o.number("bobHz", p.bobHz, 0.0, 1e3);
    o.number("bobPhaseDeg", phaseDeg, -36000.0, 36000.0);
    p.spinRadPerSec = glm::radians(spinDeg);
    p.bobPhaseRad = glm::radians(phaseDeg);
    if (spinDeg != 0.0f && glm::length(p.spinAxis) < 1e-6f) c.d.error(o.at("spinAxis"), "must be non-zero when spinDegPerSec is set");
    o.finish();
    if (c.d.count() != before) return std::nullopt;
    Result<Motion> m = Motion::create(std::move(keys), p);
    if (!m) {
        c.d.error(path, m.error());
        return std::nullopt;
    }
    return std::move(*m);
}

// A texture set as written in a file.
struct TextureSpec {
    enum class Kind { Procedural, Folder, Faces, SampleImage } kind = Kind::Procedural;
    std::string folder;        // Folder: resolved path
    std::string image;         // SampleImage: resolved path
    int count = 8;
    int size = 32;
    std::uint32_t seed = 1;
    int octaves = 4;
    float baseFrequency = 3.0f;
    float loopRadius = 0.25f;
    bool keepColor = false;
};

bool textureFolderExists(const std::string& folder) {
    std::error_code ec;
    return fs::is_directory(folder, ec) && fs::is_regular_file(fs::path(folder) / "manifest.json", ec);
}

// `allowed` restricts the forms (presets take only a folder or a procedural count).
std::optional<TextureSpec> readTextureSpec(Context& c, const std::string& path, const Json& v, int defaultCount,
                                           std::uint32_t seed, bool presetOnly) {
    TextureSpec t;
    t.count = defaultCount;
    t.seed = seed;
    auto checkFolder = [&](const std::string& at, const std::string& given, bool procIfMissing) -> bool {
        t.folder = resolvePath(c, given);
        if (textureFolderExists(t.folder)) {
            t.kind = TextureSpec::Kind::Folder;
            return true;
        }
        if (procIfMissing) {
            t.kind = TextureSpec::Kind::Procedural;
            t.folder.clear();
            return true;
        }
        c.d.error(at, "texture set '" + given + "' not found (looked for '" + t.folder +
                          "/manifest.json'); expected a texture-set folder, or {\"procedural\": {...}}");
        return false;
    };
    if (v.is_string()) {
        if (!checkFolder(path, v.get<std::string>(), false)) return std::nullopt;
        return t;
    }
    ObjectReader o(c.d, path, v);
    if (!o.valid()) return std::nullopt;
    const std::size_t before = c.d.count();
    const std::vector<std::string> forms =
        presetOnly ? std::vector<std::string>{"folder", "procedural"} : std::vector<std::string>{"folder", "procedural", "faces", "sampleImage"};
    int given = 0;
    for (const std::string& f : forms) given += o.has(f) ? 1 : 0;
    if (given != 1) {
        std::string list;
        for (std::size_t i = 0; i < forms.size(); ++i) list += (i ? ", " : "") + ("\"" + forms[i] + "\"");
        c.d.error(path, "expected exactly one of " + list + " (or a folder path string)");
    }
    if (const Json* f = o.get("folder")) {
        std::string ifMissing = "error";
        if (const Json* m = o.get("ifMissing"))
            if (auto s = readChoice(c.d, o.at("ifMissing"), *m, {"error", "procedural"})) ifMissing = *s;
        if (auto s = readString(c.d, o.at("folder"), *f)) checkFolder(o.at("folder"), *s, ifMissing == "procedural");
        // the fallback's count, when the folder is missing
        if (const Json* n = o.get("count"))
            if (auto x = readInt(c.d, o.at("count"), *n, 1, 256)) t.count = int(*x);
    }
    if (const Json* p = o.get("procedural")) {
        ObjectReader po(c.d, o.at("procedural"), *p);
        t.kind = TextureSpec::Kind::Procedural;
        po.integer("count", t.count, 1, 256);
        if (!presetOnly) {
            po.integer("size", t.size, 4, 256);
            po.seed("seed", t.seed);
            po.integer("octaves", t.octaves, 1, 12);
            po.number("baseFrequency", t.baseFrequency, 0.01, 256.0);
            po.number("loopRadius", t.loopRadius, 0.0, 16.0);
        }
        po.finish();
    }
    if (!presetOnly) {
        if (const Json* p = o.get("faces")) {
            ObjectReader po(c.d, o.at("faces"), *p);
            t.kind = TextureSpec::Kind::Faces;
            t.count = 12;
            po.integer("count", t.count, 1, 256);
            po.integer("size", t.size, 4, 256);
            po.seed("seed", t.seed);
            po.finish();
        }
        if (const Json* p = o.get("sampleImage")) {
            // King et al. 1999, sec. 4 / Fig. 11: textures cut at random
            // positions from one larger image.
            ObjectReader po(c.d, o.at("sampleImage"), *p);
            t.kind = TextureSpec::Kind::SampleImage;
            t.count = 16;
            std::string image;
            if (!po.has("image")) c.d.error(po.path(), "missing \"image\" (an image file to sample)");
            po.string("image", image);
            po.integer("count", t.count, 1, 256);
            po.integer("size", t.size, 4, 1024);
            po.seed("seed", t.seed);
            po.boolean("color", t.keepColor);
            po.finish();
            if (!image.empty()) {
                t.image = resolvePath(c, image);
                std::error_code ec;
                if (!fs::is_regular_file(t.image, ec)) c.d.error(join(po.path(), "image"), "image file '" + image + "' not found (looked for '" + t.image + "')");
            }
        }
    }
    o.finish();
    if (c.d.count() != before) return std::nullopt;
    return t;
}

Result<TextureSet> sampleImage(const TextureSpec& t) {
    Result<Image> img = readImage(t.image);
    if (!img) return makeError(img.error());
    if (img->width < t.size || img->height < t.size)
        return makeError("image '" + t.image + "' is " + std::to_string(img->width) + "x" + std::to_string(img->height) +
                         ", smaller than the sample size " + std::to_string(t.size));
    std::vector<Image> crops;
    for (int i = 0; i < t.count; ++i) {
        const int x0 = int(hashUnit(hashCell({i, 0, 0}, t.seed, 11)) * float(img->width - t.size + 1));
        const int y0 = int(hashUnit(hashCell({i, 0, 0}, t.seed, 12)) * float(img->height - t.size + 1));
        Image crop;
        crop.width = crop.height = t.size;
        crop.channels = img->channels;
        crop.pixels.resize(std::size_t(t.size) * t.size * img->channels);
        for (int y = 0; y < t.size; ++y)
            for (int x = 0; x < t.size; ++x)
                for (int ch = 0; ch < img->channels; ++ch) crop.at(x, y, ch) = img->at(x0 + x, y0 + y, ch);
        crops.push_back(std::move(crop));
    }
    return TextureSet::fromImages(crops, t.keepColor);
}

Result<TextureSet> buildTextureSet(const TextureSpec& t) {
    switch (t.kind) {
    case TextureSpec::Kind::Folder: return TextureSet::load(t.folder);
    case TextureSpec::Kind::Faces: return presets::proceduralFaces(t.count, t.size, t.seed);
    case TextureSpec::Kind::SampleImage: return sampleImage(t);
    case TextureSpec::Kind::Procedural: break;
    }
    return TextureSet::turbulence({.count = t.count, .size = t.size, .seed = t.seed, .octaves = t.octaves,
                                   .baseFrequency = t.baseFrequency, .loopRadius = t.loopRadius});
}

std::optional<ColorTable> readColorTable(Context& c, const std::string& path, const Json& v) {
    if (v.is_string()) {
        auto s = readChoice(c.d, path, v, {"fire", "smoke", "steam", "dust"});
        if (!s) return std::nullopt;
        return *s == "fire" ? ColorTable::fire() : *s == "smoke" ? ColorTable::smoke() : *s == "steam" ? ColorTable::steam() : ColorTable::dust();
    }
    ObjectReader o(c.d, path, v);
    if (!o.valid()) return std::nullopt;
    std::optional<ColorTable> out;
    if (const Json* k = o.get("constant")) {
        if (auto col = readColor(c.d, o.at("constant"), *k, true)) out = ColorTable::constant(*col);
    } else if (const Json* g = o.get("gradient")) {
        const std::string gp = o.at("gradient");
        if (!g->is_array() || g->size() < 2 || g->size() > 256) {
            c.d.error(gp, "expected an array of 2 to 256 stops [t, [r, g, b, a]], got " + brief(*g));
        } else {
            std::vector<std::pair<float, glm::vec4>> stops;
            bool ok = true;
            for (std::size_t i = 0; i < g->size(); ++i) {
                const Json& s = (*g)[i];
                if (!s.is_array() || s.size() != 2) {
                    c.d.error(index(gp, i), "expected a stop [t, [r, g, b, a]], got " + brief(s));
                    ok = false;
                    continue;
                }
                auto t = readNumber(c.d, index(index(gp, i), 0), s[0], 0.0, 1.0);
                auto col = readColor(c.d, index(index(gp, i), 1), s[1], true);
                if (!t || !col) {
                    ok = false;
                    continue;
                }
                if (!stops.empty() && !(float(*t) > stops.back().first)) {
                    c.d.error(index(index(gp, i), 0), "stop positions must increase strictly");
                    ok = false;
                }
                stops.push_back({float(*t), *col});
            }
            if (ok) out = ColorTable::gradient(stops);
        }
    } else {
        c.d.error(path, "expected \"fire\", \"smoke\", \"steam\", \"dust\", {\"constant\": [r, g, b, a]} or {\"gradient\": [[t, [r, g, b, a]], ...]}");
    }
    o.finish();
    return out;
}

// [SECTION] Geometry

struct RawGeometry {
    GeometryDesc desc;
    std::string attachTo;
    std::string path;
    bool hasOwnMotion = false;
};

// Resolved placement of a named object: the root motion it rides on and the
// composed static transform down the attachment chain.
struct Anchor {
    Motion motion;
    glm::mat4 transform{1.0f};
};

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
    for (std::size_t i = 0; i < v.size() && !c.d.full(); ++i) {
        RawGeometry g;
        g.path = index(path, i);
        ObjectReader o(c.d, g.path, v[i]);
        if (!o.valid()) continue;
        g.desc.name = "geometry[" + std::to_string(i) + "]";
        o.string("name", g.desc.name);
        std::string type = "box";
        if (!o.has("type")) c.d.error(g.path, "missing \"type\" (\"plane\", \"box\", \"cylinder\", \"sphere\", \"mesh\" or \"empty\")");
        if (const Json* t = o.get("type"))
            if (auto s = readChoice(c.d, o.at("type"), *t, {"plane", "box", "cylinder", "sphere", "mesh", "empty"})) type = *s;
        g.desc.type = type == "plane" ? GeometryType::Plane : type == "cylinder" ? GeometryType::Cylinder : type == "sphere" ? GeometryType::Sphere
                    : type == "mesh" ? GeometryType::Mesh : type == "empty" ? GeometryType::Empty : GeometryType::Box;
        if (g.desc.type == GeometryType::Mesh) {
            std::string mesh;
            if (!o.has("mesh")) c.d.error(g.path, "missing \"mesh\" (a model file, relative to the scene file)");
            o.string("mesh", mesh);
            if (!mesh.empty()) {
                g.desc.meshPath = resolvePath(c, mesh);
                std::error_code ec;
                if (!fs::is_regular_file(g.desc.meshPath, ec))
                    c.d.error(o.at("mesh"), "mesh file '" + mesh + "' not found (looked for '" + g.desc.meshPath + "')");
            }
            o.number("fitSize", g.desc.fitSize, 0.0, kMaxCoord);
        }
        o.vec3("size", g.desc.size, 1e-4, kMaxCoord, true);
        g.desc.transform = readPlacement(o, true);
        o.color3("color", g.desc.color);
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

// [SECTION] Effects

// Fields every kind shares, read before the kind-specific ones.
struct EffectCommon {
    std::string name, kind, path, attachTo;
    std::uint32_t seed = 1;
    EffectOptions options;
    DynamicsToggles toggles;
    bool traditional = false;
    std::optional<Motion> motion; // own motion, when given
};

std::uint64_t cells(glm::ivec3 d) { return std::uint64_t(d.x) * std::uint64_t(d.y) * std::uint64_t(d.z); }

bool checkDims(Context& c, const std::string& path, glm::ivec3 dims, std::uint64_t limit, const char* why) {
    if (cells(dims) > limit) {
        c.d.error(path, std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" + std::to_string(dims.z) + " = " +
                            std::to_string(cells(dims)) + " cells is too many; expected at most " + std::to_string(limit) + " (" + why + ")");
        return false;
    }
    return true;
}

// Reads "dims" (required positive) with the kind's cell limit.
void readDims(Context& c, ObjectReader& o, glm::ivec3& dims, std::uint64_t limit, const char* why) {
    if (const Json* v = o.get("dims"))
        if (auto x = readIvec3(c.d, o.at("dims"), *v, 1, kMaxAxis)) {
            if (checkDims(c, o.at("dims"), *x, limit, why)) dims = *x;
        }
}

// Effect options that depend on an anchor: a preset's object motion and its local position.
struct Placement {
    Motion motion;
    glm::mat4 parent{1.0f};
};

glm::vec3 applyPoint(const glm::mat4& m, glm::vec3 p) { return glm::vec3(m * glm::vec4(p, 1.0f)); }

// Turns a texture spec into a preset's path (a folder or empty for procedural).
// A texture-set folder named for a preset, loaded here: the presets are in
// the file-free core and take the set in memory. Errors go to the
// diagnostics at the effect's path; callers check c.d.ok() afterwards.
std::optional<TextureSet> presetSet(Context& c, const EffectCommon& e, const std::optional<TextureSpec>& t) {
    if (!t || t->kind != TextureSpec::Kind::Folder) return std::nullopt;
    Result<TextureSet> set = TextureSet::load(t->folder);
    if (!set) return c.d.error(e.path, set.error()), std::nullopt;
    return std::move(*set);
}

// Fire and steam share their fields: a lattice, textures, opacity and the
// two rates; `extra` reads what only one of them has.
template <class Desc, class Extra>
std::optional<Effect> readLatticePreset(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl, Extra extra,
                                        Result<Effect> (*make)(Materials&, const Desc&)) {
    Desc d;
    readDims(c, o, d.dims, kMaxVoxels, "grid effects");
    o.vec3("spacing", d.spacing, 1e-4, 1e3, true);
    o.vec3("position", d.position, -kMaxCoord, kMaxCoord);
    std::optional<TextureSpec> tex;
    if (const Json* t = o.get("textureSet")) tex = readTextureSpec(c, o.at("textureSet"), *t, d.textureCount, e.seed, true);
    if (tex) d.textureCount = tex->count;
    o.number("opacity", d.opacity, 1e-6, 1.0);
    o.number("propagationStepsPerSec", d.propagationStepsPerSec, 1e-3, 1e3);
    o.number("texturesPerSec", d.texturesPerSec, 0.0, 1e3);
    extra(d);
    if (!c.d.ok()) return std::nullopt;
    d.textureSet = presetSet(c, e, tex);
    if (!c.d.ok()) return std::nullopt;
    d.position = applyPoint(pl.parent, d.position);
    d.motion = pl.motion;
    d.seed = e.seed;
    Result<Effect> r = make(c.materials, d);
    if (!r) return c.d.error(e.path, r.error()), std::nullopt;
    return std::move(*r);
}

std::optional<Effect> readFire(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    return readLatticePreset<presets::FireDesc>(c, o, e, pl, [&](presets::FireDesc& d) { o.boolean("crossfade", d.crossfade); },
                                                &presets::fire);
}

std::optional<Effect> readSteam(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    return readLatticePreset<presets::SteamDesc>(c, o, e, pl, [](presets::SteamDesc&) {}, &presets::steam);
}

std::optional<Effect> readFireToSmoke(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    presets::FireToSmokeDesc d;
    readDims(c, o, d.dims, kMaxVoxels, "grid effects");
    o.vec3("spacing", d.spacing, 1e-4, 1e3, true);
    o.vec3("position", d.position, -kMaxCoord, kMaxCoord);
    o.number("split", d.split, 1e-3, 0.999);
    o.number("blend", d.blend, 0.0, 0.999);
    std::optional<TextureSpec> fireTex, smokeTex;
    if (const Json* t = o.get("fireTextureSet")) fireTex = readTextureSpec(c, o.at("fireTextureSet"), *t, 8, e.seed, true);
    if (const Json* t = o.get("smokeTextureSet")) smokeTex = readTextureSpec(c, o.at("smokeTextureSet"), *t, 8, e.seed, true);
    o.number("propagationStepsPerSec", d.propagationStepsPerSec, 1e-3, 1e3);
    o.number("texturesPerSec", d.texturesPerSec, 0.0, 1e3);
    if (!c.d.ok()) return std::nullopt;
    d.fireTextureSet = presetSet(c, e, fireTex);
    d.smokeTextureSet = presetSet(c, e, smokeTex);
    if (!c.d.ok()) return std::nullopt;
    d.position = applyPoint(pl.parent, d.position);
    d.motion = pl.motion;
    d.seed = e.seed;
    Result<Effect> r = presets::fireToSmoke(c.materials, d);
    if (!r) return c.d.error(e.path, r.error()), std::nullopt;
    return std::move(*r);
}

std::optional<Effect> readGhosts(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    presets::GhostsDesc d;
    o.number("headRadiusCells", d.headRadiusCells, 1.0, 64.0);
    o.integer("plumeCells", d.plumeCells, 0, 256);
    o.vec3("spacing", d.spacing, 1e-4, 1e3, true);
    o.vec3("position", d.position, -kMaxCoord, kMaxCoord);
    std::optional<TextureSpec> tex;
    if (const Json* t = o.get("textureSet")) tex = readTextureSpec(c, o.at("textureSet"), *t, d.textureCount, e.seed, true);
    if (tex) d.textureCount = tex->count;
    o.number("opacity", d.opacity, 1e-6, 1.0);
    o.number("texturesPerSec", d.texturesPerSec, 0.0, 1e3);
    o.number("propagationStepsPerSec", d.propagationStepsPerSec, 1e-3, 1e3);
    if (!e.attachTo.empty() || e.motion)
        c.d.error(e.path, "kind \"ghosts\" stays where it is put: it takes no \"motion\" or \"attachTo\" (place it with \"position\")");
    if (!c.d.ok()) return std::nullopt;
    d.textureSet = presetSet(c, e, tex);
    if (!c.d.ok()) return std::nullopt;
    d.position = applyPoint(pl.parent, d.position);
    d.seed = e.seed;
    Result<Effect> r = presets::ghosts(c.materials, d);
    if (!r) return c.d.error(e.path, r.error()), std::nullopt;
    return std::move(*r);
}

std::optional<Effect> readSolverKind(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl, bool dust) {
    if (e.motion)
        c.d.error(join(e.path, "motion"), "solver effects (\"" + e.kind +
                                              "\") stay put; move their source with \"sourceMotion\" or \"attachTo\" so the material trails");
    std::optional<Motion> sourceMotion;
    if (const Json* m = o.get("sourceMotion")) {
        sourceMotion = readMotion(c, o.at("sourceMotion"), *m);
        if (!e.attachTo.empty()) c.d.error(o.at("sourceMotion"), "give either \"sourceMotion\" or \"attachTo\", not both");
    }
    std::optional<TextureSpec> tex;
    const char* why = "solver effects simulate every cell every step";
    if (dust) {
        presets::DustDesc d;
        readDims(c, o, d.dims, kMaxSolverCells, why);
        o.vec3("spacing", d.spacing, 1e-4, 1e3, true);
        o.vec3("position", d.position, -kMaxCoord, kMaxCoord);
        o.vec3("sourceOffset", d.sourceOffset, -kMaxCoord, kMaxCoord);
        o.number("sourceRadius", d.sourceRadius, 1e-4, kMaxCoord);
        o.vec3("windWorld", d.windWorld, -1e3, 1e3);
        o.number("settle", d.settle, 0.0, 1e3);
        o.number("dissipation", d.dissipation, 0.0, 1e3);
        if (const Json* t = o.get("textureSet")) tex = readTextureSpec(c, o.at("textureSet"), *t, d.textureCount, e.seed, true);
        if (tex) d.textureCount = tex->count;
        if (!c.d.ok()) return std::nullopt;
        d.textureSet = presetSet(c, e, tex);
        if (!c.d.ok()) return std::nullopt;
        d.sourceMotion = sourceMotion ? *sourceMotion : pl.motion;
        d.sourceOffset = applyPoint(pl.parent, d.sourceOffset);
        d.seed = e.seed;
        Result<Effect> r = presets::dust(c.materials, d);
        if (!r) return c.d.error(e.path, r.error()), std::nullopt;
        return std::move(*r);
    }
    presets::SmokeDesc d;
    readDims(c, o, d.dims, kMaxSolverCells, why);
    o.vec3("spacing", d.spacing, 1e-4, 1e3, true);
    o.vec3("position", d.position, -kMaxCoord, kMaxCoord);
    o.vec3("sourceOffset", d.sourceOffset, -kMaxCoord, kMaxCoord);
    o.number("sourceRadius", d.sourceRadius, 1e-4, kMaxCoord);
    o.vec3("windWorld", d.windWorld, -1e3, 1e3);
    o.number("dissipation", d.dissipation, 0.0, 1e3);
    if (const Json* t = o.get("textureSet")) tex = readTextureSpec(c, o.at("textureSet"), *t, d.textureCount, e.seed, true);
    if (tex) d.textureCount = tex->count;
    o.number("texturesPerSec", d.texturesPerSec, 0.0, 1e3);
    o.integer("substeps", d.substeps, 1, 16);
    if (!c.d.ok()) return std::nullopt;
    d.textureSet = presetSet(c, e, tex);
    if (!c.d.ok()) return std::nullopt;
    d.sourceMotion = sourceMotion ? *sourceMotion : pl.motion;
    d.sourceOffset = applyPoint(pl.parent, d.sourceOffset);
    d.seed = e.seed;
    Result<Effect> r = presets::smoke(c.materials, d);
    if (!r) return c.d.error(e.path, r.error()), std::nullopt;
    return std::move(*r);
}

// A shape voxelized into a hand-made grid, in lattice cells.
struct Shape {
    enum class Type { Box, Sphere, Cone } type = Type::Box;
    glm::vec3 a{0.0f}, b{0.0f}; // box: min/max cells; sphere: centre; cone/cylinder: from/to
    float r0 = 1.0f, r1 = 1.0f; // radii (cells)
    float opacity = 1.0f;
    float softCells = 0.75f;
    // Signed distance inside the shape, cells (positive inside).
    float inside(glm::vec3 p) const {
        switch (type) {
        case Type::Box: {
            const glm::vec3 d = glm::min(p - (a - 0.5f), (b + 0.5f) - p);
            return std::min({d.x, d.y, d.z});
        }
        case Type::Sphere: return r0 - glm::length(p - a);
        case Type::Cone: break;
        }
        const glm::vec3 ab = b - a;
        const float len2 = glm::dot(ab, ab);
        const float len = std::sqrt(len2);
        if (len < 1e-6f) return -1e9f;
        const float t = glm::dot(p - a, ab) / len2;
        const float tc = std::clamp(t, 0.0f, 1.0f);
        const float radial = glm::length(p - (a + tc * ab));
        const float along = std::min(t, 1.0f - t) * len + 0.5f; // caps include the end cells
        return std::min(glm::mix(r0, r1, tc) + 0.5f - radial, along);
    }
    float weight(glm::vec3 p) const { return opacity * std::clamp(inside(p) / softCells + 0.5f, 0.0f, 1.0f); }
};

std::optional<Shape> readShape(Context& c, const std::string& path, const Json& v) {
    ObjectReader o(c.d, path, v);
    if (!o.valid()) return std::nullopt;
    const std::size_t before = c.d.count();
    Shape s;
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
        s.type = Shape::Type::Box;
        need("min"), need("max");
        o.vec3("min", s.a, -L, L);
        o.vec3("max", s.b, -L, L);
    } else if (type == "sphere") {
        s.type = Shape::Type::Sphere;
        need("center"), need("radius");
        o.vec3("center", s.a, -L, L);
        o.number("radius", s.r0, 0.0, L);
    } else if (type == "cylinder" || type == "cone") {
        s.type = Shape::Type::Cone;
        need("from"), need("to");
        o.vec3("from", s.a, -L, L);
        o.vec3("to", s.b, -L, L);
        if (type == "cylinder") {
            need("radius");
            o.number("radius", s.r0, 0.0, L);
            s.r1 = s.r0;
        } else {
            need("radiusFrom"), need("radiusTo");
            o.number("radiusFrom", s.r0, 0.0, L);
            o.number("radiusTo", s.r1, 0.0, L);
        }
    }
    o.number("opacity", s.opacity, 0.0, 1.0);
    o.number("softCells", s.softCells, 0.05, L);
    o.finish();
    if (c.d.count() != before) return std::nullopt;
    return s;
}

std::optional<PropagationDesc> readPropagation(Context& c, const std::string& path, const Json& v) {
    ObjectReader o(c.d, path, v);
    if (!o.valid()) return std::nullopt;
    const std::size_t before = c.d.count();
    PropagationDesc p;
    if (const Json* m = o.get("mode"))
        if (auto s = readChoice(c.d, o.at("mode"), *m, {"none", "fixed"})) p.mode = *s == "none" ? Propagation::None : Propagation::Fixed;
    o.ivec3("direction", p.direction, -8, 8);
    o.number("stepsPerSec", p.stepsPerSec, 1e-3, 1e3);
    int offset = int(p.offset);
    o.integer("offset", offset, 0, 1 << 20);
    p.offset = std::uint32_t(offset);
    if (p.mode == Propagation::Fixed && p.direction == glm::ivec3(0)) c.d.error(o.at("direction"), "must be non-zero for mode \"fixed\"");
    o.finish();
    if (c.d.count() != before) return std::nullopt;
    return p;
}

std::optional<CyclingDesc> readCycling(Context& c, const std::string& path, const Json& v) {
    ObjectReader o(c.d, path, v);
    if (!o.valid()) return std::nullopt;
    const std::size_t before = c.d.count();
    CyclingDesc cy;
    if (const Json* m = o.get("mode"))
        if (auto s = readChoice(c.d, o.at("mode"), *m, {"none", "ordered", "random"}))
            cy.mode = *s == "none" ? Cycling::None : *s == "ordered" ? Cycling::Ordered : Cycling::Random;
    o.number("texturesPerSec", cy.texturesPerSec, 0.0, 1e3);
    o.number("rateJitter", cy.rateJitter, 0.0, 0.99);
    o.boolean("randomStart", cy.randomStart);
    o.finish();
    if (c.d.count() != before) return std::nullopt;
    return cy;
}

// A hand-shaped grid effect: the full Effect::fromGrid control.
std::optional<Effect> readGridKind(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    glm::ivec3 dims{7, 20, 5};
    glm::vec3 spacing(0.5f);
    if (!o.has("dims")) c.d.error(o.path(), "missing \"dims\" (lattice cells [x, y, z]) for kind \"grid\"");
    readDims(c, o, dims, kMaxVoxels, "grid effects");
    o.vec3("spacing", spacing, 1e-4, 1e3, true);
    const glm::mat4 local = readPlacement(o, false);
    std::vector<Shape> shapes;
    if (const Json* s = o.get("shapes")) {
        if (!s->is_array() || s->size() > 256) c.d.error(o.at("shapes"), "expected an array of at most 256 shapes, got " + brief(*s));
        else
            for (std::size_t i = 0; i < s->size(); ++i)
                if (auto sh = readShape(c, index(o.at("shapes"), i), (*s)[i])) shapes.push_back(*sh);
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
        if (auto x = readPropagation(c, o.at("propagation"), *p)) desc.textures.propagation = *x;
    if (const Json* p = o.get("cycling"))
        if (auto x = readCycling(c, o.at("cycling"), *p)) desc.textures.cycling = *x;
    bool crossfade = true;
    o.boolean("crossfade", crossfade);
    if (!c.d.ok() || !tex || !table) return std::nullopt;

    // Voxelize: each cell takes the strongest shape covering it, scaled by
    // the effect's opacity and faded along colorAxis (sec. 2: a coarse grid
    // with opacities; the detail comes from the textures).
    const glm::vec3 axis = glm::normalize(colorAxis);
    float lo = 1e30f, hi = -1e30f;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::vec3 p((corner & 1) ? dims.x - 1 : 0, (corner & 2) ? dims.y - 1 : 0, (corner & 4) ? dims.z - 1 : 0);
        lo = std::min(lo, glm::dot(p, axis)), hi = std::max(hi, glm::dot(p, axis));
    }
    const float span = std::max(hi - lo, 1e-6f);
    std::vector<float> dense(cells(dims), 0.0f);
    std::size_t i = 0;
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x, ++i) {
                const glm::vec3 p(x, y, z);
                float w = shapes.empty() ? 1.0f : 0.0f;
                for (const Shape& s : shapes) w = std::max(w, s.weight(p));
                const float t = (glm::dot(p, axis) - lo) / span;
                dense[i] = std::clamp(w * opacity * glm::mix(1.0f, fadeTo, t), 0.0f, 1.0f);
            }
    if (std::all_of(dense.begin(), dense.end(), [](float o) { return o <= 0.0f; }))
        return c.d.error(join(e.path, "shapes"), "the shapes cover no cell of the lattice (dims) at non-zero opacity"), std::nullopt;
    Result<Grid> grid = Grid::fromDense(dims, dense, spacing);
    if (!grid) return c.d.error(e.path, grid.error()), std::nullopt;
    for (Voxel& v : grid->voxels) v.colorCoord = std::clamp((glm::dot(glm::vec3(v.cell), axis) - lo) / span, 0.0f, 1.0f);
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

void readEffects(Context& c, const std::string& path, const Json& v, const std::vector<RawGeometry>& geo,
                 const std::map<std::string, std::size_t>& geoByName, SceneFile& out) {
    if (!v.is_array() || v.size() > kMaxEffects) {
        c.d.error(path, "expected an array of at most " + std::to_string(kMaxEffects) + " effects, got " + typeName(v) + " " + brief(v));
        return;
    }
    std::uint64_t totalCells = 0;
    std::map<std::string, std::size_t> names;
    for (std::size_t i = 0; i < v.size() && !c.d.full(); ++i) {
        EffectCommon e;
        e.path = index(path, i);
        ObjectReader o(c.d, e.path, v[i]);
        if (!o.valid()) continue;
        const std::vector<std::string> kinds = {"fire", "smoke", "steam", "dust", "fireToSmoke", "ghosts", "grid"};
        if (const Json* k = o.get("kind")) {
            if (auto s = readChoice(c.d, o.at("kind"), *k, kinds)) e.kind = *s;
        } else {
            c.d.error(e.path, "missing \"kind\" (one of fire, smoke, steam, dust, fireToSmoke, ghosts, grid)");
        }
        if (e.kind.empty()) continue; // kind-specific keys cannot be checked without it
        e.name = e.kind + std::to_string(i);
        o.string("name", e.name);
        if (names.count(e.name)) c.d.error(o.at("name"), "duplicate effect name '" + e.name + "'");
        names[e.name] = i;
        std::uint32_t localSeed = std::uint32_t(i);
        o.seed("seed", localSeed);
        // Every effect's seed derives from the scene seed (so --seed changes them all).
        e.seed = c.sceneSeed * 1000003u + localSeed;
        o.boolean("enabled", e.options.enabled);
        o.number("rangeWorld", e.options.rangeWorld, 0.0, 1e9);
        o.boolean("traditional", e.traditional);
        if (const Json* t = o.get("toggles")) {
            ObjectReader to(c.d, o.at("toggles"), *t);
            to.boolean("object", e.toggles.object);
            to.boolean("global", e.toggles.global);
            to.boolean("local", e.toggles.local);
            to.finish();
        }
        o.string("attachTo", e.attachTo);
        const bool solverKind = e.kind == "smoke" || e.kind == "dust";
        if (const Json* m = o.get("motion")) {
            if (!e.attachTo.empty()) c.d.error(o.at("motion"), "an effect either has its own \"motion\" or is attached to geometry; not both");
            e.motion = readMotion(c, o.at("motion"), *m);
        }
        Placement pl;
        if (!e.attachTo.empty()) {
            if (auto a = resolveAnchor(c, geo, geoByName, e.attachTo, o.at("attachTo"))) pl.motion = a->motion, pl.parent = a->transform;
        } else if (e.motion && !solverKind) {
            pl.motion = *e.motion;
        }
        const std::size_t before = c.d.count();
        std::optional<Effect> effect;
        if (e.kind == "fire") effect = readFire(c, o, e, pl);
        else if (e.kind == "steam") effect = readSteam(c, o, e, pl);
        else if (e.kind == "fireToSmoke") effect = readFireToSmoke(c, o, e, pl);
        else if (e.kind == "ghosts") effect = readGhosts(c, o, e, pl);
        else if (e.kind == "grid") effect = readGridKind(c, o, e, pl);
        else effect = readSolverKind(c, o, e, pl, e.kind == "dust");
        o.finish();
        if (!effect || c.d.count() != before) continue;
        totalCells += effect->costCells(); // EffectKind: cells or voxels one advance evaluates
        if (totalCells > kMaxVoxels) {
            c.d.error(e.path, "the scene's effects hold more than " + std::to_string(kMaxVoxels) + " voxels/cells in all");
            return;
        }
        effect->setToggles(e.toggles);
        e.options.name = e.name;
        e.options.draw.textured = !e.traditional; // the Scene owns how each effect is drawn
        SceneEffectInfo info;
        info.name = e.name;
        info.kind = e.kind;
        info.attachedTo = e.attachTo;
        info.traditional = e.traditional;
        info.id = out.scene.add(std::move(*effect), e.options);
        out.effects.push_back(info);
    }
}

// [SECTION] Camera and output

std::optional<CameraKey> readCameraKey(Context& c, ObjectReader& o, bool needTime) {
    const std::size_t before = c.d.count();
    CameraKey k;
    if (needTime) {
        if (!o.has("time")) c.d.error(o.path(), "missing \"time\" (seconds)");
        o.number("time", k.timeSec, 0.0, kMaxSeconds);
    }
    o.vec3("position", k.position, -kMaxCoord, kMaxCoord);
    o.vec3("target", k.target, -kMaxCoord, kMaxCoord);
    float fovDeg = glm::degrees(k.fovYRad);
    o.number("fovDeg", fovDeg, 1.0, 170.0);
    k.fovYRad = glm::radians(fovDeg);
    if (glm::length(k.target - k.position) < 1e-5f) c.d.error(o.at("target"), "must differ from position");
    if (c.d.count() != before) return std::nullopt;
    return k;
}

void readCamera(Context& c, const std::string& path, const Json& v, CameraPath& cam) {
    ObjectReader o(c.d, path, v);
    if (!o.valid()) return;
    o.boolean("smooth", cam.smooth);
    o.number("near", cam.nearPlane, 1e-5, 1e5);
    o.number("far", cam.farPlane, 1e-4, 1e9);
    if (!(cam.farPlane > cam.nearPlane)) c.d.error(o.at("far"), "must be greater than near");
    if (const Json* k = o.get("keys")) {
        for (const char* key : {"position", "target", "fovDeg"})
            if (o.has(key)) c.d.error(o.at(key), "give the camera either \"keys\" or a single position/target/fovDeg, not both");
        if (!k->is_array() || k->empty() || k->size() > kMaxKeys) {
            c.d.error(o.at("keys"), "expected an array of 1 to " + std::to_string(kMaxKeys) + " camera keys, got " + brief(*k));
        } else {
            for (std::size_t i = 0; i < k->size() && !c.d.full(); ++i) {
                ObjectReader ko(c.d, index(o.at("keys"), i), (*k)[i]);
                if (!ko.valid()) continue;
                auto key = readCameraKey(c, ko, true);
                ko.finish();
                if (!key) continue;
                if (!cam.keys.empty() && !(key->timeSec > cam.keys.back().timeSec))
                    c.d.error(join(ko.path(), "time"), "camera key times must increase strictly");
                cam.keys.push_back(*key);
            }
        }
    } else if (auto key = readCameraKey(c, o, false)) {
        cam.keys = {*key};
    }
    o.finish();
}

void readOutput(Context& c, const std::string& path, const Json& v, OutputSettings& out) {
    ObjectReader o(c.d, path, v);
    if (!o.valid()) return;
    if (const Json* s = o.get("size")) {
        if (!s->is_array() || s->size() != 2) {
            c.d.error(o.at("size"), "expected [width, height] in pixels, got " + brief(*s));
        } else {
            auto w = readInt(c.d, index(o.at("size"), 0), (*s)[0], 16, 8192);
            auto h = readInt(c.d, index(o.at("size"), 1), (*s)[1], 16, 8192);
            if (w && h) out.size = {int(*w), int(*h)};
        }
    }
    o.integer("frames", out.frames, 1, 100000);
    o.number("fps", out.fps, 0.1, 240.0);
    o.color3("background", out.background);
    if (const Json* n = o.get("name"))
        if (auto s = readString(c.d, o.at("name"), *n)) {
            const bool safe = !s->empty() && s->size() <= 64 && std::all_of(s->begin(), s->end(), [](char ch) {
                return std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_';
            });
            if (!safe) c.d.error(o.at("name"), "expected 1 to 64 letters, digits, '-' or '_' (it names output files), got " + brief(*n));
            else out.name = *s;
        }
    o.finish();
}

// [SECTION] Entry points

Result<SceneFile> parse(const std::string& text, const std::string& path, Materials& materials, const SceneFileOptions& options) {
    if (text.size() > kMaxFileBytes)
        return makeError(path + ": file is " + std::to_string(text.size()) + " bytes; scene files are at most " + std::to_string(kMaxFileBytes));
    if (auto at = tooDeep(text)) {
        const LineCol lc = lineColumn(text, *at);
        return makeError(path + ":" + std::to_string(lc.line) + ":" + std::to_string(lc.column) + ": nesting deeper than " +
                         std::to_string(kMaxDepth) + " levels");
    }
    Json root;
    try {
        root = Json::parse(text);
    } catch (const Json::parse_error& e) {
        // e.byte is 1-based: the position of the character that failed.
        const LineCol lc = lineColumn(text, e.byte == 0 ? 0 : e.byte - 1);
        return makeError(path + ":" + std::to_string(lc.line) + ":" + std::to_string(lc.column) + ": syntax error: " + syntaxReason(e.what()));
    } catch (const Json::out_of_range& e) {
        // A literal like 1e999: the JSON library refuses it while parsing.
        std::string what = e.what();
        const std::size_t p = what.find("] ");
        return makeError(path + ": " + (p == std::string::npos ? what : what.substr(p + 2)) + " (expected a finite number)");
    }

    Diagnostics d(path, options.maxErrors);
    SceneFile out;
    out.path = path;
    Context c{d, fs::path(path).parent_path(), materials};
    ObjectReader o(d, "", root);
    if (!o.valid()) return makeError(path + ": expected a JSON object {\"format\": \"splatfx-scene\", \"version\": 1, ...}");

    // Format and version first: a file of another kind gets one clear message.
    const Json* format = o.get("format");
    if (!format || !format->is_string() || format->get<std::string>() != kSceneFileFormat)
        return makeError(path + ": format: expected \"" + std::string(kSceneFileFormat) + "\", got " +
                         (format ? brief(*format) : std::string("nothing")) + " (is this a splatfx scene file?)");
    const Json* version = o.get("version");
    if (!version || !version->is_number_integer() || version->get<std::int64_t>() != kSceneFileVersion)
        return makeError(path + ": version: expected " + std::to_string(kSceneFileVersion) + ", got " +
                         (version ? brief(*version) : std::string("nothing")) +
                         (version && version->is_number_integer() && version->get<std::int64_t>() > kSceneFileVersion
                              ? " (written by a newer splatfx)" : ""));
    o.string("title", out.title);
    o.seed("seed", out.seed);
    if (options.seed) out.seed = *options.seed;
    c.sceneSeed = out.seed;
    out.output.name = fs::path(path).parent_path().filename().string();
    if (const Json* v = o.get("output")) readOutput(c, "output", *v, out.output);
    if (out.output.name.empty() || !std::all_of(out.output.name.begin(), out.output.name.end(), [](char ch) {
            return std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_';
        }))
        out.output.name = "scene";
    if (const Json* v = o.get("camera")) readCamera(c, "camera", *v, out.camera);
    if (out.camera.keys.empty()) out.camera.keys = {CameraKey{}};

    std::vector<RawGeometry> geo;
    std::map<std::string, std::size_t> geoByName;
    if (const Json* v = o.get("geometry")) {
        geo = readGeometryList(c, "geometry", *v);
        for (std::size_t i = 0; i < geo.size(); ++i) {
            if (geoByName.count(geo[i].desc.name)) d.error(join(geo[i].path, "name"), "duplicate geometry name '" + geo[i].desc.name + "'");
            geoByName[geo[i].desc.name] = i;
        }
        for (RawGeometry& g : geo) {
            GeometryDesc desc = g.desc;
            if (!g.attachTo.empty()) {
                if (auto a = resolveAnchor(c, geo, geoByName, g.attachTo, join(g.path, "attachTo"))) {
                    desc.motion = a->motion;
                    desc.transform = a->transform * g.desc.transform;
                    desc.attachedTo = g.attachTo;
                }
            }
            out.geometry.push_back(std::move(desc));
        }
    }
    if (const Json* v = o.get("effects")) readEffects(c, "effects", *v, geo, geoByName, out);
    o.finish();
    if (!d.ok()) return makeError(d.message());
    return out;
}

} // namespace
} // namespace scenefile

Result<SceneFile> parseSceneFile(const std::string& text, const std::string& path, Materials& materials, const SceneFileOptions& options) {
    assert(options.maxErrors >= 1 && "SceneFileOptions::maxErrors must be >= 1");
    // The JSON library reports through exceptions; none may cross the API.
    try {
        return scenefile::parse(text, path, materials, options);
    } catch (const std::bad_alloc&) {
        return makeError(path + ": out of memory while reading the scene");
    } catch (const std::exception& e) {
        return makeError(path + ": cannot read the scene: " + e.what());
    }
}

Result<SceneFile> loadSceneFile(const std::string& path, Materials& materials, const SceneFileOptions& options) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        return makeError(path + ": scene file not found" + (std::filesystem::exists(path, ec) ? " (not a regular file)" : ""));
    const auto size = std::filesystem::file_size(path, ec);
    if (ec) return makeError(path + ": cannot read: " + ec.message());
    if (size > scenefile::kMaxFileBytes)
        return makeError(path + ": file is " + std::to_string(size) + " bytes; scene files are at most " + std::to_string(scenefile::kMaxFileBytes));
    std::ifstream in(path, std::ios::binary);
    if (!in) return makeError(path + ": cannot open for reading");
    std::ostringstream text;
    text << in.rdbuf();
    return parseSceneFile(text.str(), path, materials, options);
}

} // namespace splatfx
