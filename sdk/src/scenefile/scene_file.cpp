// Scene files: versioned JSON to a Scene, geometry, camera path and output
// settings (docs/scene-format.md). This file checks the text and reads the
// top level; the rest is read by:
//   shared.cpp         placement, motion, texture sets, colour tables
//   geometry.cpp       geometry list and attachment chains
//   effects.cpp        the keys every effect kind takes
//   kinds.cpp          the table of effect kinds and geometry types, whose
//                      readers are in kinds/ (one a file)
//   camera_output.cpp  camera path and output settings
//   lights.cpp         lights, the scene shadow, each effect's lighting
//   fog_block.cpp      the "fog" block
//
// [SECTION] Text checks (size, nesting, syntax with line and column, duplicate keys)
// [SECTION] Entry points
#include "splatfx/scene_file.hpp"

#include <algorithm>
#include <cassert>
#include <cctype>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "scenefile/reader.hpp"

namespace splatfx {
namespace scenefile {
namespace {

namespace fs = std::filesystem;

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

// Duplicate object keys. nlohmann::json keeps the last of them, so
// `"density": 0.5, "density": 1e6` would silently become 1e6; its parser
// callback gives no byte position, so this scans the text (already parsed,
// hence valid JSON) once: a stack of open containers, each object holding
// the keys it has seen with where. Linear in the text; what it keeps is at
// most the text's keys, and the nesting is bounded by tooDeep.
struct KeyScanner {
    struct Place {
        std::size_t line, column;
    };
    struct Open {
        bool object = false;
        std::string_view key;  // object: the key whose value is being read
        std::size_t index = 0; // array: the element being read
        std::unordered_map<std::string_view, Place> seen;
    };
    const std::string& text;
    const std::string& file;
    std::size_t maxReports;
    std::vector<std::string> reports{};
    std::deque<std::string> decoded{}; // keys written with escapes, decoded (the views point here or into text)

    // The path of a key in the innermost open object, as messages write paths.
    static std::string pathOf(const std::vector<Open>& stack, std::string_view key) {
        std::string p;
        for (std::size_t i = 0; i + 1 < stack.size(); ++i) p = stack[i].object ? join(p, std::string(stack[i].key)) : index(p, stack[i].index);
        return join(p, std::string(key));
    }

    // The key as the JSON library reads it (escapes decoded: "\u0061" is "a").
    std::string_view decode(std::size_t open, std::size_t close) {
        const std::string_view raw = std::string_view(text).substr(open, close - open + 1);
        if (raw.find('\\') == std::string_view::npos) return raw.substr(1, raw.size() - 2);
        return decoded.emplace_back(Json::parse(raw).get<std::string>());
    }

    void run() {
        std::vector<Open> stack;
        std::size_t line = 1, lineStart = 0;
        bool expectKey = false;
        for (std::size_t i = 0; i < text.size() && reports.size() < maxReports; ++i) {
            const char c = text[i];
            if (c == '\n') {
                ++line, lineStart = i + 1;
            } else if (c == '{' || c == '[') {
                stack.emplace_back().object = c == '{';
                expectKey = c == '{';
            } else if (c == '}' || c == ']') {
                if (!stack.empty()) stack.pop_back();
                expectKey = false;
            } else if (c == ',') {
                if (!stack.empty() && !stack.back().object) ++stack.back().index;
                expectKey = !stack.empty() && stack.back().object;
            } else if (c == '"') {
                const std::size_t open = i;
                for (++i; i < text.size() && text[i] != '"'; ++i)
                    if (text[i] == '\\') ++i; // valid JSON: strings hold no raw newline
                if (!expectKey || stack.empty()) continue;
                expectKey = false;
                Open& o = stack.back();
                o.key = decode(open, i);
                const Place here{line, open - lineStart + 1};
                const auto [it, fresh] = o.seen.emplace(o.key, here);
                if (fresh) continue;
                const auto at = [&](const Place& p) { return file + ":" + std::to_string(p.line) + ":" + std::to_string(p.column); };
                reports.push_back(at(here) + ": " + pathOf(stack, o.key) + ": duplicate key; it is also given at " + at(it->second) +
                                  " (JSON keeps only one of them: remove the other)");
            }
        }
    }
};

// nlohmann's messages start with "[json.exception.parse_error.101] parse
// error at line L, column C: "; keep only the explanation after it.
std::string syntaxReason(const std::string& what) {
    const std::size_t p = what.find(": ");
    std::string reason = p == std::string::npos ? what : what.substr(p + 2);
    if (reason.rfind("syntax error while parsing ", 0) == 0) reason = reason.substr(27);
    return reason;
}

// [SECTION] Entry points

Result<SceneFile> parse(const std::string& text, const std::string& path, Materials& materials, const SceneFileOptions& options) {
    if (text.size() > kMaxFileBytes)
        return makeError(path + ": file is " + std::to_string(text.size()) + " bytes; scene files are at most " + std::to_string(kMaxFileBytes));
    // A NUL byte ends the text for some readers and not others: refuse it where it is,
    // rather than silently ignore what follows it.
    if (const std::size_t nul = text.find('\0'); nul != std::string::npos) {
        const LineCol lc = lineColumn(text, nul);
        return makeError(path + ":" + std::to_string(lc.line) + ":" + std::to_string(lc.column) +
                         ": a NUL byte (scene files are text; is this the right file?)");
    }
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
        // A literal like 1e999: the JSON library refuses it while parsing and
        // gives no position, so find the literal it names to report where it is.
        std::string what = e.what();
        const std::size_t p = what.find("] ");
        what = p == std::string::npos ? what : what.substr(p + 2);
        std::string where = path;
        const std::size_t q0 = what.find('\''), q1 = q0 == std::string::npos ? q0 : what.find('\'', q0 + 1);
        if (q1 != std::string::npos)
            if (const std::size_t at = text.find(what.substr(q0 + 1, q1 - q0 - 1)); at != std::string::npos) {
                const LineCol lc = lineColumn(text, at);
                where += ":" + std::to_string(lc.line) + ":" + std::to_string(lc.column);
            }
        return makeError(where + ": " + what + " (expected a finite number)");
    }

