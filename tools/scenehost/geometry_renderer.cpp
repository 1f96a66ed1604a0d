#include "geometry_renderer.hpp"

#include <algorithm>
#include <bit>
#include <map>
#include <string>
#include <unordered_map>

#include <epoxy/gl.h>

#include "splatfx/transparency.hpp"
#include <glm/gtc/type_ptr.hpp>

#include "splatfx/fog.hpp"
#include "splatfx/gl/fog_uniforms.hpp"
#include "splatfx/gl/program.hpp"
#include "splatfx/lighting.hpp"

namespace scenehost {
namespace {

const char* kVertex = R"(#version 450 core
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
uniform mat4 uModel;
uniform mat4 uViewProj;
out vec3 vNormal;
out vec3 vWorld;
void main() {
    vec4 world = uModel * vec4(aPosition, 1.0);
    vWorld = world.xyz;
    vNormal = transpose(inverse(mat3(uModel))) * aNormal;
    gl_Position = uViewProj * world;
}
)";

// Two-sided shading, whatever the mesh's winding: the interpolated normal is
// turned to the side of the triangle the eye sees (the triangle's own normal,
// from the position's screen derivatives, decides). Testing the smooth normal
// itself against the eye flips it wrongly near silhouettes, where it may lean
// away from the eye on a triangle that faces it (dark specks on ridges).
const char* kHostNormal = R"(
vec3 twoSidedNormal(vec3 normal, vec3 world, vec3 eye) {
    vec3 n = normalize(normal);
    vec3 face = cross(dFdx(world), dFdy(world));
    if (dot(face, eye - world) < 0.0) face = -face;
    return dot(n, face) < 0.0 ? -n : n;
}
// The host's lights (GeometryLighting), each with its own shadow.
const int kLights = 8; // scenehost::kMaxGeometryLights
uniform int uLightCount;
uniform vec4 uLight[kLights];      // xyz: direction towards the light (w = 0) or its position (w = 1)
uniform vec3 uLightColor[kLights];
uniform int uShadowLight[kLights]; // splatfx_shadowTo's index; -1 unshadowed
uniform vec4 uSpot[kLights];       // xyz: the spot's axis (zero: not a spot), w: cos of the outer half-angle
uniform float uSpotInner[kLights]; // cos of the inner half-angle
vec3 hostDirect(vec3 n, vec3 world, bool shadowed) {
    vec3 sum = vec3(0.0);
    for (int i = 0; i < min(uLightCount, kLights); ++i) {
        vec3 toLight = normalize(uLight[i].w == 0.0 ? uLight[i].xyz : uLight[i].xyz - world);
        float d = max(dot(n, toLight), 0.0);
        if (dot(uSpot[i].xyz, uSpot[i].xyz) > 0.0) d *= smoothstep(uSpot[i].w, uSpotInner[i], dot(-toLight, normalize(uSpot[i].xyz)));
#ifndef HOST_UNSHADOWED
        if (shadowed && d > 0.0) d *= splatfx_shadowTo(uShadowLight[i], world);
#endif
        sum += d * uLightColor[i];
    }
    return sum;
}
)";

// The host's surface shader with the SDK's shadow include (shadowGlsl(),
// lighting.hpp): the gas's shadow table, bound by gl::FrameRenderer for the
// opaque hook, darkens the direct light on the ground and the objects.
const char* kFragmentBody = R"(
in vec3 vNormal;
in vec3 vWorld;
uniform vec3 uColor;
uniform vec3 uEye;
out vec4 fragColor;
void main() {
    vec3 n = twoSidedNormal(vNormal, vWorld, uEye);
    vec3 lit = uColor * (0.25 + 0.75 * hostDirect(n, vWorld, true));
    // Light from the frame's fires (shadowGlsl): a Lambertian surface reflects albedo * E / pi.
    lit += uColor * splatfx_emittedIrradiance(vWorld, n) * 0.31830989;
    fragColor = vec4(lit, 1.0);
}
)";

