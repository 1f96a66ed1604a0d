// The OGRE side of sample 21 (see ogre_campfire.hpp). What an engine hands
// splatfx, and why, is said where it is done; docs/integration.md,
// "Inside an engine", collects it.
#include "ogre_campfire.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <utility>

#include <epoxy/gl.h>

#include <Ogre.h>

#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/lighting.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/presets.hpp"
#include "splatfx/scene.hpp"

#ifndef SPLATFX_OGRE_PLUGIN_DIR
#error "SPLATFX_OGRE_PLUGIN_DIR must name OGRE's plugin folder (from OGRE's CMake package: OGRE_PLUGIN_DIR)"
#endif

namespace ogrefx {
namespace {

// The scene, in world units (metres; splatfx's and OGRE's are the same).
// The fire preset's 7x20x5 lattice at 0.5 spacing stands on the origin:
// 3.5 wide, 10 tall, 2.5 deep. The log lies in front of its lower left; the
// wall stands behind it.
constexpr float kLogCentre[3] = {-1.2f, 0.9f, 2.6f};
constexpr float kLogSize[3] = {4.0f, 1.8f, 0.8f};
constexpr float kWallCentre[3] = {0.0f, 4.0f, -5.0f};
constexpr float kWallSize[3] = {16.0f, 8.0f, 1.0f};
constexpr float kPrefabCubeSize = 100.0f; // OGRE's Prefab_Cube is 100 units on a side

// GLSL 3.30 (OGRE's GL3Plus compiles it; no RTSS and no media needed).
// Attributes by OGRE's GL3Plus names (vertex, normal).
const char* kVertexShader = R"(#version 330 core
in vec4 vertex;
in vec3 normal;
uniform mat4 worldViewProj;
uniform mat4 world;
out vec3 vNormal;
out vec3 vWorld;
void main() {
    gl_Position = worldViewProj * vertex;
    vNormal = mat3(world) * normal;
    vWorld = (world * vertex).xyz;
}
)";
// Lambert from the sun, shadowed by the smoke (splatfx_shadowTo(0, ...): the
// transmittance towards scene light 0 through the frame's shadow table,
// bound as an OGRE texture unit), plus the fire's own light: splatfx's
// emitted lights (splatfx_emittedIrradiance), a Lambertian surface
// reflecting albedo x E / pi; and a checker on surfaces that ask for it (the
// ground). Both from shadowGlsl(), their uniforms set each frame as OGRE
// parameters. Compiled after "#version 330 core" and splatfx::shadowGlsl().
const char* kFragmentShader = R"(
in vec3 vNormal;
in vec3 vWorld;
uniform vec3 albedo;
uniform float checker;
uniform vec3 sunTowards;
uniform vec3 sunColour;
out vec4 fragColour;
void main() {
    vec3 n = normalize(vNormal);
    vec3 sun = normalize(sunTowards);
    vec3 fireLight = splatfx_emittedIrradiance(vWorld, n) * 0.31830989;
    float smokeShadow = splatfx_shadowTo(0, vWorld);
    vec3 light = vec3(0.10, 0.11, 0.16) + sunColour * max(dot(n, sun), 0.0) * smokeShadow + fireLight;
    float c = 1.0;
    if (checker > 0.0) c = (mod(floor(vWorld.x) + floor(vWorld.z), 2.0) < 1.0) ? 1.0 : 0.7;
    fragColour = vec4(albedo * c * light, 1.0);
}
)";

// OGRE 1.12 learns a uniform array's size from the GLSL text and reads only
// a literal there: an array sized by a named constant gets size 0 and its
// parameters cannot be set. The include's two such sizes, spelled out.
std::string ogreReadable(std::string glsl) {
    for (const auto& [name, n] : {std::pair<std::string, int>{"splatfx_kMaxEmittedLights]", splatfx::kMaxEmittedLights},
                                  std::pair<std::string, int>{"splatfx_kMaxShadowLights]", splatfx::kMaxShadowLights}}) {
        std::string literal = std::to_string(n);
        literal += ']';
        for (std::size_t at = glsl.find(name); at != std::string::npos; at = glsl.find(name, at))
            if (at > 0 && glsl[at - 1] == '[') glsl.replace(at, name.size(), literal);
            else at += name.size();
    }
    return glsl;
}

// OGRE's matrices act on column vectors, as GL's and glm's do, but are
// stored by rows: m[row][col], where glm is g[col][row].
glm::mat4 toGlm(const Ogre::Matrix4& m) {
    glm::mat4 g(1.0f);
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) g[c][r] = float(m[r][c]);
    return g;
}
// An Affine3 stores three rows; the fourth is (0, 0, 0, 1).
glm::mat4 toGlm(const Ogre::Affine3& m) {
    glm::mat4 g(1.0f);
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) g[c][r] = float(m[r][c]);
    return g;
}

std::string describe(const Ogre::Exception& e) { return e.getFullDescription(); }

} // namespace

