// [clouds, issue 17] Projected tetrahedra with pre-integration (tetra_pass.hpp).
#include "tetra_pass.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <epoxy/gl.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "render/gl/context_check.hpp"
#include "render/gl/host_depth.hpp"
#include "render/gl/fog_state.hpp"
#include "render/gl/saved_state.hpp"
#include "render/gl/over_state.hpp"
#include "render/gl/program_library.hpp"

namespace splatfx::gl::detail {
namespace {

// Per tetrahedron, 10 vec4 (std430): the four vertices relative to the eye,
// the four barycentric planes lambda_i(x) = dot(B_i.xyz, x) + B_i.w (x
// relative to the eye, lambda_i = 1 at vertex i, 0 on the opposite face),
// and the scalar and length scale as linear functions of x. A volume with an
// RGB source per vertex (LodFrame::rgb) has 12: the scalar's slot holds the
// red source, the green and blue ones follow the length scale.
constexpr int kVec4PerTet = 10, kVec4PerRgbTet = 12;

// The faces wound counter-clockwise seen from outside a positively oriented
// tetrahedron (dot(p1-p0, cross(p2-p0, p3-p0)) > 0): opposite 0, 1, 2, 3.
constexpr std::uint32_t kTetraFaces[12] = {1, 2, 3, 0, 3, 2, 0, 1, 3, 0, 2, 1};

} // namespace

struct TetraPass::Impl {
    Programs library;
    using Program = ProgramLibrary::Program;
    const Program* programs[4] = {}; // [perspective * 2 + host depth]
    // The fog variants, built for the structure of the last fog seen (Fog::glslKey).
    const Program* fogPrograms[4] = {};
    std::uint64_t fogKey = 0;
    std::string fogSource; // the fog's GLSL the fog variants were built from (the RGB ones are built on first use)
    const Fog* fog = nullptr;
    double fogTimeSec = 0.0;
    GLuint vao = 0, ssbo = 0;
    std::size_t ssboBytes = 0;
    // Indices for one indexed draw of many tetrahedra (4 t + kTetraFaces[k]),
    // grown to the largest draw: vertices are shaded once per corner (an instanced
    // draw of 12 vertices shaded each corner three times, the vertex work that
    // bounds a CPU rasterizer at low resolution).
    GLuint indices = 0;
    std::uint32_t indexedTets = 0;
    struct Table {
        const PreIntegrationTable* source = nullptr;
        std::uint64_t version = 0;
        const float* data = nullptr;
        GLuint texture = 0;
        bool used = false;
    };
    std::vector<Table> tables;
    std::vector<int> tableOfVolume;                      // per frame volume: index into tables (-1: not drawn)
    std::vector<std::size_t> recordBase;                 // per frame volume: its first vec4
    std::vector<bool> rgbOfVolume;                       // per frame volume: an RGB source per vertex (kVec4PerRgbTet)
    std::vector<std::vector<std::uint32_t>> firstRecord; // per volume: records before tet i (size tets + 1)
    std::vector<glm::vec4> records;
    glm::vec3 eye{0.0f};
    TetraStats stats;