// Biri et al.'s buffer method (sec. 4.3): the fog include (fogGlsl) in the
// vertex stage, one transmittance per vertex, interpolated across the
// triangle; the fragment mixes with the fog colour as the per-pixel pass does.
const char* kVertexFogBody = R"(
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
uniform mat4 uModel;
uniform mat4 uViewProj;
uniform vec3 uEye;
out vec3 vNormal;
out vec3 vWorld;
out float vFog;
void main() {
    vec4 world = uModel * vec4(aPosition, 1.0);
    vWorld = world.xyz;
    vNormal = transpose(inverse(mat3(uModel))) * aNormal;
    vFog = splatfx_fog_transmittance(vec3(0.0), world.xyz - uEye);
    gl_Position = uViewProj * world;
}
)";
const char* kFragmentFogBody = R"(
in vec3 vNormal;
in vec3 vWorld;
in float vFog;
uniform vec3 uColor;
uniform vec3 uEye;
uniform vec3 splatfx_fog_colour;
out vec4 fragColor;
void main() {
    vec3 n = twoSidedNormal(vNormal, vWorld, uEye);
    vec3 lit = uColor * (0.25 + 0.75 * hostDirect(n, vWorld, true));
    lit += uColor * splatfx_emittedIrradiance(vWorld, n) * 0.31830989;
    fragColor = vec4(mix(splatfx_fog_colour, lit, vFog), 1.0);
}
)";

// (issue 15) Transparent objects (GeometryDesc::opacity < 1): the same
// shading, premultiplied, emitted into the frame's fragment lists through the
// SDK's include (transparentGlsl(); docs/integration.md, "Transparent surfaces").
const char* kTransparentBody = R"(
in vec3 vNormal;
in vec3 vWorld;
uniform vec3 uColor;
uniform float uOpacity;
uniform vec3 uEye;
out vec4 fragColor;
void main() {
    vec3 n = twoSidedNormal(vNormal, vWorld, uEye);
    vec3 lit = uColor * (0.25 + 0.75 * hostDirect(n, vWorld, false));
    lit += uColor * splatfx_emittedIrradiance(vWorld, n) * 0.31830989; // the fire's light, as on the opaque surfaces
    fragColor = splatfx_emitTransparent(vec4(lit * uOpacity, uOpacity), gl_FragCoord.z);
}
)";

void setLightUniforms(GLuint program, const GeometryLighting& lighting) {
    const int n = std::clamp(lighting.lightCount, 0, kMaxGeometryLights);
    glm::vec4 light[kMaxGeometryLights]{}, spot[kMaxGeometryLights]{};
    glm::vec3 color[kMaxGeometryLights]{};
    int shadow[kMaxGeometryLights]{};
    float inner[kMaxGeometryLights]{};
    for (int i = 0; i < n; ++i) {
        const GeometryLight& l = lighting.lights[std::size_t(i)];
        light[i] = l.light, color[i] = l.color, shadow[i] = l.shadowLight;
        spot[i] = glm::vec4(l.spotAxis, l.cosOuter), inner[i] = l.cosInner;
    }
    glUniform1i(glGetUniformLocation(program, "uLightCount"), n);
    glUniform4fv(glGetUniformLocation(program, "uLight"), kMaxGeometryLights, glm::value_ptr(light[0]));
    glUniform3fv(glGetUniformLocation(program, "uLightColor"), kMaxGeometryLights, glm::value_ptr(color[0]));
    glUniform1iv(glGetUniformLocation(program, "uShadowLight"), kMaxGeometryLights, shadow);
    glUniform4fv(glGetUniformLocation(program, "uSpot"), kMaxGeometryLights, glm::value_ptr(spot[0]));
    glUniform1fv(glGetUniformLocation(program, "uSpotInner"), kMaxGeometryLights, inner);
}

} // namespace