struct OgreCampfire::Impl : public Ogre::RenderQueueListener {
    OgreCampfireDesc desc;
    // OGRE. The log manager is made first so that OGRE writes no Ogre.log
    // into the working directory (messages still reach the listener: none).
    std::unique_ptr<Ogre::LogManager> logManager;
    std::unique_ptr<Ogre::Root> root;
    Ogre::RenderWindow* window = nullptr;
    Ogre::SceneManager* sceneManager = nullptr;
    Ogre::Camera* ogreCamera = nullptr;
    Ogre::TexturePtr colourTexture;
    Ogre::RenderTexture* target = nullptr;
    Ogre::Viewport* viewport = nullptr;
    Ogre::SceneNode* logNode = nullptr;
    // The fragment parameters of the three materials: the fire's lights go there each frame.
    std::vector<Ogre::GpuProgramParametersSharedPtr> surfaceParams;
    // The smoke's shadow table (FrameShadow of slot 0) as an OGRE 3D texture,
    // on texture unit 0 of each material's pass; re-uploaded when its version changes.
    Ogre::TexturePtr shadowTexture;
    std::vector<Ogre::TextureUnitState*> shadowUnits;
    glm::ivec3 shadowDims{0};
    std::uint64_t shadowVersion = 0;
    bool shadowUploaded = false;

    // splatfx.
    splatfx::Materials materials{splatfx::Footprint{}};
    splatfx::Scene scene;
    splatfx::Frame frame;
    std::optional<splatfx::gl::FrameRenderer> renderer;
    splatfx::Camera drawnCamera;

    // The copy of OGRE's depth (OGRE's GL3Plus attaches a renderbuffer, which
    // no shader can sample): a texture of the same internal format, and an
    // FBO to blit into. Made on first use, remade when the size changes.
    GLuint depthCopy = 0, depthCopyFbo = 0;
    GLint depthCopyFormat = 0;
    int depthCopyW = 0, depthCopyH = 0;

    FrameOptions frameOptions;
    HookInfo info;
    std::string hookError;

    // The frame's emitted lights (Frame::emittedLights) into shadowGlsl()'s
    // uniforms on every surface material: what gl::setShadowUniforms does for
    // a GL program, through OGRE's parameters (OGRE uploads its own copy of
    // every uniform it knows, so glProgramUniform would be overwritten).
    void setFireLight(bool on) {
        constexpr int kMax = splatfx::kMaxEmittedLights;
        const std::vector<splatfx::EmittedLight>& lights = frame.emittedLights();
        const int count = on ? int(std::min<std::size_t>(lights.size(), std::size_t(kMax))) : 0;
        float position[4 * kMax] = {}, intensity[3 * kMax] = {}, plus[3 * kMax] = {}, minus[3 * kMax] = {};
        for (int i = 0; i < count; ++i) {
            const splatfx::EmittedLight& l = lights[std::size_t(i)];
            for (int c = 0; c < 3; ++c) {
                position[4 * i + c] = l.position[c];
                intensity[3 * i + c] = l.intensity[c];
                plus[3 * i + c] = l.escapePlus[c];
                minus[3 * i + c] = l.escapeMinus[c];
            }
            position[4 * i + 3] = l.radius;
        }
        for (const Ogre::GpuProgramParametersSharedPtr& fp : surfaceParams) {
            fp->setNamedConstant("splatfx_emittedLightCount", count);
            fp->setNamedConstant("splatfx_emittedLightPosition", position, kMax, 4);
            fp->setNamedConstant("splatfx_emittedLightIntensity", intensity, kMax, 3);
            fp->setNamedConstant("splatfx_emittedLightEscapePlus", plus, kMax, 3);
            fp->setNamedConstant("splatfx_emittedLightEscapeMinus", minus, kMax, 3);
        }
    }

    // (Re)makes the shadow texture for `dims` when they changed (the units
    // follow it) and uploads `depth` (dims.x * dims.y * dims.z floats, x fastest).
    void uploadShadow(glm::ivec3 dims, const float* depth) {
        if (dims != shadowDims || !shadowTexture) {
            if (shadowTexture) Ogre::TextureManager::getSingleton().remove(shadowTexture);
            shadowTexture = Ogre::TextureManager::getSingleton().createManual("splatfx/smokeShadow", Ogre::RGN_DEFAULT, Ogre::TEX_TYPE_3D,
                                                                              Ogre::uint(dims.x), Ogre::uint(dims.y), Ogre::uint(dims.z), 0,
                                                                              Ogre::PF_FLOAT32_R, Ogre::TU_DYNAMIC_WRITE_ONLY);
            for (Ogre::TextureUnitState* u : shadowUnits) u->setTexture(shadowTexture);
            shadowDims = dims;
        }
        const Ogre::PixelBox box(Ogre::uint32(dims.x), Ogre::uint32(dims.y), Ogre::uint32(dims.z), Ogre::PF_FLOAT32_R, const_cast<float*>(depth));
        shadowTexture->getBuffer()->blitFromMemory(box);
    }