    ~Impl() {
        if (!contextIsCurrent()) return;
        for (const Table& t : tables) glDeleteTextures(1, &t.texture);
        if (vao) glDeleteVertexArrays(1, &vao);
        if (ssbo) glDeleteBuffers(1, &ssbo);
        if (indices) glDeleteBuffers(1, &indices);
    }
};

TetraPass::TetraPass(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
TetraPass::TetraPass(TetraPass&&) noexcept = default;
TetraPass& TetraPass::operator=(TetraPass&&) noexcept = default;
TetraPass::~TetraPass() = default;
const TetraStats& TetraPass::stats() const { return mImpl->stats; }

Result<TetraPass> TetraPass::create(Programs programs) {
    if (!contextIsCurrent()) return makeError("splatfx::gl tetrahedra pass: no OpenGL context is current on this thread");
    auto impl = std::make_unique<Impl>();
    Impl& r = *impl;
    r.library = std::move(programs);
    for (int v = 0; v < 4; ++v) {
        auto p = r.library->get({glsl::ProgramId::Tetra, {(v & 2) ? 1 : 0, v & 1, 0, 0}});
        if (!p) return makeError(p.error());
        r.programs[v] = *p;
    }
    glCreateVertexArrays(1, &r.vao); // no attributes: everything comes from the buffer
    glCreateBuffers(1, &r.ssbo);
    return TetraPass(std::move(impl));
}

Status TetraPass::setFog(const Fog* fog, double timeSec) {
    Impl& r = *mImpl;
    r.fogTimeSec = timeSec;
    auto change = fogChange(fog, r.fogKey);
    r.fog = change ? change->fog : nullptr;
    if (!change) return makeError("splatfx::gl tetrahedra pass: " + change.error());
    if (!change->rebuild) return {};
    r.library->release(glsl::ProgramId::Tetra, [](const glsl::ProgramKey& k) { return k.values[glsl::tetra::FOG] != 0; });
    for (auto& p : r.fogPrograms) p = nullptr;
    r.fogKey = 0;
    r.fogSource.clear();
    for (int v = 0; v < 4; ++v) {
        auto p = r.library->get({glsl::ProgramId::Tetra, {(v & 2) ? 1 : 0, v & 1, 1, 0}, r.fog->glslKey()}, {.fog = *change->rebuild});
        if (!p) {
            r.library->release(glsl::ProgramId::Tetra, [](const glsl::ProgramKey& k) { return k.values[glsl::tetra::FOG] != 0; });
            for (auto& q : r.fogPrograms) q = nullptr;
            r.fog = nullptr;
            return makeError(p.error());
        }
        r.fogPrograms[v] = *p;
    }
    r.fogKey = r.fog->glslKey();
    r.fogSource = *change->rebuild;
    return {};
}

void TetraPass::uploadTables(const Frame& frame) {
    Impl& r = *mImpl;
    const std::uint64_t uploads = r.stats.tableUploads;
    r.stats = {};
    r.stats.tableUploads = uploads;
    const auto& volumes = frame.volumes();
    for (auto& t : r.tables) t.used = false;
    r.tableOfVolume.assign(volumes.size(), -1);
    // 0. Upload the tables that changed.
    for (std::size_t v = 0; v < volumes.size(); ++v) {
        const PreIntegrationTable* src = volumes[v].table;
        if (!src || src->data().empty()) continue;
        int found = -1;
        for (std::size_t i = 0; i < r.tables.size(); ++i)
            if (r.tables[i].source == src) found = int(i);
        if (found < 0) {
            r.tables.push_back({});
            found = int(r.tables.size() - 1);
        }
        Impl::Table& t = r.tables[std::size_t(found)];
        if (!t.texture || t.version != volumes[v].tableVersion || t.data != src->data().data()) {
            if (t.texture) glDeleteTextures(1, &t.texture);
            const glm::ivec3 n = src->dims();
            glCreateTextures(GL_TEXTURE_3D, 1, &t.texture);
            glTextureStorage3D(t.texture, 1, GL_RGBA32F, n.x, n.y, n.z);
            glTextureSubImage3D(t.texture, 0, 0, 0, 0, n.x, n.y, n.z, GL_RGBA, GL_FLOAT, src->data().data());
            glTextureParameteri(t.texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
            glTextureParameteri(t.texture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
            for (GLenum w : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) glTextureParameteri(t.texture, w, GL_CLAMP_TO_EDGE);
            t.source = src;
            t.version = volumes[v].tableVersion;
            t.data = src->data().data();
            ++r.stats.tableUploads;
        }
        t.used = true;
        r.tableOfVolume[v] = found;
    }
    // Tables no frame volume uses any more are released (indices are re-mapped).
    for (std::size_t i = r.tables.size(); i-- > 0;) {
        if (r.tables[i].used) continue;
        glDeleteTextures(1, &r.tables[i].texture);
        r.tables.erase(r.tables.begin() + std::ptrdiff_t(i));
        for (int& k : r.tableOfVolume)
            if (k > int(i)) --k;
    }
    for (const auto& t : r.tables) r.stats.tableBytes += t.source ? t.source->bytes() : 0;

    // Per-tetrahedron records, relative to the eye (float precision where it matters).
    const Camera& camera = frame.camera();
    r.eye = camera.eye();
    const glm::dvec3 eye(r.eye);
    r.records.clear();
    r.recordBase.assign(volumes.size(), 0);
    r.rgbOfVolume.assign(volumes.size(), false);
    r.firstRecord.resize(volumes.size());
    for (std::size_t v = 0; v < volumes.size(); ++v) {
        auto& first = r.firstRecord[v];
        const auto& tets = volumes[v].lod.tets;
        const auto& rgb = volumes[v].lod.rgb;
        // An RGB list of another length than the tetrahedra's is not one (LodFrame::rgb): the scalar is drawn, and noted.
        const bool coloured = !rgb.empty() && rgb.size() == tets.size();
        if (!rgb.empty() && !coloured)
            r.stats.rgbError = "frame volume " + std::to_string(v) + ": LodFrame::rgb holds " + std::to_string(rgb.size()) + " entries for " +
                               std::to_string(tets.size()) + " tetrahedra: drawn with their scalar";
        r.rgbOfVolume[v] = coloured;
        first.assign(tets.size() + 1, 0);
        r.recordBase[v] = r.records.size();
        const PreIntegrationTable* table = r.tableOfVolume[v] >= 0 ? volumes[v].table : nullptr;
        std::uint32_t count = 0;
        for (std::size_t i = 0; i < tets.size(); ++i) {
            first[i] = count;
            if (!table) continue;
            const Tetrahedron& t = tets[i];
            const auto [lo, hi] = std::minmax_element(t.scalar.begin(), t.scalar.end());
            if (table->zeroOpacity(*lo, *hi)) { // the paper's table form of the ZOT (sec. 4.1)
                ++r.stats.transparent;
                continue;
            }
            glm::dvec3 p[4];
            for (int k = 0; k < 4; ++k) p[k] = glm::dvec3(t.position[std::size_t(k)]) - eye;
            const glm::dmat3 m(p[1] - p[0], p[2] - p[0], p[3] - p[0]);
            const double det = glm::determinant(m);
            const double scale = glm::length(m[0]) * glm::length(m[1]) * glm::length(m[2]);
            if (!std::isfinite(det) || !(std::abs(det) > 1e-9 * scale)) {
                ++r.stats.degenerate;
                continue;
            }
            const glm::dmat3 inv = glm::inverse(m); // rows: gradients of lambda_1..3
            glm::dvec4 b[4];
            glm::dvec3 g0(0.0);
            for (int k = 1; k < 4; ++k) {
                const glm::dvec3 g(inv[0][k - 1], inv[1][k - 1], inv[2][k - 1]);
                b[k] = glm::dvec4(g, -glm::dot(g, p[0]));
                g0 -= g;
            }
            b[0] = glm::dvec4(g0, 1.0 - glm::dot(g0, p[0]));
            glm::dvec4 s(0.0), ls(0.0), sg(0.0), sb(0.0);
            for (int k = 0; k < 4; ++k) {
                const std::size_t kk = std::size_t(k);
                s += double(coloured ? rgb[i][kk].r : t.scalar[kk]) * b[k];
                ls += double(t.lengthScale[kk]) * b[k];
                if (coloured) {
                    sg += double(rgb[i][kk].g) * b[k];
                    sb += double(rgb[i][kk].b) * b[k];
                }
            }
            for (int k = 0; k < 4; ++k) r.records.emplace_back(glm::vec3(p[k]), 0.0f);
            for (int k = 0; k < 4; ++k) r.records.emplace_back(b[k]);
            r.records.emplace_back(s);
            r.records.emplace_back(ls);
            if (coloured) {
                r.records.emplace_back(sg);
                r.records.emplace_back(sb);
            }
            ++count;
        }
        first[tets.size()] = count;
    }
    const std::size_t bytes = r.records.size() * sizeof(glm::vec4);
    if (bytes > 0) {
        // Orphan and refill: no wait on last frame's draws.
        glNamedBufferData(r.ssbo, GLsizeiptr(bytes), r.records.data(), GL_STREAM_DRAW);
        r.ssboBytes = bytes;
    }
}

void TetraPass::draw(const Frame& frame, std::uint32_t volume, std::uint32_t begin, std::uint32_t end, const PassTarget& target,
                     const Camera* cameraIn, bool sampleRay) {
    Impl& r = *mImpl;
    if (volume >= r.firstRecord.size() || r.tableOfVolume[volume] < 0) return;
    const auto& first = r.firstRecord[volume];
    end = std::min<std::uint32_t>(end, std::uint32_t(first.size() - 1));
    if (begin >= end) return;
    const std::uint32_t a = first[begin], b = first[end];
    if (a >= b) return;
    const PreIntegrationTable& table = *frame.volumes()[volume].table;
    const Impl::Table& tex = r.tables[std::size_t(r.tableOfVolume[volume])];
    const Camera& camera = cameraIn ? *cameraIn : frame.camera();

    const GLuint hostDepth = target.depthTexture;

    // Which winding is front-facing on screen for this camera (hosts may mirror
    // their projection): a triangle facing the eye, projected.
    const glm::mat4 vp = camera.proj * camera.view;
    const glm::vec3 eye = camera.eye(), c = eye + camera.forward() * std::max(1.0f, 2.0f * camera.nearPlane());
    auto ndc = [&](glm::vec3 q) {
        const glm::vec4 h = vp * glm::vec4(q, 1.0f);
        return glm::vec2(h) / h.w;
    };
    const glm::vec2 pa = ndc(c), pb = ndc(c + camera.right()), pc = ndc(c + camera.up());
    const float area = (pb.x - pa.x) * (pc.y - pa.y) - (pb.y - pa.y) * (pc.x - pa.x);

    const bool coloured = r.rgbOfVolume[volume];
    const int variant = (camera.perspective() ? 2 : 0) + (hostDepth ? 1 : 0);
    const bool fogged = r.fog && r.fogPrograms[variant];
    const Impl::Program* program = fogged ? r.fogPrograms[variant] : r.programs[variant];
    if (coloured) {
        // Built on first use (the library keeps it): most frames have no RGB volume.
        auto q = r.library->get({glsl::ProgramId::Tetra, {camera.perspective() ? 1 : 0, hostDepth ? 1 : 0, fogged ? 1 : 0, 1}, fogged ? r.fogKey : 0},
                                {.fog = fogged ? std::string_view(r.fogSource) : std::string_view()});
        if (!q) {
            r.stats.rgbError = "tetrahedra with an RGB source per vertex not drawn: " + q.error();
            return;
        }
        program = *q;
        r.stats.rgb += b - a;
    }
    const Impl::Program& p = *program;

    SavedState saved;
    saved.save({.texture2DUnits = 2, .scissor = false});
    GLint prevTex3D = 0, prevSsbo = 0, prevCullMode = 0, prevFrontFace = 0;
    glActiveTexture(GL_TEXTURE2);
    glGetIntegerv(GL_TEXTURE_BINDING_3D, &prevTex3D);
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_BINDING, &prevSsbo);
    glGetIntegerv(GL_CULL_FACE_MODE, &prevCullMode);
    glGetIntegerv(GL_FRONT_FACE, &prevFrontFace);
    const GLboolean prevClamp = glIsEnabled(GL_DEPTH_CLAMP);

    // With the host depth the shader cuts each segment there; without it
    // whole fragments behind the host are dropped.
    setOverState(target.framebuffer, target, hostDepth ? DepthTest::Off : nearerOrEqual(camera));
    glEnable(GL_DEPTH_CLAMP); // the CPU clipped at the near plane; GL must not clip again by rounding
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(area >= 0.0f ? GL_CCW : GL_CW);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);

    glUseProgram(p.id);
    if (fogged) {
        // Parameters in double relative to the eye the records are relative to (docs/fog.md, GLSL).
        std::vector<glm::vec4> own;
        if (!mFrameParams) own = r.fog->glslParameters(r.fogTimeSec, glm::dvec3(r.eye));
        setFogUniforms(
            p.id, {.params = p.uniform(glsl::tetra::FogParams), .colour = p.uniform(glsl::tetra::FogColour), .far = p.uniform(glsl::tetra::FogFar)},
            *r.fog, mFrameParams ? std::span<const glm::vec4>(*mFrameParams) : own);
        ++r.stats.foggedDraws;
    }
    const glm::mat4 vpRel = vp * glm::translate(glm::mat4(1.0f), r.eye);
    glUniformMatrix4fv(p.uniform(glsl::tetra::ViewProjRel), 1, GL_FALSE, glm::value_ptr(vpRel));
    // The first vec4 of the draw's first tetrahedron.
    glUniform1i(p.uniform(glsl::tetra::First), GLint(r.recordBase[volume] + std::size_t(a) * std::size_t(coloured ? kVec4PerRgbTet : kVec4PerTet)));
    const glm::vec3 f = camera.forward();
    glUniform3f(p.uniform(glsl::tetra::Forward), f.x, f.y, f.z);
    const glm::vec3 depthMap = hostDepthMap(camera);
    glUniform3fv(p.uniform(glsl::tetra::HostDepthMap), 1, glm::value_ptr(depthMap));
    const glm::vec3 n(table.dims());
    glUniform3f(p.uniform(glsl::tetra::TexScale), (n.x - 1.0f) / n.x, (n.y - 1.0f) / n.y, (n.z - 1.0f) / n.z);
    glUniform3f(p.uniform(glsl::tetra::TexOffset), 0.5f / n.x, 0.5f / n.y, 0.5f / n.z);
    glUniform1f(p.uniform(glsl::tetra::MaxLength), table.maxLengthWorld());
    glUniform1i(p.uniform(glsl::tetra::SampleRay), sampleRay ? 1 : 0);
    if (sampleRay) {
        const glm::mat4 inv(glm::inverse(glm::dmat4(vpRel)));
        const glm::vec4 hc = vp * glm::vec4(c, 1.0f); // c: a finite point in front of the eye
        glUniformMatrix4fv(p.uniform(glsl::tetra::InvViewProjRel), 1, GL_FALSE, glm::value_ptr(inv));
        glUniform4f(p.uniform(glsl::tetra::Viewport), float(target.x), float(target.y), float(target.width), float(target.height));
        glUniform1f(p.uniform(glsl::tetra::NdcZ), hc.z / hc.w);
    }
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, r.ssbo);
    glBindTextureUnit(1, hostDepth);
    glBindTextureUnit(2, tex.texture);
    const std::uint32_t count = b - a;
    if (count > r.indexedTets) { // grown by doubling, rebuilt rarely
        r.indexedTets = std::max(count, 2 * r.indexedTets);
        std::vector<std::uint32_t> idx(std::size_t(r.indexedTets) * 12);
        for (std::uint32_t t = 0; t < r.indexedTets; ++t)
            for (int k = 0; k < 12; ++k) idx[std::size_t(t) * 12 + std::size_t(k)] = 4 * t + kTetraFaces[k];
        if (r.indices) glDeleteBuffers(1, &r.indices);
        glCreateBuffers(1, &r.indices);
        glNamedBufferStorage(r.indices, GLsizeiptr(idx.size() * sizeof(std::uint32_t)), idx.data(), 0);
        glVertexArrayElementBuffer(r.vao, r.indices);
    }
    glBindVertexArray(r.vao);
    glDrawElements(GL_TRIANGLES, GLsizei(count) * 12, GL_UNSIGNED_INT, nullptr);
    ++r.stats.drawCalls;
    r.stats.tetrahedra += b - a;

    // Put back what SavedState does not cover.
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, GLuint(prevSsbo));
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_3D, glIsTexture(GLuint(prevTex3D)) ? GLuint(prevTex3D) : 0);
    glCullFace(GLenum(prevCullMode));
    glFrontFace(GLenum(prevFrontFace));
    if (!prevClamp) glDisable(GL_DEPTH_CLAMP);
    saved.restore();
}