    KeyScanner keys{text, path, std::size_t(std::max(options.maxErrors, 1))};
    keys.run();
    if (!keys.reports.empty()) {
        std::string m;
        for (const std::string& r : keys.reports) m += (m.empty() ? "" : "\n") + r;
        return makeError(m);
    }

    Diagnostics d(path, options.maxErrors);
    SceneFile out;
    out.path = path;
    Context c{d, fs::path(path).parent_path(), materials};
    c.budgets = options.budgets;
    out.scene.setBudgets(options.budgets); // the same lightingBytes holds while it plays
    ObjectReader o(d, "", root);
    if (!o.valid()) return makeError(path + ": expected a JSON object {\"format\": \"splatfx-scene\", \"version\": 1, ...}");

    // Format and version first: a file of another kind gets one clear message.
    const Json* format = o.get("format");
    if (!format || !format->is_string() || format->get<std::string>() != kSceneFileFormat)
        return makeError(path + ": format: expected \"" + std::string(kSceneFileFormat) + "\", got " +
                         (format ? brief(*format) : std::string("nothing")) + " (is this a splatfx scene file?)");
    const Json* version = o.get("version");
    if (!version || !version->is_number_integer() || version->get<std::int64_t>() != kSceneFileVersion)
        return makeError(
            path + ": version: expected " + std::to_string(kSceneFileVersion) + ", got " + (version ? brief(*version) : std::string("nothing")) +
            (version && version->is_number_integer() && version->get<std::int64_t>() > kSceneFileVersion ? " (written by a newer splatfx)" : ""));
    o.string("title", out.title);
    o.seed("seed", out.seed);
    if (options.seed) out.seed = *options.seed;
    c.sceneSeed = out.seed;
    out.output.name = fs::path(path).parent_path().filename().string();
    if (const Json* v = o.get("output")) readOutput(c, "output", *v, out.output);
    if (out.output.name.empty() || !std::all_of(out.output.name.begin(), out.output.name.end(),
                                                [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_'; }))
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
    c.geometry = &geo, c.geometryByName = &geoByName;
    if (const Json* v = o.get("effects")) readEffects(c, "effects", *v, geo, geoByName, out);
    if (const Json* v = o.get("lights")) readLights(c, "lights", *v, out); // issue 16
    if (const Json* v = o.get("sceneShadow")) readSceneShadow(c, "sceneShadow", *v, out);
    if (d.ok()) checkLightingBudget(c, out);                                  // tables are built at the first frame: estimated now
    if (const Json* v = o.get("fog")) readFog(c, "fog", *v, out.scene);       // fog_block.cpp (issue 14)
    if (const Json* v = o.get("volumes")) readVolumes(c, "volumes", *v, out); // [clouds]
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
    } catch (const std::bad_alloc&) { return makeError(path + ": out of memory while reading the scene"); } catch (const std::exception& e) {
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