    // shadowGlsl()'s table of slot 0 (the sun's: the smoke's transmittance)
    // through OGRE: what gl::setShadowUniforms and the FrameRenderer's own
    // upload do for a GL program, but as an OGRE texture and OGRE parameters,
    // because OGRE draws its surfaces before splatfx's hook runs (the
    // FrameRenderer binds its tables only while it renders). The table is the
    // frame's optical depth in log2 units, R32F, linear, clamped
    // (docs/lighting.md, "For a GL pass"); off, or without a table, slot 0
    // names no light and splatfx_shadowTo(0, ...) returns 1.
    splatfx::Status setSmokeShadow(bool on) {
        const splatfx::FrameShadow& sh = frame.shadows()[0];
        const bool valid = on && sh.valid && sh.light == 0 && sh.dims.x > 0 && sh.dims.y > 0 && sh.dims.z > 0 &&
                           sh.depth.size() == std::size_t(sh.dims.x) * std::size_t(sh.dims.y) * std::size_t(sh.dims.z);
        try {
            if (valid && (!shadowUploaded || sh.version != shadowVersion || sh.dims != shadowDims)) {
                uploadShadow(sh.dims, sh.depth.data());
                shadowVersion = sh.version;
                shadowUploaded = true;
            }
        } catch (const Ogre::Exception& e) { return splatfx::makeError("OGRE: the smoke's shadow table: " + describe(e)); }
        const int index[splatfx::kMaxShadowLights] = {valid ? 0 : -1, -1, -1, -1};
        // OGRE keeps matrices by rows (Ogre::Matrix4) and GL3Plus uploads them transposed
        // (glUniformMatrix4fv, transpose GL_TRUE), raw floats too: hand it the rows.
        const glm::mat4 worldToTable = glm::transpose(valid ? sh.worldToTable : glm::mat4(1.0f));
        const glm::vec4 light = valid ? sh.lightInTable : glm::vec4(0.0f, -1.0f, 0.0f, 0.0f);
        for (const Ogre::GpuProgramParametersSharedPtr& fp : surfaceParams) {
            fp->setNamedConstant("splatfx_shadowLightIndex", index, 1, splatfx::kMaxShadowLights);
            fp->setNamedConstant("splatfx_worldToTable", &worldToTable[0][0], 4, 4);
            fp->setNamedConstant("splatfx_shadowLight", &light[0], 1, 4);
        }
        return {};
    }

    ~Impl() override {
        if (depthCopyFbo) glDeleteFramebuffers(1, &depthCopyFbo);
        if (depthCopy) glDeleteTextures(1, &depthCopy);
        renderer.reset(); // its GL objects live in OGRE's context: before the Root goes
        shadowTexture.reset();
        if (sceneManager) sceneManager->removeRenderQueueListener(this);
        colourTexture.reset();
        root.reset(); // destroys the window and the context
        logManager.reset();
    }

    splatfx::Camera convert() const {
        // OGRE's view matrix and its [-1, 1]-depth projection (GL3Plus uses
        // GL's clip convention; getProjectionMatrixWithRSDepth is the same
        // matrix there). A GL render texture is drawn upside down
        // (RenderTarget::requiresTextureFlipping), OGRE negating the
        // projection's second row (AutoParamDataSource::getProjectionMatrix);
        // splatfx must draw with the same flip or its fire stands on its head.
        const glm::mat4 view = toGlm(ogreCamera->getViewMatrix(true));
        glm::mat4 proj = toGlm(ogreCamera->getProjectionMatrixWithRSDepth());
        if (target->requiresTextureFlipping())
            for (int c = 0; c < 4; ++c) proj[c][1] = -proj[c][1];
        // Under OGRE's "Reversed Z-Buffer" the matrix is [0, 1] and reversed
        // (GL3Plus sets glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE)): read off it.
        const splatfx::DepthConvention depth =
            desc.reverseZ ? splatfx::conventionOfProjection(proj, splatfx::ClipDepth::ZeroToOne) : splatfx::DepthConvention{};
        return splatfx::Camera::fromMatrices(view, proj, {desc.width, desc.height}, depth);
    }