struct GeometryRenderer::Impl {
    struct Object {
        splatfx::GeometryDesc desc;
        GLuint vao = 0, vbo = 0, ibo = 0;
        GLsizei indexCount = 0;
        splatfx::Aabb localBounds;
        bool worldSpace = false; // setWorldTriangles: no placement, no motion
    };
    GLuint program = 0;
    GLuint transparentProgram = 0;
    GLuint vertexFogProgram = 0;       // for GeometryLighting::vertexFog, built for the fog's structure
    std::uint64_t vertexFogKey = 0;    // Fog::glslKey of vertexFogProgram
    std::string vertexFogError;        // why it could not be built (draw then fogs nothing: problem() says so)
    std::vector<Object> objects;
    GeometryStats stats;
    ~Impl() {
        for (Object& o : objects) {
            glDeleteVertexArrays(1, &o.vao);
            glDeleteBuffers(1, &o.vbo);
            glDeleteBuffers(1, &o.ibo);
        }
        if (program) glDeleteProgram(program);
        if (transparentProgram) glDeleteProgram(transparentProgram);
        if (vertexFogProgram) glDeleteProgram(vertexFogProgram);
    }
    // (Re)places an object's buffers: interleaved position + normal, triangle indices.
    // Fails when the GL cannot store the buffers (GL_OUT_OF_MEMORY): the
    // object would otherwise vanish from every frame without a word.
    static splatfx::Status upload(Object& o, const std::vector<float>& interleaved, const std::vector<std::uint32_t>& indices) {
        while (glGetError() != GL_NO_ERROR) {}
        glDeleteBuffers(1, &o.vbo);
        glDeleteBuffers(1, &o.ibo);
        if (!o.vao) glCreateVertexArrays(1, &o.vao);
        glCreateBuffers(1, &o.vbo);
        glCreateBuffers(1, &o.ibo);
        if (!interleaved.empty()) glNamedBufferStorage(o.vbo, GLsizeiptr(interleaved.size() * sizeof(float)), interleaved.data(), 0);
        if (!indices.empty()) glNamedBufferStorage(o.ibo, GLsizeiptr(indices.size() * sizeof(std::uint32_t)), indices.data(), 0);
        glVertexArrayVertexBuffer(o.vao, 0, o.vbo, 0, 6 * sizeof(float));
        glVertexArrayElementBuffer(o.vao, o.ibo);
        for (GLuint a = 0; a < 2; ++a) {
            glEnableVertexArrayAttrib(o.vao, a);
            glVertexArrayAttribFormat(o.vao, a, 3, GL_FLOAT, GL_FALSE, a * 3 * sizeof(float));
            glVertexArrayAttribBinding(o.vao, a, 0);
        }
        o.indexCount = GLsizei(indices.size());
        if (const GLenum e = glGetError(); e != GL_NO_ERROR) {
            o.indexCount = 0;
            return splatfx::makeError("the GL could not store its mesh of " + std::to_string(interleaved.size() / 6) + " vertices and " +
                                      std::to_string(indices.size() / 3) + " triangles (" +
                                      (e == GL_OUT_OF_MEMORY ? std::string("GL_OUT_OF_MEMORY") : "GL error " + std::to_string(e)) + ")");
        }
        return {};
    }
};

splatfx::Result<GeometryRenderer> GeometryRenderer::create(const std::vector<splatfx::GeometryDesc>& geometry, const splatfx::Budgets& budgets) {
    if (!epoxy_has_gl_extension("GL_ARB_direct_state_access") && epoxy_gl_version() < 45)
        return splatfx::makeError("GeometryRenderer: needs a current OpenGL 4.5 context");
    auto impl = std::make_unique<Impl>();
    const std::string shadow = splatfx::shadowGlsl();
    splatfx::Result<GLuint> program =
        splatfx::gl::linkProgram({kVertex}, {"#version 450 core\n", shadow.c_str(), kHostNormal, kFragmentBody}, "GeometryRenderer");
    if (!program) return splatfx::makeError(program.error());
    impl->program = *program;
    {
        // Unshadowed (HOST_UNSHADOWED), but lit by the frame's fires: shadowGlsl() for
        // splatfx_emittedIrradiance, whose uniforms drawTransparent sets.
        const std::string include = splatfx::transparentGlsl();
        auto tp = splatfx::gl::linkProgram({kVertex}, {"#version 450 core\n#define HOST_UNSHADOWED\n", shadow.c_str(), include.c_str(), kHostNormal, kTransparentBody},
                                           "GeometryRenderer (transparent)");
        if (!tp) return splatfx::makeError(tp.error());
        impl->transparentProgram = *tp;
    }

    std::map<std::string, Mesh> meshes; // each file loaded once
    for (const splatfx::GeometryDesc& g : geometry) {
        Impl::Object o;
        o.desc = g;
        Mesh mesh;
        switch (g.type) {
        case splatfx::GeometryType::Empty: impl->objects.push_back(std::move(o)); continue;
        case splatfx::GeometryType::Plane: mesh = planeMesh(g.size); break;
        case splatfx::GeometryType::Box: mesh = boxMesh(g.size); break;
        case splatfx::GeometryType::Cylinder: mesh = cylinderMesh(g.size); break;
        case splatfx::GeometryType::Sphere: mesh = sphereMesh(g.size); break;
        case splatfx::GeometryType::Mesh: {
            auto it = meshes.find(g.meshPath);
            if (it == meshes.end()) {
                splatfx::Result<Mesh> m = loadMesh(g.meshPath, budgets);
                if (!m) return splatfx::makeError("geometry '" + g.name + "': " + m.error());
                it = meshes.emplace(g.meshPath, std::move(*m)).first;
            }
            mesh = g.fitSize > 0.0f ? fitted(it->second, g.fitSize) : it->second;
            break;
        }
        case splatfx::GeometryType::Heightmap: {
            splatfx::Result<Mesh> m = heightmapMesh(g.heightmapPath, g.heightmapSpacing, g.heightmapScale, budgets);
            if (!m) return splatfx::makeError("geometry '" + g.name + "': " + m.error());
            mesh = std::move(*m);
            break;
        }
        }
        o.localBounds = mesh.bounds();
        std::vector<float> interleaved;
        interleaved.reserve(mesh.positions.size() * 6);
        for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
            const glm::vec3 p = mesh.positions[i], n = mesh.normals[i];
            interleaved.insert(interleaved.end(), {p.x, p.y, p.z, n.x, n.y, n.z});
        }
        if (auto s = Impl::upload(o, interleaved, mesh.indices); !s) return splatfx::makeError("geometry '" + g.name + "': " + s.error());
        impl->objects.push_back(std::move(o));
    }
    return GeometryRenderer(std::move(impl));
}

