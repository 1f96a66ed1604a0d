// The scene file's top-level "fog" block (docs/scene-format.md, "fog"):
// the analytic fog of fog.hpp, validated by Fog::create (whose message names
// the term) after the keys are checked here (each error names the field).
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "scenefile/reader.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/scene.hpp"

namespace splatfx::scenefile {
namespace {

glm::dvec3 dv(glm::vec3 v) { return glm::dvec3(v); }

// "wind": a velocity [x, y, z] (constant) or [{"timeSec": t, "velocity": [x, y, z]}, ...] (sorted keys).
void readWind(Context& c, const std::string& path, const Json& v, FogWind& wind) {
    if (v.is_array() && v.size() == 3 && std::all_of(v.begin(), v.end(), [](const Json& e) { return e.is_number(); })) {
        if (auto vel = readVec3(c.d, path, v, -kMaxCoord, kMaxCoord)) wind = FogWind::constant(dv(*vel));
        return;
    }
    if (!v.is_array() || v.empty() || v.size() > kMaxKeys) {
        c.d.error(path, "expected a velocity [x, y, z] or a list of {\"timeSec\", \"velocity\"} keys, got " + brief(v));
        return;
    }
    wind.keys.clear();
    for (std::size_t i = 0; i < v.size(); ++i) {
        const std::string kp = path + "[" + std::to_string(i) + "]";
        auto key = readObject<FogWindKey>(c, kp, v[i], [](Context&, ObjectReader& o, FogWindKey& k) {
            o.number("timeSec", k.timeSec, -kMaxSeconds, kMaxSeconds);
            glm::vec3 vel(0.0f);
            o.vec3("velocity", vel, -kMaxCoord, kMaxCoord);
            k.velocity = dv(vel);
        });
        if (!key) continue;
        if (!wind.keys.empty() && key->timeSec < wind.keys.back().timeSec) c.d.error(join(kp, "timeSec"), "wind keys must be sorted by time");
        wind.keys.push_back(*key);
    }
}

int axisIndex(Context& c, const std::string& path, const Json& v) {
    auto a = readChoice(c.d, path, v, {"x", "y", "z"});
    return a ? int((*a)[0] - 'x') : -1;
}

void readTerm(Context& c, ObjectReader& o, FogTerm& t) {
    std::string kind;
    if (const Json* k = o.get("kind")) {
        if (auto s = readChoice(c.d, o.at("kind"), *k, {"constant", "cosine", "cosineProduct", "polynomial", "point", "line", "sphere"})) kind = *s;
    } else {
        c.d.error(o.at("kind"), "required: constant, cosine, cosineProduct, polynomial, point, line or sphere");
    }
    o.number("weight", t.weight, -1e6, 1e6);
    o.number("windFactor", t.windFactor, -1e3, 1e3);
    auto dir = [&](const char* key, glm::dvec3 def) {
        glm::vec3 d = glm::vec3(def);
        o.vec3(key, d, -1e6, 1e6);
        if (!(glm::length(d) > 0.0f)) {
            c.d.error(o.at(key), "must be a non-zero direction");
            return def;
        }
        return glm::normalize(dv(d));
    };
    if (kind == "constant") {
        t.kind = FogTermKind::Constant;
    } else if (kind == "cosine" || kind == "cosineProduct") {
        t.kind = kind == "cosine" ? FogTermKind::Cosine : FogTermKind::CosineProduct;
        double k = 1.0, phase = 0.0;
        o.number("k", k, 0.0, 1e6);
        o.number("phase", phase, -1e6, 1e6);
        t.wave = k * dir("direction", {1.0, 0.0, 0.0});
        t.phase = phase;
        if (t.kind == FogTermKind::CosineProduct) {
            double k2 = 1.0, phase2 = 0.0;
            o.number("k2", k2, 0.0, 1e6);
            o.number("phase2", phase2, -1e6, 1e6);
            t.wave2 = k2 * dir("direction2", {0.0, 0.0, 1.0});
            t.phase2 = phase2;
        }
    } else if (kind == "polynomial") {
        int axis = 0;
        if (const Json* a = o.get("axis")) axis = std::max(axisIndex(c, o.at("axis"), *a), 0);
        std::vector<double> coeffs;
        if (const Json* cv = o.get("coeffs")) {
            if (!cv->is_array() || cv->empty() || cv->size() > std::size_t(kFogMaxDegree + 1))
                c.d.error(o.at("coeffs"), "expected 1 to " + std::to_string(kFogMaxDegree + 1) +
                                              " numbers (degree <= " + std::to_string(kFogMaxDegree) + "), got " + brief(*cv));
            else
                for (std::size_t i = 0; i < cv->size(); ++i)
                    if (auto x = readNumber(c.d, o.at("coeffs") + "[" + std::to_string(i) + "]", (*cv)[i], -1e6, 1e6)) coeffs.push_back(*x);
        } else {
            c.d.error(o.at("coeffs"), "required for a polynomial term");
        }
        double halfSize = 1.0, centre = 0.0;
        o.number("halfSize", halfSize, 1e-6, kMaxCoord);
        o.number("centre", centre, -kMaxCoord, kMaxCoord);
        FogCellMode mode = FogCellMode::Periodic;
        if (const Json* m = o.get("mode"))
            if (auto s = readChoice(c.d, o.at("mode"), *m, {"periodic", "zeroOutside"}))
                mode = *s == "periodic" ? FogCellMode::Periodic : FogCellMode::ZeroOutside;
        const double w = t.weight, wf = t.windFactor;
        t = FogTerm::polynomial1D(w, axis, coeffs, halfSize, mode, centre);
        t.windFactor = wf;
    } else if (kind == "point" || kind == "line" || kind == "sphere") {
        t.kind = kind == "point" ? FogTermKind::Point : kind == "line" ? FogTermKind::Line : FogTermKind::Sphere;
        glm::vec3 centre(0.0f);
        o.vec3(kind == "line" ? "point" : "centre", centre, -kMaxCoord, kMaxCoord);
        t.centre = dv(centre);
        if (t.kind == FogTermKind::Line) t.axis = dir("axis", {0.0, 1.0, 0.0});
        if (t.kind == FogTermKind::Sphere) o.number("radius", t.radius, 0.0, kMaxCoord);
        o.number("c", t.c, 1e-12, 1e12);
        o.number("d", t.d, 0.0, 1e12);
        if (const Json* f = o.get("form"))
            if (auto s = readChoice(c.d, o.at("form"), *f, {"density", "segment"}))
                t.form = *s == "segment" ? FogPotentialForm::Segment : FogPotentialForm::Density;
    }
}

// A whole fog scaled from its own units to the world's: positions and sizes
// times s, wave numbers over s, extinction (per unit length) over s, so the
// optical depth of a scaled path is unchanged; `density` multiplies every weight.
void scaleFog(FogDesc& f, double s, double density) {
    for (FogTerm& t : f.terms) {
        // A density is per unit length; the paper's segment form is a depth already.
        t.weight *= t.form == FogPotentialForm::Segment ? density : density / s;
        t.wave /= s, t.wave2 /= s;
        t.cellCentre *= s, t.cellHalfSize *= s;
        t.centre *= s, t.radius *= s;
        t.d /= s * s; // 1 / (c + d (r / s)^2)
    }
    for (FogWindKey& k : f.wind.keys) k.velocity *= s;
}

} // namespace

void readFog(Context& c, const std::string& path, const Json& v, Scene& scene) {
    const std::size_t before = c.d.count();
    ObjectReader o(c.d, path, v);
    if (!o.valid()) return;
    FogDesc desc;
    if (const Json* p = o.get("preset")) {
        if (auto s = readChoice(c.d, o.at("preset"), *p, {"fig6", "fig7", "fig8"}))
            desc = *s == "fig6" ? paperFig6Fog() : *s == "fig7" ? paperFig7Fog() : paperFig8Fog();
    }
    double scale = 1.0, density = 1.0;
    o.number("scale", scale, 1e-6, 1e6);
    o.number("density", density, 0.0, 1e6);
    if (const Json* t = o.get("terms")) {
        if (!t->is_array() || t->size() > 256) {
            c.d.error(o.at("terms"), "expected a list of at most 256 terms, got " + brief(*t));
        } else {
            for (std::size_t i = 0; i < t->size(); ++i) {
                auto term = readObject<FogTerm>(c, o.at("terms") + "[" + std::to_string(i) + "]", (*t)[i], readTerm);
                if (term) desc.terms.push_back(*term);
            }
        }
    }
    std::optional<FogWind> wind; // world units per second: not scaled
    if (const Json* w = o.get("wind")) readWind(c, o.at("wind"), *w, wind.emplace());
    glm::vec3 colour = glm::vec3(desc.colour);
    o.color3("colour", colour);
    desc.colour = dv(colour);
    o.number("farDistance", desc.farDistanceWorld, 0.0, 1e12);
    o.finish();
    if (c.d.count() != before) return;
    const double far = desc.farDistanceWorld; // in world units already
    scaleFog(desc, scale, density);
    desc.farDistanceWorld = far;
    if (wind) desc.wind = *wind;
    const std::size_t terms = desc.terms.size();
    // The GLSL the terms generate is compiled into every pass that fogs, in
    // time growing faster than its size: it is the fog's cost, budgeted
    // before any GL sees it, here against Budgets (the field a scene file's
    // user raises) instead of FogDesc::shaderBudgetBytes.
    desc.shaderBudgetBytes = std::numeric_limits<std::uint64_t>::max();
    auto fog = Fog::create(std::move(desc));
    if (!fog) {
        c.d.error(path, fog.error());
        return;
    }
    if (auto glsl = fogGlsl(*fog)) {
        if (Status s = checkBudget("the shader of its " + std::to_string(terms) + " terms", glsl->termBytes, "bytes of GLSL",
                                   c.budgets.fogShaderBytes, "fogShaderBytes");
            !s) {
            c.d.error(o.has("terms") ? o.at("terms") : path, s.error());
            return;
        }
    }
    scene.setFog(std::move(*fog));
}

} // namespace splatfx::scenefile
