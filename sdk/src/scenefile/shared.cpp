// Scene files: the pieces several readers share (placement, motion, texture
// sets, colour tables, lattice dims).
#include <algorithm>
#include <filesystem>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "scenefile/reader.hpp"
#include "splatfx/image_io.hpp"
#include "splatfx/presets.hpp"
#include "splatfx/texture_set_io.hpp"

namespace splatfx::scenefile {

namespace fs = std::filesystem;

namespace {

glm::quat eulerDeg(glm::vec3 deg) {
    const glm::vec3 r = glm::radians(deg);
    // X first, then Y, then Z: R = Rz * Ry * Rx.
    return glm::angleAxis(r.z, glm::vec3(0, 0, 1)) * glm::angleAxis(r.y, glm::vec3(0, 1, 0)) * glm::angleAxis(r.x, glm::vec3(1, 0, 0));
}

std::optional<Easing> readEasing(Diagnostics& d, const std::string& path, const Json& v) {
    auto s = readChoice(d, path, v, {"linear", "smooth", "step"});
    if (!s) return std::nullopt;
    return *s == "linear" ? Easing::Linear : *s == "smooth" ? Easing::Smooth : Easing::Step;
}

bool textureFolderExists(const std::string& folder) {
    std::error_code ec;
    return fs::is_directory(folder, ec) && fs::is_regular_file(fs::path(folder) / "manifest.json", ec);
}

// King et al. 1999, sec. 4 / Fig. 11: the file is read here; the windows are
// cut by TextureSet::sampleImage, which works on the image in memory.
Result<TextureSet> sampleImageFile(const TextureSpec& t) {
    Result<Image> img = readImage(t.image);
    if (!img) return makeError(img.error());
    return TextureSet::sampleImage(
        *img, {.count = t.count, .size = t.size, .seed = t.seed, .keepColor = t.keepColor, .sourceName = "image '" + t.image + "'"});
}

bool checkDims(Context& c, const std::string& path, glm::ivec3 dims, std::uint64_t limit, const char* field, const char* why) {
    const std::string what = std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" + std::to_string(dims.z) + " (" + why + ")";
    if (Status s = checkBudget(what, cells(dims), "cells", limit, field); !s) {
        c.d.error(path, s.error());
        return false;
    }
    return true;
}

} // namespace

std::string resolvePath(const Context& c, const std::string& p) {
    fs::path q(p);
    if (q.is_relative()) q = c.baseDir / q;
    return q.lexically_normal().string();
}

glm::mat4 readPlacement(ObjectReader& o, bool withScale) {
    glm::vec3 pos(0.0f), rot(0.0f), scale(1.0f);
    o.vec3("position", pos, -kMaxCoord, kMaxCoord);
    o.vec3("rotationDeg", rot, -36000.0, 36000.0);
    if (withScale) o.vec3("scale", scale, 1e-4, 1e4, true);
    return glm::translate(glm::mat4(1.0f), pos) * glm::mat4_cast(eulerDeg(rot)) * glm::scale(glm::mat4(1.0f), scale);
}

// A motion object: keys plus procedural motion (motion.hpp).
std::optional<Motion> readMotion(Context& c, const std::string& path, const Json& v) {
    ObjectReader o(c.d, path, v);
    if (!o.valid()) return std::nullopt;
    const std::size_t before = c.d.count();
    std::vector<Keyframe> keys;
    if (const Json* k = o.get("keys")) {
        if (!k->is_array() || k->size() > kMaxKeys) {
            c.d.error(o.at("keys"), "expected an array of at most " + std::to_string(kMaxKeys) + " keyframes, got " + typeName(*k) + " " + brief(*k));
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

std::optional<TextureSpec> readTextureSpec(Context& c, const std::string& path, const Json& v, int defaultCount, std::uint32_t seed,
                                           bool presetOnly) {
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
            // Each window becomes size^2 float RGBA texels: 256 windows of 1024^2 would be 4 GiB
            // per effect, so the set's texels are budgeted before anything is read.
            if (Status s = checkBudget("count " + std::to_string(t.count) + " x size " + std::to_string(t.size) + "^2",
                                       std::uint64_t(t.count) * std::uint64_t(t.size) * std::uint64_t(t.size), "texels", c.budgets.sampledTexels,
                                       "sampledTexels");
                !s)
                c.d.error(po.path(), s.error() + "; or use fewer or smaller windows");
            po.finish();
            if (!image.empty()) {
                t.image = resolvePath(c, image);
                std::error_code ec;
                if (!fs::is_regular_file(t.image, ec))
                    c.d.error(join(po.path(), "image"), "image file '" + image + "' not found (looked for '" + t.image + "')");
            }
        }
    }
    o.finish();
    if (c.d.count() != before) return std::nullopt;
    return t;
}

Result<TextureSet> buildTextureSet(const TextureSpec& t) {
    switch (t.kind) {
    case TextureSpec::Kind::Folder: return loadTextureSet(t.folder);
    case TextureSpec::Kind::Faces: return presets::proceduralFaces(t.count, t.size, t.seed);
    case TextureSpec::Kind::SampleImage: return sampleImageFile(t);
    case TextureSpec::Kind::Procedural: break;
    }
    return TextureSet::turbulence(
        {.count = t.count, .size = t.size, .seed = t.seed, .octaves = t.octaves, .baseFrequency = t.baseFrequency, .loopRadius = t.loopRadius});
}

std::optional<TextureSet> presetSet(Context& c, const std::string& effectPath, const std::optional<TextureSpec>& t) {
    if (!t || t->kind != TextureSpec::Kind::Folder) return std::nullopt;
    std::error_code ec;
    const std::string key = std::filesystem::weakly_canonical(t->folder, ec).string();
    if (!ec)
        if (auto it = c.folders.find(key); it != c.folders.end()) return it->second;
    Result<TextureSet> set = loadTextureSet(t->folder);
    if (!set) return c.d.error(effectPath, set.error()), std::nullopt;
    if (!ec) c.folders.emplace(key, *set);
    return std::move(*set);
}

std::optional<TextureSpec> readPresetTextureSet(Context& c, ObjectReader& o, std::uint32_t seed, int& count) {
    std::optional<TextureSpec> tex;
    if (const Json* t = o.get("textureSet")) tex = readTextureSpec(c, o.at("textureSet"), *t, count, seed, true);
    if (tex) count = tex->count;
    return tex;
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
        c.d.error(path,
                  "expected \"fire\", \"smoke\", \"steam\", \"dust\", {\"constant\": [r, g, b, a]} or {\"gradient\": [[t, [r, g, b, a]], ...]}");
    }
    o.finish();
    return out;
}

std::uint64_t cells(glm::ivec3 d) { return std::uint64_t(d.x) * std::uint64_t(d.y) * std::uint64_t(d.z); }

std::string dimsText(glm::ivec3 d) { return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z); }