    // Makes (or remakes) the depth copy for OGRE's depth attachment of `fbo`.
    // Returns the texture splatfx reads, or 0 with hookError set.
    GLuint depthTextureFor(GLuint fbo, int w, int h) {
        GLint type = GL_NONE, name = 0;
        glGetNamedFramebufferAttachmentParameteriv(fbo, GL_DEPTH_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
        glGetNamedFramebufferAttachmentParameteriv(fbo, GL_DEPTH_ATTACHMENT, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME, &name);
        info.depthObjectType = unsigned(type);
        if (type == GL_TEXTURE) { // a depth texture already: hand it over as it is
            GLint format = 0;
            glGetTextureLevelParameteriv(GLuint(name), 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
            info.depthInternalFormat = unsigned(format);
            info.depthCopied = false;
            return GLuint(name);
        }
        if (type != GL_RENDERBUFFER) {
            hookError = "OGRE's framebuffer " + std::to_string(fbo) + " has no depth attachment";
            return 0;
        }
        GLint format = 0, samples = 0;
        glGetNamedRenderbufferParameteriv(GLuint(name), GL_RENDERBUFFER_INTERNAL_FORMAT, &format);
        glGetNamedRenderbufferParameteriv(GLuint(name), GL_RENDERBUFFER_SAMPLES, &samples);
        info.depthInternalFormat = unsigned(format);
        info.depthSamples = samples;
        if (samples > 1) {
            // OGRE's FSAA: a multisampled renderbuffer. splatfx copies it into a
            // multisampled texture itself and reads it sample by sample
            // (FrameRendererDesc::copyHostDepth): hand over no texture.
            info.depthCopied = true;
            return 0;
        }
        if (!depthCopy || format != depthCopyFormat || w != depthCopyW || h != depthCopyH) {
            if (depthCopyFbo) glDeleteFramebuffers(1, &depthCopyFbo);
            if (depthCopy) glDeleteTextures(1, &depthCopy);
            // Direct state access throughout: nothing is bound, so OGRE's
            // state cache (which remembers bindings) is never wrong about them.
            glCreateTextures(GL_TEXTURE_2D, 1, &depthCopy);
            glTextureStorage2D(depthCopy, 1, GLenum(format), w, h);
            glTextureParameteri(depthCopy, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glTextureParameteri(depthCopy, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
            glTextureParameteri(depthCopy, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
            glTextureParameteri(depthCopy, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
            glCreateFramebuffers(1, &depthCopyFbo);
            const bool stencil = format == GL_DEPTH24_STENCIL8 || format == GL_DEPTH32F_STENCIL8;
            glNamedFramebufferTexture(depthCopyFbo, stencil ? GL_DEPTH_STENCIL_ATTACHMENT : GL_DEPTH_ATTACHMENT, depthCopy, 0);
            glNamedFramebufferDrawBuffer(depthCopyFbo, GL_NONE);
            glNamedFramebufferReadBuffer(depthCopyFbo, GL_NONE);
            const GLenum status = glCheckNamedFramebufferStatus(depthCopyFbo, GL_DRAW_FRAMEBUFFER);
            if (status != GL_FRAMEBUFFER_COMPLETE) {
                hookError =
                    "the depth copy's framebuffer is incomplete (status " + std::to_string(status) + ", format " + std::to_string(format) + ")";
                return 0;
            }
            depthCopyFormat = format;
            depthCopyW = w;
            depthCopyH = h;
        }
        // A blit is not a draw: of the per-fragment operations only the
        // scissor test applies (HookInfo::scissor records OGRE's), and a named
        // blit binds nothing. Same internal format on both sides, as GL requires.
        glBlitNamedFramebuffer(fbo, depthCopyFbo, 0, 0, w, h, 0, 0, w, h, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
        info.depthCopied = true;
        return depthCopy;
    }

    // OGRE's frame: after its main render-queue group (its opaque geometry
    // and that group's transparents), before later groups (overlays, ...).
    void renderQueueEnded(Ogre::uint8 queueGroupId, const Ogre::String& invocation, bool& repeat) override {
        (void)invocation;
        repeat = false;
        if (queueGroupId != Ogre::RENDER_QUEUE_MAIN) return;
        if (sceneManager->getCurrentViewport() != viewport) return; // only the camera's viewport (not shadow maps)

        // 1. OGRE's framebuffer: the one it has bound now, checked against
        // the render target's own name for it.
        GLint fbo = 0;
        glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &fbo);
        info.framebuffer = unsigned(fbo);
        try { // GL3Plus names its FBO through a custom attribute; not every version has it
            Ogre::uint32 id = 0;
            target->getCustomAttribute("GL_FBOID", &id);
            info.framebufferFromOgre = id;
        } catch (const Ogre::Exception&) { info.framebufferFromOgre = 0; }
        GLint vp[4] = {};
        glGetIntegerv(GL_VIEWPORT, vp);
        std::copy(vp, vp + 4, info.viewport);
        info.scissor = glIsEnabled(GL_SCISSOR_TEST) == GL_TRUE;
        glGetIntegerv(GL_SCISSOR_BOX, info.scissorBox);
        // 2. OGRE's depth as a texture (a copy: see depthTextureFor).
        const GLuint depth = depthTextureFor(GLuint(fbo), desc.width, desc.height);
        if (!depth && !hookError.empty()) return;
        // 3. OGRE's camera, converted (flip included): the one render() prepared the frame with.
        drawnCamera = convert();
        info.flipped = target->requiresTextureFlipping();
        if (!frameOptions.fire) return; // the depth copy is still made: tests compare frames with and without
        // 4. Draw. OGRE drew its opaque geometry itself: no drawOpaque hook.
        // The viewport origin is OGRE's (GL's lower left).
        // An sRGB target blends in linear only with GL_FRAMEBUFFER_SRGB on (OGRE
        // turns it on for a hardware-gamma target; made sure of, then put back).
        const bool srgbWasOn = glIsEnabled(GL_FRAMEBUFFER_SRGB) == GL_TRUE;
        info.framebufferSrgb = srgbWasOn;
        if (desc.srgb && !srgbWasOn) glEnable(GL_FRAMEBUFFER_SRGB);
        GLint clipDepth = 0;
        glGetIntegerv(GL_CLIP_DEPTH_MODE, &clipDepth);
        info.clipZeroToOne = clipDepth == GL_ZERO_TO_ONE;
        renderer->render(frame, {.framebuffer = unsigned(fbo), .x = vp[0], .y = vp[1], .depthTexture = depth});
        if (desc.srgb && !srgbWasOn) glDisable(GL_FRAMEBUFFER_SRGB);
        info.splats = renderer->stats().splats;
        info.msaaSamples = renderer->stats().msaa.samples;
        info.notes = renderer->stats().notes;
        ++info.calls;
    }
};

OgreCampfire::OgreCampfire(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
OgreCampfire::~OgreCampfire() = default;

splatfx::Result<std::unique_ptr<OgreCampfire>> OgreCampfire::create(const OgreCampfireDesc& desc) {
    using splatfx::makeError;
    if (desc.width < 16 || desc.height < 16 || desc.width > 8192 || desc.height > 8192)
        return makeError("OgreCampfireDesc::width/height: " + std::to_string(desc.width) + "x" + std::to_string(desc.height) +
                         "; expected each in [16, 8192]");
    if (desc.msaa != 0 && desc.msaa != 1 && desc.msaa != 2 && desc.msaa != 4 && desc.msaa != 8)
        return makeError("OgreCampfireDesc::msaa: " + std::to_string(desc.msaa) + "; expected 0, 1, 2, 4 or 8");
    if (desc.resolutionScale != 1 && desc.resolutionScale != 2 && desc.resolutionScale != 4)
        return makeError("OgreCampfireDesc::resolutionScale: " + std::to_string(desc.resolutionScale) + "; expected 1, 2 or 4");
    if (!std::getenv("DISPLAY"))
        return makeError("OGRE's GL3Plus render system needs an X display (GLX) and DISPLAY is not set; "
                         "run headless under xvfb-run (tools/setup-deps.sh installs it)");

    auto impl = std::make_unique<Impl>();
    Impl& s = *impl;
    s.desc = desc;
    try {
        s.logManager = std::make_unique<Ogre::LogManager>();
        s.logManager->createLog("ogre-campfire", /*default*/ true, /*debuggerOutput*/ false, /*suppressFile*/ true);
        // No plugins.cfg, ogre.cfg or resources.cfg: the one plugin is loaded
        // by its path (OGRE's CMake package says where plugins are), and the
        // scene needs no resource locations (meshes and materials made in code).
        s.root = std::make_unique<Ogre::Root>("", "", "");
        const std::string dir = desc.pluginDir.empty() ? std::string(SPLATFX_OGRE_PLUGIN_DIR) : desc.pluginDir;
        s.root->loadPlugin(dir + "/RenderSystem_GL3Plus");
        Ogre::RenderSystem* rs = s.root->getRenderSystemByName("OpenGL 3+ Rendering Subsystem");
        if (!rs) return makeError("OGRE has no \"OpenGL 3+ Rendering Subsystem\" after loading " + dir + "/RenderSystem_GL3Plus");
        if (desc.reverseZ) rs->setConfigOption("Reversed Z-Buffer", "Yes");
        s.root->setRenderSystem(rs);
        s.root->initialise(false);
        // The window only carries the GL context; OGRE draws into a render texture.
        Ogre::NameValuePairList params{{"hidden", "true"}, {"vsync", "false"}};
        s.window = s.root->createRenderWindow("splatfx inside OGRE", 64, 64, false, &params);
        s.window->setAutoUpdated(false);
        // OGRE decides on its reversed depth once the context exists (it needs GL_ARB_clip_control).
        if (desc.reverseZ && !rs->isReverseDepthBufferEnabled())
            return makeError("OGRE's GL3Plus did not enable its \"Reversed Z-Buffer\" (it needs GL_ARB_clip_control)");

        s.sceneManager = s.root->createSceneManager();
        s.sceneManager->addRenderQueueListener(&s);

        // Materials: one GLSL program pair, three colours.
        auto& programs = Ogre::HighLevelGpuProgramManager::getSingleton();
        const Ogre::String group = Ogre::RGN_DEFAULT;
        auto vs = programs.createProgram("splatfx/lambert.vert", group, "glsl", Ogre::GPT_VERTEX_PROGRAM);
        vs->setSource(kVertexShader);
        auto fs = programs.createProgram("splatfx/lambert.frag", group, "glsl", Ogre::GPT_FRAGMENT_PROGRAM);
        fs->setSource("#version 330 core\n" + ogreReadable(splatfx::shadowGlsl()) + kFragmentShader);
        vs->load();
        fs->load();
        if (vs->hasCompileError() || fs->hasCompileError()) return makeError("OGRE could not compile the sample's GLSL materials");
        auto material = [&](const char* name, Ogre::Vector3 albedo, float checker) {
            Ogre::MaterialPtr m = Ogre::MaterialManager::getSingleton().create(name, group);
            Ogre::Pass* pass = m->getTechnique(0)->getPass(0);
            pass->setVertexProgram(vs->getName());
            pass->setFragmentProgram(fs->getName());
            auto vp = pass->getVertexProgramParameters();
            vp->setNamedAutoConstant("worldViewProj", Ogre::GpuProgramParameters::ACT_WORLDVIEWPROJ_MATRIX);
            vp->setNamedAutoConstant("world", Ogre::GpuProgramParameters::ACT_WORLD_MATRIX);
            auto fp = pass->getFragmentProgramParameters();
            fp->setNamedConstant("albedo", albedo);
            fp->setNamedConstant("checker", checker);
            fp->setNamedConstant("sunTowards", Ogre::Vector3(kSunTowards[0], kSunTowards[1], kSunTowards[2]));
            fp->setNamedConstant("sunColour", Ogre::Vector3(kSunColour[0], kSunColour[1], kSunColour[2]));
            // The smoke's shadow table on the pass's texture unit 0 (its texture set by
            // setSmokeShadow). Every slot's sampler3D reads unit 0: slots 1 to 3 name no
            // light and are never sampled, but a sampler must not share a unit with another type.
            Ogre::TextureUnitState* unit = pass->createTextureUnitState();
            unit->setTextureFiltering(Ogre::FO_LINEAR, Ogre::FO_LINEAR, Ogre::FO_NONE);
            unit->setTextureAddressingMode(Ogre::TextureUnitState::TAM_CLAMP);
            s.shadowUnits.push_back(unit);
            for (const char* table : {"splatfx_shadowTable", "splatfx_shadowTable1", "splatfx_shadowTable2", "splatfx_shadowTable3"})
                fp->setNamedConstant(table, 0);
            s.surfaceParams.push_back(fp);
            m->load();
            return m;
        };
        auto ground = material("splatfx/ground", {0.45f, 0.42f, 0.36f}, 1.0f);
        auto wood = material("splatfx/log", {0.42f, 0.25f, 0.13f}, 0.0f);
        auto stone = material("splatfx/wall", {0.50f, 0.50f, 0.52f}, 0.0f);
        // setFireLight writes whole arrays: had OGRE read an array's size wrongly
        // (ogreReadable), the write would assert inside OGRE. Checked here, once.
        for (const Ogre::GpuProgramParametersSharedPtr& fp : s.surfaceParams)
            for (const auto& [name, floats] : {std::pair<const char*, std::size_t>{"splatfx_emittedLightPosition", 4},
                                               {"splatfx_emittedLightIntensity", 3},
                                               {"splatfx_emittedLightEscapePlus", 3},
                                               {"splatfx_emittedLightEscapeMinus", 3}}) {
                const Ogre::GpuConstantDefinition* d = fp->_findNamedConstantDefinition(name, false);
                if (!d || d->elementSize * d->arraySize < floats * std::size_t(splatfx::kMaxEmittedLights))
                    return makeError(std::string("OGRE did not take the fire-light uniform ") + name + "[" +
                                     std::to_string(splatfx::kMaxEmittedLights) + "] of the sample's material" +
                                     (d ? " (it reads " + std::to_string(d->arraySize) + " elements)" : ""));
            }
        // Until the first frame with a table, the units hold a 1^3 table of zero depth (unshadowed).
        const float zeroDepth = 0.0f;
        s.uploadShadow(glm::ivec3(1), &zeroDepth);
        // The same for the shadow slots' light indices (setSmokeShadow writes all four).
        for (const Ogre::GpuProgramParametersSharedPtr& fp : s.surfaceParams) {
            const Ogre::GpuConstantDefinition* d = fp->_findNamedConstantDefinition("splatfx_shadowLightIndex", false);
            if (!d || d->elementSize * d->arraySize < std::size_t(splatfx::kMaxShadowLights))
                return makeError("OGRE did not take the shadow uniform splatfx_shadowLightIndex[" + std::to_string(splatfx::kMaxShadowLights) +
                                 "] of the sample's material" + (d ? " (it reads " + std::to_string(d->arraySize) + " elements)" : ""));
        }

        Ogre::SceneNode* rootNode = s.sceneManager->getRootSceneNode();
        Ogre::MeshManager::getSingleton().createPlane("splatfx/groundPlane", group, Ogre::Plane(Ogre::Vector3::UNIT_Y, 0.0f), 60.0f, 60.0f, 1, 1,
                                                      true, 1, 1.0f, 1.0f, Ogre::Vector3::UNIT_Z);
        Ogre::Entity* groundEntity = s.sceneManager->createEntity("ground", "splatfx/groundPlane");
        groundEntity->setMaterial(ground);
        rootNode->createChildSceneNode()->attachObject(groundEntity);
        auto box = [&](const char* name, const float* centre, const float* size, const Ogre::MaterialPtr& m) {
            Ogre::Entity* e = s.sceneManager->createEntity(name, Ogre::SceneManager::PT_CUBE);
            e->setMaterial(m);
            Ogre::SceneNode* n = rootNode->createChildSceneNode(Ogre::Vector3(centre[0], centre[1], centre[2]));
            n->setScale(size[0] / kPrefabCubeSize, size[1] / kPrefabCubeSize, size[2] / kPrefabCubeSize);
            n->attachObject(e);
            return n;
        };
        s.logNode = box("log", kLogCentre, kLogSize, wood);
        box("wall", kWallCentre, kWallSize, stone);

        // The camera: where sample 01 looks at its campfire from.
        s.ogreCamera = s.sceneManager->createCamera("camera");
        s.ogreCamera->setNearClipDistance(0.5f);
        s.ogreCamera->setFarClipDistance(100.0f);
        s.ogreCamera->setFOVy(Ogre::Degree(45.0f));
        s.ogreCamera->setAspectRatio(float(desc.width) / float(desc.height));
        Ogre::SceneNode* camNode = rootNode->createChildSceneNode(Ogre::Vector3(0.0f, 4.8f, 15.0f));
        camNode->lookAt(Ogre::Vector3(0.0f, 4.0f, 0.0f), Ogre::Node::TS_WORLD);
        camNode->attachObject(s.ogreCamera);

        // The render target OGRE draws into (as an engine with post-processing does).
        s.colourTexture = Ogre::TextureManager::getSingleton().createManual("splatfx/frame", group, Ogre::TEX_TYPE_2D, Ogre::uint(desc.width),
                                                                            Ogre::uint(desc.height), 0, Ogre::PF_BYTE_RGBA, Ogre::TU_RENDERTARGET,
                                                                            nullptr, desc.srgb, Ogre::uint(desc.msaa > 1 ? desc.msaa : 0));
        s.target = s.colourTexture->getBuffer()->getRenderTarget();
        s.viewport = s.target->addViewport(s.ogreCamera);
        s.viewport->setBackgroundColour(Ogre::ColourValue(0.05f, 0.06f, 0.10f, 1.0f));
        s.viewport->setClearEveryFrame(true);
        s.viewport->setOverlaysEnabled(false);
    } catch (const Ogre::Exception& e) { return makeError("OGRE: " + describe(e)); } catch (const std::exception& e) {
        return makeError(std::string("OGRE: ") + e.what());
    }

    // splatfx, in OGRE's context (current on this thread since initialise()).
    s.info.glRenderer =
        std::string(reinterpret_cast<const char*>(glGetString(GL_RENDERER))) + " / " + reinterpret_cast<const char*>(glGetString(GL_VERSION));
    auto fire = splatfx::presets::fire(s.materials, {.dims = {7, 20, 5},
                                                     .spacing = glm::vec3(0.5f),
                                                     .propagationStepsPerSec = 8.0f,
                                                     .texturesPerSec = 6.0f,
                                                     .crossfade = true,
                                                     .seed = desc.seed});
    if (!fire) return makeError(fire.error());
    // The fire lights OGRE's ground, log and wall: two point lights fitted to its
    // splats each frame (emitted_light.hpp), at 6x the splats' own emission (a
    // flame is far brighter than the display white its colour table stops at;
    // docs/samples.md, 03: the scene-file samples take 12; this wall stands
    // nearer a larger fire, which at 12 lit it to white).
    splatfx::EffectOptions fireOptions;
    fireOptions.name = "campfire";
    fireOptions.emitsLight.enabled = true;
    fireOptions.emitsLight.lights = 2;
    fireOptions.emitsLight.scale = 6.0f;
    s.scene.add(std::move(*fire), std::move(fireOptions));
    if (desc.smoke) {
        // The sun of OGRE's shader as splatfx's scene light 0 (it travels away from
        // kSunTowards): it lights the smoke, and the frame's scene-shadow table for it
        // (SceneShadowDesc's default: light 0, 64^3) is the smoke's shadow on OGRE's surfaces.
        const glm::vec3 towards(kSunTowards[0], kSunTowards[1], kSunTowards[2]);
        if (auto l = s.scene.addLight(splatfx::Light::directional(-glm::normalize(towards), {1.0f, 0.97f, 0.92f}, 1.0f)); !l)
            return makeError(l.error());
        // Above the flames (the fire's lattice is 10 tall, its flames end lower), the
        // emitter at the domain's left; a breeze carries the smoke right and a little forward.
        splatfx::presets::SmokeDesc smoke;
        smoke.dims = {14, 14, 8};
        smoke.spacing = glm::vec3(0.5f);
        smoke.position = {2.5f, 7.0f, 0.0f};
        smoke.sourceOffset = {-2.5f, 0.5f, 0.0f};
        smoke.sourceRadius = 0.9f;
        smoke.windWorld = {1.6f, 0.0f, 0.4f};
        smoke.dissipation = 0.05f; // a thick campfire smoke: it thins slowly
        smoke.seed = desc.seed;
        auto plume = splatfx::presets::smoke(s.materials, smoke);
        if (!plume) return makeError(plume.error());
        splatfx::EffectOptions smokeOptions;
        smokeOptions.name = "smoke";
        smokeOptions.lighting.enabled = true;
        smokeOptions.lighting.gas.albedo = 0.7f;
        smokeOptions.lighting.gas.ambient = {0.16f, 0.17f, 0.24f};
        smokeOptions.draw.opacityScale = 2.5f;
        s.scene.add(std::move(*plume), std::move(smokeOptions));
    }
    splatfx::gl::FrameRendererDesc frd;
    frd.resolutionScale = desc.resolutionScale;
    frd.splats.restoreState = desc.restoreState;
    auto r = splatfx::gl::FrameRenderer::create(frd);
    if (!r) return makeError("splatfx in OGRE's context: " + r.error());
    s.renderer = std::move(*r);
    if (auto st = s.renderer->upload(s.materials); !st) return makeError(st.error());
    s.drawnCamera = s.convert();
    return std::unique_ptr<OgreCampfire>(new OgreCampfire(std::move(impl)));
}

splatfx::Status OgreCampfire::render(const FrameOptions& options) {
    Impl& s = *mImpl;
    s.frameOptions = options;
    s.info.calls = 0;
    s.info.splats = 0;
    s.hookError.clear();
    // The frame is prepared before OGRE draws: its emitted lights light OGRE's
    // surfaces, which OGRE draws before the hook (with options.fire off too:
    // only the splats are left out then).
    s.drawnCamera = s.convert();
    if (auto st = s.scene.prepare(options.timeSec, s.drawnCamera, s.materials, s.frame); !st) return st;
    s.setFireLight(options.fireLight);
    if (auto st = s.setSmokeShadow(options.smokeShadow); !st) return st;
    try {
        s.logNode->setVisible(options.log);
        if (!s.root->renderOneFrame()) return splatfx::makeError("OGRE's renderOneFrame asked to stop");
    } catch (const Ogre::Exception& e) { return splatfx::makeError("OGRE: " + describe(e)); }
    if (!s.hookError.empty()) return splatfx::makeError(s.hookError);
    if (options.fire && s.info.calls != 1)
        return splatfx::makeError("the render-queue hook drew " + std::to_string(s.info.calls) + " times in one frame; expected 1");
    return {};
}

splatfx::Result<splatfx::Image> OgreCampfire::readColour() const {
    const Impl& s = *mImpl;
    Ogre::Image image;
    try {
        s.colourTexture->convertToImage(image);
    } catch (const Ogre::Exception& e) { return splatfx::makeError("OGRE: " + describe(e)); }
    splatfx::Image out;
    out.width = int(image.getWidth());
    out.height = int(image.getHeight());
    out.channels = 4;
    out.pixels.resize(std::size_t(out.width) * out.height * 4);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x) {
            const Ogre::ColourValue c = image.getColourAt(std::size_t(x), std::size_t(y), 0);
            float* p = &out.pixels[(std::size_t(y) * out.width + x) * 4];
            p[0] = c.r;
            p[1] = c.g;
            p[2] = c.b;
            p[3] = c.a;
        }
    return out;
}

splatfx::Result<std::vector<float>> OgreCampfire::readDepth() const {
    const Impl& s = *mImpl;
    if (!s.depthCopy) return splatfx::makeError("no depth copy yet: render a frame with the fire first");
    const int w = s.depthCopyW, h = s.depthCopyH;
    std::vector<float> gl(std::size_t(w) * h);
    // The read honours the pack state and a bound pixel-pack buffer: both
    // are OGRE's, so they are set for the read and put back exactly.
    GLint packBuffer = 0, alignment = 4, rowLength = 0, skipRows = 0, skipPixels = 0;
    glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &packBuffer);
    glGetIntegerv(GL_PACK_ALIGNMENT, &alignment);
    glGetIntegerv(GL_PACK_ROW_LENGTH, &rowLength);
    glGetIntegerv(GL_PACK_SKIP_ROWS, &skipRows);
    glGetIntegerv(GL_PACK_SKIP_PIXELS, &skipPixels);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glPixelStorei(GL_PACK_SKIP_ROWS, 0);
    glPixelStorei(GL_PACK_SKIP_PIXELS, 0);
    glGetTextureImage(s.depthCopy, 0, GL_DEPTH_COMPONENT, GL_FLOAT, GLsizei(gl.size() * sizeof(float)), gl.data());
    glBindBuffer(GL_PIXEL_PACK_BUFFER, GLuint(packBuffer));
    glPixelStorei(GL_PACK_ALIGNMENT, alignment);
    glPixelStorei(GL_PACK_ROW_LENGTH, rowLength);
    glPixelStorei(GL_PACK_SKIP_ROWS, skipRows);
    glPixelStorei(GL_PACK_SKIP_PIXELS, skipPixels);
    // GL's row 0 is the bottom of the texture. A flipped target (OGRE's
    // render textures) holds the image's top row there, which is what
    // readColour() returns first; otherwise reverse.
    if (!s.target->requiresTextureFlipping()) {
        std::vector<float> top(gl.size());
        for (int y = 0; y < h; ++y) std::memcpy(&top[std::size_t(y) * w], &gl[std::size_t(h - 1 - y) * w], std::size_t(w) * sizeof(float));
        gl.swap(top);
    }
    return gl;
}

const splatfx::Camera& OgreCampfire::camera() const { return mImpl->drawnCamera; }
splatfx::Camera OgreCampfire::convertedCamera() const { return mImpl->convert(); }
const splatfx::Frame& OgreCampfire::frame() const { return mImpl->frame; }
const HookInfo& OgreCampfire::hook() const { return mImpl->info; }
int OgreCampfire::width() const { return mImpl->desc.width; }
int OgreCampfire::height() const { return mImpl->desc.height; }

} // namespace ogrefx
