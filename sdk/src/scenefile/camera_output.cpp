// Scene files: the camera path and the output settings.
#include <algorithm>
#include <cctype>
#include <cstdio>

#include "scenefile/reader.hpp"

namespace splatfx::scenefile {
namespace {

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

} // namespace

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
    // Frame i shows time i / fps: the last one must be a time the scene can be prepared at.
    if (const double last = (out.frames - 1) / double(out.fps); last > kMaxTimeSec) {
        char buf[256];
        std::snprintf(buf, sizeof buf,
                      "%d frames at %g fps end at %g s, later than %g s (kMaxTimeSec, about 72.8 hours), the latest time the effects' "
                      "dynamics hold exactly; fewer frames or a higher fps",
                      out.frames, double(out.fps), last, kMaxTimeSec);
        c.d.error(o.at("frames"), buf);
    }
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

} // namespace splatfx::scenefile