GeometryRenderer::GeometryRenderer(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
GeometryRenderer::GeometryRenderer(GeometryRenderer&&) noexcept = default;
GeometryRenderer& GeometryRenderer::operator=(GeometryRenderer&&) noexcept = default;
GeometryRenderer::~GeometryRenderer() = default;

const GeometryStats& GeometryRenderer::stats() const { return mImpl->stats; }
const std::string& GeometryRenderer::vertexFogError() const { return mImpl->vertexFogError; }

// [issue 17]
long GeometryRenderer::find(const std::string& name) const {
    for (std::size_t i = 0; i < mImpl->objects.size(); ++i)
        if (mImpl->objects[i].desc.name == name) return long(i);
    return -1;
}

splatfx::Status GeometryRenderer::setWorldTriangles(std::size_t i, const std::vector<glm::vec3>& triangles) {
    Impl::Object& o = mImpl->objects.at(i);
    // Corners are welded by exact position so triangles that meet share a smooth normal, as on
    // the heightmap mesh this replaces (the LOD terrain is conforming: corners that meet are
    // bit-identical).
    struct Key {
        std::uint32_t x, y, z;
        bool operator==(const Key&) const = default;
    };
    struct KeyHash {
        std::size_t operator()(const Key& k) const {
            return (std::size_t(k.x) * 73856093u) ^ (std::size_t(k.y) * 19349663u) ^ (std::size_t(k.z) * 83492791u);
        }
    };
    std::unordered_map<Key, std::uint32_t, KeyHash> corner;
    corner.reserve(triangles.size() / 2);
    Mesh welded;
    welded.indices.reserve(triangles.size());
    for (std::size_t k = 0; k + 2 < triangles.size(); k += 3)
        for (std::size_t c = 0; c < 3; ++c) {
            const glm::vec3& p = triangles[k + c];
            const Key key{std::bit_cast<std::uint32_t>(p.x), std::bit_cast<std::uint32_t>(p.y), std::bit_cast<std::uint32_t>(p.z)};
            auto [it, added] = corner.try_emplace(key, std::uint32_t(welded.positions.size()));
            if (added) welded.positions.push_back(p);
            welded.indices.push_back(it->second);
        }
    computeNormals(welded);
    std::vector<float> interleaved;
    interleaved.reserve(welded.positions.size() * 6);
    o.localBounds = {};
    for (std::size_t v = 0; v < welded.positions.size(); ++v) {
        const glm::vec3 p = welded.positions[v], n = welded.normals[v];
        interleaved.insert(interleaved.end(), {p.x, p.y, p.z, n.x, n.y, n.z});
        o.localBounds.extend(p);
    }
    o.worldSpace = true;
    if (auto s = Impl::upload(o, interleaved, welded.indices); !s) return splatfx::makeError("geometry '" + o.desc.name + "': " + s.error());
    return {};
}

splatfx::Aabb GeometryRenderer::worldBounds(std::size_t i, double t) const {
    const Impl::Object& o = mImpl->objects.at(i);
    splatfx::Aabb out;
    if (o.localBounds.empty()) return out;
    if (o.worldSpace) return o.localBounds;
    const glm::mat4 m = o.desc.motion.matrix(t) * o.desc.transform;
    for (int c = 0; c < 8; ++c) out.extend(glm::vec3(m * glm::vec4(o.localBounds.corner(c), 1.0f)));
    return out;
}

void GeometryRenderer::draw(double t, const splatfx::Camera& camera, const GeometryLighting& lighting) {
    Impl& r = *mImpl;
    r.stats = {};
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(camera.depth.reversed ? GL_GREATER : GL_LESS); // the camera's depth convention
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    GLuint program = r.program;
    if (lighting.vertexFog) {
        if (r.vertexFogKey != lighting.vertexFog->glslKey()) {
            if (r.vertexFogProgram) glDeleteProgram(r.vertexFogProgram);
            r.vertexFogProgram = 0;
            r.vertexFogKey = lighting.vertexFog->glslKey();
            r.vertexFogError.clear();
            auto glsl = splatfx::fogGlsl(*lighting.vertexFog);
            const std::string shadow = splatfx::shadowGlsl();
            auto linked = glsl ? splatfx::gl::linkProgram({"#version 450 core\n", glsl->source.c_str(), kVertexFogBody},
                                                          {"#version 450 core\n", shadow.c_str(), kHostNormal, kFragmentFogBody},
                                                          "GeometryRenderer (fog per vertex)")
                               : splatfx::Result<GLuint>(splatfx::makeError(glsl.error()));
            if (linked) r.vertexFogProgram = *linked;
            else r.vertexFogError = "geometry fog per vertex: " + linked.error();
        }
        if (r.vertexFogProgram) {
            program = r.vertexFogProgram;
            if (auto s = splatfx::gl::setFogUniforms(program, *lighting.vertexFog, t, glm::dvec3(camera.eye())); !s)
                r.vertexFogError = "geometry fog per vertex: " + s.error();
        }
    }
    glUseProgram(program);
    const glm::mat4 viewProj = camera.proj * camera.view;
    const glm::vec3 eye = camera.eye();
    glUniformMatrix4fv(glGetUniformLocation(program, "uViewProj"), 1, GL_FALSE, glm::value_ptr(viewProj));
    glUniform3fv(glGetUniformLocation(program, "uEye"), 1, glm::value_ptr(eye));
    setLightUniforms(program, lighting);
    splatfx::gl::setShadowUniforms(program, lighting.shadow);
    const GLint model = glGetUniformLocation(program, "uModel"), color = glGetUniformLocation(program, "uColor");
    for (const Impl::Object& o : r.objects) {
        if (!o.vao || o.desc.opacity < 1.0f) continue; // transparent ones: drawTransparent
        // Object to world: its motion (own or shared) after its static placement.
        const glm::mat4 m = o.worldSpace ? glm::mat4(1.0f) : o.desc.motion.matrix(t) * o.desc.transform;
        glUniformMatrix4fv(model, 1, GL_FALSE, glm::value_ptr(m));
        glUniform3fv(color, 1, glm::value_ptr(o.desc.color));
        glBindVertexArray(o.vao);
        glDrawElements(GL_TRIANGLES, o.indexCount, GL_UNSIGNED_INT, nullptr);
        ++r.stats.objects;
        r.stats.triangles += std::size_t(o.indexCount) / 3;
    }
    glBindVertexArray(0);
    glUseProgram(0);
}

// (issue 15)
bool GeometryRenderer::hasTransparent() const {
    for (const Impl::Object& o : mImpl->objects)
        if (o.vao && o.desc.opacity < 1.0f) return true;
    return false;
}

void GeometryRenderer::drawTransparent(double t, const splatfx::Camera& camera, const GeometryLighting& lighting) {
    Impl& r = *mImpl;
    glUseProgram(r.transparentProgram);
    const GLuint p = r.transparentProgram;
    const glm::mat4 viewProj = camera.proj * camera.view;
    const glm::vec3 eye = camera.eye();
    glUniformMatrix4fv(glGetUniformLocation(p, "uViewProj"), 1, GL_FALSE, glm::value_ptr(viewProj));
    glUniform3fv(glGetUniformLocation(p, "uEye"), 1, glm::value_ptr(eye));
    setLightUniforms(p, lighting);
    splatfx::gl::setShadowUniforms(p, lighting.shadow); // the emitted lights (its tables are not sampled here)
    const GLint model = glGetUniformLocation(p, "uModel"), color = glGetUniformLocation(p, "uColor"), opacity = glGetUniformLocation(p, "uOpacity");
    for (const Impl::Object& o : r.objects) {
        if (!o.vao || !(o.desc.opacity < 1.0f)) continue;
        const glm::mat4 m = o.worldSpace ? glm::mat4(1.0f) : o.desc.motion.matrix(t) * o.desc.transform;
        glUniformMatrix4fv(model, 1, GL_FALSE, glm::value_ptr(m));
        glUniform3fv(color, 1, glm::value_ptr(o.desc.color));
        glUniform1f(opacity, o.desc.opacity);
        glBindVertexArray(o.vao);
        glDrawElements(GL_TRIANGLES, o.indexCount, GL_UNSIGNED_INT, nullptr);
    }
    glBindVertexArray(0);
    glUseProgram(0);
}

} // namespace scenehost