// ---- As a pass of the frame (passes/pass.hpp) ----

void TetraPass::prepare(const FramePlan& plan, const Frame&) {
    mFogError.clear();
    mFogged = false;
    mActive = plan.tetrahedra;
    if (!plan.tetrahedra) return;
    const Status s = setFog(plan.fog, plan.timeSec);
    if (!s) mFogError = s.error();
    mFogged = plan.fog && s;
}

void TetraPass::execute(const PlanStep& step, StepContext& context) {
    if (step.kind == StepKind::PrepareTetrahedra) {
        uploadTables(context.frame);
        return;
    }
    assert(step.kind == StepKind::Tetrahedra);
    mFrameParams = &context.plan.fogParameters;
    const bool layer = step.target == StepTarget::Reduced;
    // Straight into a multisampled host (per sample): the ray from the sample.
    draw(context.frame, step.volume, std::uint32_t(step.begin), std::uint32_t(step.end), layer ? context.reduced : context.plan.target,
         layer ? context.layerCamera : nullptr, !layer && context.plan.samples > 1);
    mFrameParams = nullptr;
}

void TetraPass::report(FrameRenderStats& stats) const {
    const TetraStats& ts = mImpl->stats;
    stats.tetrahedra.tableBytes = ts.tableBytes;
    if (!mActive) return; // the pass's counters are last frame's
    stats.drawCalls += ts.drawCalls;
    stats.tetrahedra.drawn = ts.tetrahedra;
    stats.tetrahedra.transparent = ts.transparent;
    stats.tetrahedra.rgb = ts.rgb;
    stats.tetrahedra.error = ts.rgbError;
    stats.fog.tetrahedra = mFogged;
    if (!mFogError.empty()) stats.fog.error = mFogError;
}

} // namespace splatfx::gl::detail