void readDims(Context& c, ObjectReader& o, glm::ivec3& dims, std::uint64_t limit, const char* field, const char* why) {
    if (const Json* v = o.get("dims"))
        if (auto x = readIvec3(c.d, o.at("dims"), *v, 1, kMaxAxis)) {
            if (checkDims(c, o.at("dims"), *x, limit, field, why)) dims = *x;
        }
}

glm::vec3 applyPoint(const glm::mat4& m, glm::vec3 p) { return glm::vec3(m * glm::vec4(p, 1.0f)); }

// "propagation" and "cycling" objects (kinds grid and vdb).
void readPropagation(Context& c, ObjectReader& o, PropagationDesc& p, bool allowVelocity) {
    if (const Json* m = o.get("mode")) {
        const std::vector<std::string> modes =
            allowVelocity ? std::vector<std::string>{"none", "fixed", "velocity"} : std::vector<std::string>{"none", "fixed"};
        if (auto s = readChoice(c.d, o.at("mode"), *m, modes))
            p.mode = *s == "none" ? Propagation::None : *s == "fixed" ? Propagation::Fixed : Propagation::Velocity;
    }
    o.ivec3("direction", p.direction, -8, 8);
    o.number("stepsPerSec", p.stepsPerSec, 1e-3, 1e3);
    int offset = int(p.offset);
    o.integer("offset", offset, 0, 1 << 20);
    p.offset = std::uint32_t(offset);
    if (p.mode == Propagation::Fixed && p.direction == glm::ivec3(0)) c.d.error(o.at("direction"), "must be non-zero for mode \"fixed\"");
}

void readCycling(Context& c, ObjectReader& o, CyclingDesc& cy) {
    if (const Json* m = o.get("mode"))
        if (auto s = readChoice(c.d, o.at("mode"), *m, {"none", "ordered", "random"}))
            cy.mode = *s == "none" ? Cycling::None : *s == "ordered" ? Cycling::Ordered : Cycling::Random;
    o.number("texturesPerSec", cy.texturesPerSec, 0.0, 1e3);
    o.number("rateJitter", cy.rateJitter, 0.0, 0.99);
    o.boolean("randomStart", cy.randomStart);
}

} // namespace splatfx::scenefile
