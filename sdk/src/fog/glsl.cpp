// GLSL 4.50 for the fog's closed forms: the shared logic in fog.glsl
// (render/gl/glsl), the terms of one fog generated here; and the float
// parameters that feed them (computed in double relative to a reference
// point). The code mirrors integrals.cpp branch for branch; docs/fog.md explains each.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string>

#include "fog/frozen.hpp"
#include "glsl/glsl_files.hpp"
#include "splatfx/fog.hpp"

namespace splatfx {

namespace {

using fogdetail::Frozen;
using fogdetail::Poly;

int polyDegree(const Poly& p) {
    int deg = 0;
    for (const FogMonomial& m : p.mono) deg = std::max(deg, m.px + m.py + m.pz);
    return deg;
}

// vec4 count of each part of the layout (must match glslParameters' packing).
bool multi(const Poly& p) { return p.usedCount > 1; }
int polyVec4s(const Poly& p) {
    if (multi(p)) return 2 + (int(p.mono.size()) + 3) / 4; // uRef + mean, 1/halfSize, coefficients
    return 1 + (polyDegree(p) + 1 + 3) / 4;                // uRef, 1/h, cell integral; dense coefficients
}

// Mean of a polynomial over its reference cell (used axes), by tensor Gauss (exact).
double cellMean(const Poly& p) {
    static constexpr double x[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
    static constexpr double w[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665, 0.2369268850561891};
    const int nu = p.used[0] ? 5 : 1, nv = p.used[1] ? 5 : 1, nw = p.used[2] ? 5 : 1;
    double mean = 0.0;
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j)
            for (int k = 0; k < nw; ++k)
                mean += (nu > 1 ? w[i] / 2 : 1.0) * (nv > 1 ? w[j] / 2 : 1.0) * (nw > 1 ? w[k] / 2 : 1.0) *
                        fogdetail::evalPoly(p, {nu > 1 ? x[i] : 0.0, nv > 1 ? x[j] : 0.0, nw > 1 ? x[k] : 0.0});
    return mean;
}

} // namespace

namespace {

// A polynomial in two or three variables: evaluation, Gauss piece, and the
// integral (O(1) when the ray moves along one variable only, else a cell walk
// of at most maxCells cells, the rest at the cell's mean density: docs/fog.md).
std::string multiPolySource(const Poly& p, const std::string& P, const std::string& id, int base, int maxCells) {
    const std::string fn = P + "_poly" + id;
    auto prm = [&](int i) { return P + "_params[" + std::to_string(i) + "]"; };
    const std::string used =
        std::string("vec3(") + (p.used[0] ? "1.0" : "0.0") + ", " + (p.used[1] ? "1.0" : "0.0") + ", " + (p.used[2] ? "1.0" : "0.0") + ")";
    int maxPow[3] = {0, 0, 0};
    for (const FogMonomial& m : p.mono) {
        maxPow[0] = std::max(maxPow[0], m.px);
        maxPow[1] = std::max(maxPow[1], m.py);
        maxPow[2] = std::max(maxPow[2], m.pz);
    }
    std::string s = "float " + fn + "(vec3 u) {\n";
    const char* names = "xyz";
    for (int a = 0; a < 3; ++a) {
        const std::string A(1, char('X' + a));
        s += "    float " + A + "[" + std::to_string(maxPow[a] + 1) + "];\n    " + A + "[0] = 1.0;\n";
        for (int n = 1; n <= maxPow[a]; ++n)
            s += "    " + A + "[" + std::to_string(n) + "] = " + A + "[" + std::to_string(n - 1) + "] * u." + names[a] + ";\n";
    }
    s += "    float r = 0.0;\n";
    for (size_t n = 0; n < p.mono.size(); ++n) {
        const FogMonomial& m = p.mono[n];
        s += "    r += " + prm(base + 2 + int(n / 4)) + "[" + std::to_string(n % 4) + "] * X[" + std::to_string(m.px) + "] * Y[" +
             std::to_string(m.py) + "] * Z[" + std::to_string(m.pz) + "];\n";
    }
    s += "    return r;\n}\n";
    const bool periodic = p.mode == FogCellMode::Periodic;
    s += "float " + fn +
         "_piece(float la, float lb, vec3 U0, vec3 dU, float L) {\n"
         "    if (lb <= la) return 0.0;\n"
         "    float mid = 0.5 * (la + lb), hw = 0.5 * (lb - la), sum = 0.0;\n";
    s += periodic ? "    vec3 shift = 2.0 * floor((U0 + mid * dU + 1.0) * 0.5);\n" : "    vec3 shift = vec3(0.0);\n";
    s += "    for (int j = 0; j < 5; ++j) sum += " + P + "_GW[j] * " + fn + "(U0 + (mid + hw * " + P +
         "_GX[j]) * dU - shift);\n"
         "    return sum * hw * L;\n}\n";
    s += "float " + fn +
         "_integral(vec3 oRel, vec3 pRel, float L) {\n"
         "    const vec3 used = " +
         used +
         ";\n"
         "    vec3 U0 = (" +
         prm(base) + ".xyz + oRel * " + prm(base + 1) +
         ".xyz) * used;\n"
         "    vec3 dU = (pRel - oRel) * " +
         prm(base + 1) + ".xyz * used;\n";
    if (!periodic) {
        s += "    float la = 0.0, lb = 1.0;\n"
             "    for (int a = 0; a < 3; ++a) {\n"
             "        if (used[a] == 0.0) continue;\n"
             "        if (dU[a] == 0.0) { if (abs(U0[a]) > 1.0) return 0.0; continue; }\n"
             "        float l0 = (-1.0 - U0[a]) / dU[a], l1 = (1.0 - U0[a]) / dU[a];\n"
             "        la = max(la, min(l0, l1));\n"
             "        lb = min(lb, max(l0, l1));\n"
             "    }\n"
             "    return " +
             fn + "_piece(la, lb, U0, dU, L);\n}\n";
        return s;
    }
    s += "    vec3 n0 = floor((U0 + 1.0) * 0.5), n1 = floor((U0 + dU + 1.0) * 0.5);\n"
         "    bvec3 moving = notEqual(n0, n1);\n"
         "    int nMoving = int(moving.x) + int(moving.y) + int(moving.z);\n"
         "    if (nMoving == 0) return " +
         fn +
         "_piece(0.0, 1.0, U0, dU, L);\n"
         "    bvec3 varies = notEqual(dU, vec3(0.0));\n"
         "    if (nMoving == 1 && int(varies.x) + int(varies.y) + int(varies.z) == 1) {\n"
         "        int a = moving.x ? 0 : (moving.y ? 1 : 2);\n"
         "        float dir = dU[a] > 0.0 ? 1.0 : -1.0;\n"
         "        float a0 = U0[a] - 2.0 * n0[a], a1 = U0[a] + dU[a] - 2.0 * n1[a];\n"
         "        float l1 = clamp((dir - a0) / dU[a], 0.0, 1.0);\n"
         "        float lk = clamp(1.0 - (a1 + dir) / dU[a], 0.0, 1.0);\n"
         "        float whole = abs(n1[a] - n0[a]) - 1.0;\n"
         "        vec3 u = U0 - 2.0 * n0;\n"
         "        float cell = 0.0;\n"
         "        for (int j = 0; j < 5; ++j) { u[a] = " +
         P + "_GX[j]; cell += " + P + "_GW[j] * " + fn +
         "(u); }\n"
         "        return " +
         fn + "_piece(0.0, l1, U0, dU, L) + " + fn +
         "_piece(lk, 1.0, U0, dU, L)\n"
         "             + whole * cell * (L / abs(dU[a]));\n"
         "    }\n"
         "    vec3 dir = sign(dU);\n"
         "    vec3 nb = 2.0 * n0 + dir;\n"
         "    vec3 nx = vec3(2.0);\n"
         "    for (int a = 0; a < 3; ++a) if (dU[a] != 0.0) nx[a] = (nb[a] - U0[a]) / dU[a];\n"
         "    float lam = 0.0, total = 0.0;\n"
         "    for (int i = 0; i < " +
         std::to_string(maxCells) +
         "; ++i) {\n"
         "        float ln = min(min(min(nx.x, nx.y), nx.z), 1.0);\n"
         "        total += " +
         fn +
         "_piece(lam, ln, U0, dU, L);\n"
         "        lam = ln;\n"
         "        if (lam >= 1.0) return total;\n"
         "        for (int a = 0; a < 3; ++a)\n"
         "            if (dU[a] != 0.0 && nx[a] <= lam) { nb[a] += 2.0 * dir[a]; nx[a] = (nb[a] - U0[a]) / dU[a]; }\n"
         "    }\n"
         "    return total + (1.0 - lam) * L * " +
         prm(base) + ".w;\n}\n";
    return s;
}

} // namespace

std::vector<glm::vec4> Fog::glslParameters(double tSec, glm::dvec3 reference) const {
    const Frozen fr = fogdetail::freeze(mDesc, tSec, reference);
    std::vector<glm::vec4> out;
    out.push_back({float(fr.constant), 0.0f, 0.0f, 0.0f});
    for (const auto& w : fr.waves) {
        out.push_back({glm::vec3(w.w), float(w.alpha)});
        out.push_back({float(w.amp), 0.0f, 0.0f, 0.0f});
    }
    for (const Poly& p : fr.polys) {
        if (multi(p)) {
            out.push_back({glm::vec3(p.uRef), float(cellMean(p))});
            out.push_back({glm::vec3(1.0 / p.halfSize), 0.0f});
            for (size_t n = 0; n < p.mono.size(); n += 4)
                out.push_back({float(p.mono[n].coeff), n + 1 < p.mono.size() ? float(p.mono[n + 1].coeff) : 0.0f,
                               n + 2 < p.mono.size() ? float(p.mono[n + 2].coeff) : 0.0f, n + 3 < p.mono.size() ? float(p.mono[n + 3].coeff) : 0.0f});
            continue;
        }
        const int a = std::max(p.usedAxis, 0);
        const int deg = polyDegree(p);
        std::vector<double> dense(size_t(deg + 1), 0.0);
        for (const FogMonomial& m : p.mono) dense[size_t(m.px + m.py + m.pz)] += m.coeff; // one axis only
        double cell = 0.0;                                                                // integral of P over [-1, 1]: odd powers vanish
        for (int n = 0; n <= deg; n += 2) cell += 2.0 * dense[size_t(n)] / (n + 1);
        out.push_back({float(p.uRef[a]), float(1.0 / p.halfSize[a]), float(cell), 0.0f});
        for (int n = 0; n <= deg; n += 4)
            out.push_back({float(dense[size_t(n)]), n + 1 <= deg ? float(dense[size_t(n + 1)]) : 0.0f,
                           n + 2 <= deg ? float(dense[size_t(n + 2)]) : 0.0f, n + 3 <= deg ? float(dense[size_t(n + 3)]) : 0.0f});
    }
    for (const auto& p : fr.pots) {
        out.push_back({glm::vec3(p.qRel), float(p.c)});
        out.push_back({glm::vec3(p.axis), float(p.d)});
        // z: the kind the shader's loop branches on (0 point, 1 line, 2 sphere);
        // w: 1 for FogPotentialForm::Segment (a parameter, so the source does not change with it).
        const float kind = p.kind == FogTermKind::Line ? 1.0f : p.kind == FogTermKind::Sphere ? 2.0f : 0.0f;
        out.push_back({float(p.weight), float(p.radius2), kind, p.segment ? 1.0f : 0.0f});
    }
    return out;
}

Result<FogGlsl> fogGlsl(const Fog& fog, const FogGlslOptions& opt) {
    const Frozen fr = fogdetail::freeze(fog.desc(), 0.0, glm::dvec3(0.0));
    if (opt.maxPolynomialCells < 1) return makeError("FogGlslOptions.maxPolynomialCells must be >= 1");
    bool identifier = !opt.prefix.empty() && !std::isdigit((unsigned char)opt.prefix[0]) && opt.prefix.rfind("gl_", 0) != 0;
    for (char ch : opt.prefix) identifier = identifier && (std::isalnum((unsigned char)ch) || ch == '_');
    if (!identifier)
        return makeError("FogGlslOptions.prefix must be a GLSL identifier ([A-Za-z_][A-Za-z0-9_]*, not starting with gl_); got \"" + opt.prefix +
                         "\"");
    const std::string P = opt.prefix;
    int count = 1 + int(fr.waves.size()) * 2 + int(fr.pots.size()) * 3;
    for (const Poly& p : fr.polys) count += polyVec4s(p);

    FogGlsl g;
    g.uniformName = P + "_params";
    g.vec4Count = count;
    // The logic every fog shares is fog.glsl (render/gl/glsl, embedded); what
    // follows it is this fog's structure: the parameter array, a function per
    // polynomial (its degree and monomials) and the sum of the terms.
    auto shared = glsl::expand("fog.glsl");
    if (!shared) return makeError("fogGlsl: " + shared.error());
    std::string s = std::move(*shared);
    if (P != "splatfx_fog") {
        std::string renamed;
        for (std::size_t pos = 0;;) {
            const std::size_t at = s.find("splatfx_fog_", pos);
            renamed += s.substr(pos, at == std::string::npos ? std::string::npos : at - pos);
            if (at == std::string::npos) break;
            renamed += P + "_";
            pos = at + 12;
        }
        s = std::move(renamed);
    }
    const std::size_t sharedBytes = s.size();
    s += "// The terms of this fog (splatfx::fogGlsl).\n";
    if (opt.uniformLocation >= 0) s += "layout(location = " + std::to_string(opt.uniformLocation) + ") ";
    s += "uniform vec4 " + P + "_params[" + std::to_string(count) + "];\n";

    // Per polynomial: its Horner evaluation and its integral (1D, O(1) in the cells crossed).
    int base = 1 + int(fr.waves.size()) * 2;
    std::vector<int> polyBase;
    for (size_t j = 0; j < fr.polys.size(); ++j) {
        const Poly& p = fr.polys[j];
        const int deg = polyDegree(p);
        const std::string id = std::to_string(j);
        polyBase.push_back(base);
        if (multi(p)) {
            s += multiPolySource(p, P, id, base, opt.maxPolynomialCells);
            base += polyVec4s(p);
            continue;
        }
        s += "float " + P + "_poly" + id + "(float u) {\n    float r = 0.0;\n";
        for (int n = deg; n >= 0; --n) {
            const int idx = base + 1 + n / 4;
            s += "    r = r * u + " + P + "_params[" + std::to_string(idx) + "][" + std::to_string(n % 4) + "];\n";
        }
        s += "    return r;\n}\n";
        // Gauss piece over lambda in [la, lb]; local coordinate = uAnchor + (lambda - lAnchor) dU,
        // anchored at the piece's own end of the segment so that a piece far along a long ray
        // does not subtract two large cell coordinates in float.
        s += "float " + P + "_poly" + id +
             "_piece(float la, float lb, float uAnchor, float lAnchor, float dU, float L) {\n"
             "    if (lb <= la) return 0.0;\n"
             "    float mid = 0.5 * (la + lb), hw = 0.5 * (lb - la), sum = 0.0;\n"
             "    for (int j = 0; j < 5; ++j) sum += " +
             P + "_GW[j] * " + P + "_poly" + id + "(uAnchor + (mid + hw * " + P +
             "_GX[j] - lAnchor) * dU);\n"
             "    return sum * hw * L;\n"
             "}\n";
        const std::string pv = P + "_params[" + std::to_string(base) + "]";
        const char axisChar = "xyz"[std::max(p.usedAxis, 0)];
        s += "float " + P + "_poly" + id + "_integral(vec3 oRel, vec3 pRel, float L) {\n";
        if (p.usedCount == 0) {
            s += "    return L * " + P + "_poly" + id + "(0.0);\n}\n";
        } else {
            s += std::string("    float U0 = ") + pv + ".x + oRel." + axisChar + " * " + pv + ".y;\n" + "    float U1 = " + pv + ".x + pRel." +
                 axisChar + " * " + pv + ".y;\n" + "    float dU = (pRel." + axisChar + " - oRel." + axisChar + ") * " + pv + ".y;\n";
            if (p.mode == FogCellMode::ZeroOutside) {
                s += "    if (dU == 0.0) return abs(U0) > 1.0 ? 0.0 : " + P + "_poly" + id +
                     "_piece(0.0, 1.0, U0, 0.0, 0.0, L);\n"
                     "    float l0 = (-1.0 - U0) / dU, l1 = (1.0 - U0) / dU;\n"
                     "    float la = max(min(l0, l1), 0.0), lb = min(max(l0, l1), 1.0);\n"
                     "    return " +
                     P + "_poly" + id + "_piece(la, lb, U0, 0.0, dU, L);\n}\n";
            } else {
                s += "    float n0 = floor((U0 + 1.0) * 0.5), n1 = floor((U1 + 1.0) * 0.5);\n"
                     "    float a0 = U0 - 2.0 * n0, a1 = U1 - 2.0 * n1;\n"
                     "    if (n0 == n1) return " +
                     P + "_poly" + id +
                     "_piece(0.0, 1.0, a0, 0.0, dU, L);\n"
                     "    float dir = dU > 0.0 ? 1.0 : -1.0;\n"
                     "    float l1 = clamp((dir - a0) / dU, 0.0, 1.0);\n"       // first boundary, from the start's cell
                     "    float lk = clamp(1.0 - (a1 + dir) / dU, 0.0, 1.0);\n" // last boundary, from the end's cell
                     "    float whole = abs(n1 - n0) - 1.0;\n"
                     "    return " +
                     P + "_poly" + id + "_piece(0.0, l1, a0, 0.0, dU, L) + " + P + "_poly" + id +
                     "_piece(lk, 1.0, a1, 1.0, dU, L)\n"
                     "         + whole * " +
                     pv + ".z * (L / abs(dU));\n}\n";
            }
        }
        base += polyVec4s(p);
    }

    s += "float " + P +
         "_optical_depth(vec3 oRel, vec3 pRel) {\n"
         "    vec3 seg = pRel - oRel;\n"
         "    float L = length(seg);\n"
         "    if (L == 0.0) return 0.0;\n"
         "    vec3 e = seg / L;\n"
         "    float total = " +
         P + "_params[0].x * L;\n";
    // Cosines and potentials are one loop each over their parameters (the
    // kind of a potential is a parameter too), so the shader does not grow
    // with their count: only polynomials are generated code.
    if (!fr.waves.empty())
        s += "    for (int j = 0; j < " + std::to_string(fr.waves.size()) + "; ++j) {\n        vec4 w = " + P +
             "_params[1 + 2 * j];\n        total += " + P + "_params[2 + 2 * j].x * L * cos(dot(w.xyz, 0.5 * (oRel + pRel)) + w.w) * " + P +
             "_sinc(0.5 * dot(w.xyz, seg));\n    }\n";
    for (size_t j = 0; j < fr.polys.size(); ++j) s += "    total += " + P + "_poly" + std::to_string(j) + "_integral(oRel, pRel, L);\n";
    if (!fr.pots.empty())
        s += "    for (int j = 0; j < " + std::to_string(fr.pots.size()) + "; ++j) {\n        int b = " + std::to_string(base) +
             " + 3 * j;\n        vec4 q = " + P + "_params[b], ax = " + P + "_params[b + 1], wr = " + P +
             "_params[b + 2];\n"
             "        vec3 v = oRel - q.xyz;\n"
             "        if (wr.w == 1.0) total += wr.x / (q.w + ax.w * " +
             P +
             "_segment_r2(v, e, L, ax.xyz, wr.z, wr.y));\n"
             "        else if (wr.z == 1.0) total += wr.x * " +
             P +
             "_inv_quadratic(v - dot(v, ax.xyz) * ax.xyz, e - dot(e, ax.xyz) * ax.xyz, L, q.w, ax.w);\n        else if (wr.z == 2.0) total += wr.x "
             "* " +
             P + "_sphere(v, e, L, q.w, ax.w, wr.y);\n        else total += wr.x * " + P + "_inv_quadratic(v, e, L, q.w, ax.w);\n    }\n";
    s += "    return max(total, 0.0);\n}\n";
    g.termBytes = s.size() - sharedBytes;
    g.source = std::move(s);
    return g;
}

} // namespace splatfx
