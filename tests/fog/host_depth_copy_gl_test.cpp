// A host whose depth is not a texture (a window's default framebuffer, a
// depth renderbuffer): gl::FrameRenderer copies the depth buffer after the
// opaque pass (FrameRendererDesc::copyHostDepth) and every pass reads the
// copy, so the host gets the same fog and the same depth cut as a host that
// hands over a depth texture of the same format. The copy is a blit between
// equal formats; a driver may take it through float (llvmpipe does for
// DEPTH24_STENCIL8), which can move a value by one step of the format: the
// bound below is what one step does to the image.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/gl/frame_renderer.hpp"

namespace splatfx {
namespace {

constexpr glm::ivec2 kSize{64, 48};

Fog testFog() {
    FogDesc d;
    d.terms.push_back(FogTerm::constant(0.08));
    d.terms.push_back(FogTerm::point(0.6, {0.3, 0.0, 0.5}, 1.0, 3.0));
    d.colour = {0.7, 0.75, 0.8};
    return *Fog::create(d);
}

// Splats around the origin, half of them behind the host's wall at z = -0.2
// (so the cut matters) and a fog over all of it.
struct Scene {
    Materials materials{Footprint{}};
    Frame frame;
    Scene() {
        materials.addColorTable(ColorTable::constant({0.9f, 0.5f, 0.2f, 1.0f}));
        Grid g;
        for (int z = -2; z <= 2; ++z)
            for (int x = -2; x <= 2; ++x) g.voxels.push_back({.cell = {x, 0, z}, .opacity = 0.4f});
        g.spacing = glm::vec3(0.5f);
        frame.begin(0.0, Camera::lookAt({0.4f, 1.2f, 4.0f}, {0, 0, 0}, {0, 1, 0}, 0.9f, kSize, 0.05f, 30.0f));
        frame.builder().add(g, materials, {.textured = false});
        frame.end();
        frame.setFog(std::make_shared<const Fog>(testFog()));
    }
};

// The host's opaque pass: a background colour, and a wall (depth written by
// a scissored clear) on the left half at a depth inside the splats.
void drawHost(double wallDepth) {
    glClearColor(0.1f, 0.2f, 0.3f, 1.0f);
    glClearDepth(1.0);
    glDepthMask(GL_TRUE);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, 0, kSize.x / 2, kSize.y);
    glClearDepth(wallDepth);
    glClearColor(0.5f, 0.5f, 0.45f, 1.0f);
    glClear(GL_DEPTH_BUFFER_BIT | GL_COLOR_BUFFER_BIT);
    glDisable(GL_SCISSOR_TEST);
    glClearDepth(1.0);
}

// A framebuffer with an RGBA32F colour texture and a depth buffer of
// `depthFormat` (0: none): a renderbuffer, or (asTexture) a texture of the
// same format, the host that hands splatfx its depth as a texture.
struct Target {
    GLuint fbo = 0, color = 0, depth = 0;
    bool texture = false;
    explicit Target(GLenum depthFormat, bool asTexture = false) : texture(asTexture) {
        glCreateFramebuffers(1, &fbo);
        glCreateTextures(GL_TEXTURE_2D, 1, &color);
        glTextureStorage2D(color, 1, GL_RGBA32F, kSize.x, kSize.y);
        glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, color, 0);
        if (!depthFormat) return;
        const GLenum point = depthFormat == GL_DEPTH24_STENCIL8 || depthFormat == GL_DEPTH32F_STENCIL8 ? GL_DEPTH_STENCIL_ATTACHMENT : GL_DEPTH_ATTACHMENT;
        if (asTexture) {
            glCreateTextures(GL_TEXTURE_2D, 1, &depth);
            glTextureStorage2D(depth, 1, depthFormat, kSize.x, kSize.y);
            glNamedFramebufferTexture(fbo, point, depth, 0);
        } else {
            glCreateRenderbuffers(1, &depth);
            glNamedRenderbufferStorage(depth, depthFormat, kSize.x, kSize.y);
            glNamedFramebufferRenderbuffer(fbo, point, GL_RENDERBUFFER, depth);
        }
    }
    ~Target() {
        glDeleteFramebuffers(1, &fbo);
        glDeleteTextures(1, &color);
        if (texture) glDeleteTextures(1, &depth);
        else glDeleteRenderbuffers(1, &depth);
    }
    std::vector<float> read() const {
        std::vector<float> px(std::size_t(kSize.x) * kSize.y * 4);
        glGetTextureImage(color, 0, GL_RGBA, GL_FLOAT, GLsizei(px.size() * sizeof(float)), px.data());
        return px;
    }
};

class HostDepthCopyGL : public test::GLTest {};

TEST_F(HostDepthCopyGL, ADepthRenderbufferGetsTheSameFogAndCutAsADepthTexture) {
    Scene s;
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr) << fr.error();
    ASSERT_TRUE(fr->upload(s.materials));
    const double wall = 0.9985; // ~ 3.8 units: among the splats

    for (GLenum format : {GL_DEPTH_COMPONENT24, GL_DEPTH24_STENCIL8, GL_DEPTH_COMPONENT32F, GL_DEPTH32F_STENCIL8, GL_DEPTH_COMPONENT16}) {
        // The reference host: the same format as a depth texture attachment.
        Target tex(format, true);
        fr->render(s.frame, {.framebuffer = tex.fbo, .drawOpaque = [&] { drawHost(wall); }});
        ASSERT_TRUE(fr->stats().fog.host) << fr->stats().fog.error;
        EXPECT_FALSE(fr->stats().hostDepthCopied);
        const std::vector<float> withTexture = tex.read();
        {
            Target rb(format);
            ASSERT_EQ(glCheckNamedFramebufferStatus(rb.fbo, GL_DRAW_FRAMEBUFFER), GLenum(GL_FRAMEBUFFER_COMPLETE));
            fr->render(s.frame, {.framebuffer = rb.fbo, .drawOpaque = [&] { drawHost(wall); }});
            EXPECT_TRUE(fr->stats().hostDepthCopied) << "format " << format;
            EXPECT_TRUE(fr->stats().fog.host) << fr->stats().fog.error;
            EXPECT_TRUE(fr->stats().notes.empty()) << fr->stats().notes.front();
            const std::vector<float> px = rb.read();
            double worst = 0.0;
            for (std::size_t i = 0; i < px.size(); ++i) worst = std::max(worst, double(std::abs(px[i] - withTexture[i])));
            // One step of the format at the wall's depth d moves its point by dz = step * dz/dd,
            // dz/dd = n f (f - n) / (f - d (f - n))^2 (here ~5000 units per unit depth); the fog's
            // depth by at most its largest density (0.08 + 0.6 / 1) times dz, the pixel by as
            // much (colours <= 1); the splats' cut moves by the same dz through kernels of
            // extinction well under that density's. The sky (depth 1) is copied exactly.
            const double n = 0.05, f = 30.0;
            const double step = format == GL_DEPTH_COMPONENT16 ? std::ldexp(1.0, -16)
                                : (format == GL_DEPTH_COMPONENT32F || format == GL_DEPTH32F_STENCIL8) ? std::ldexp(wall, -24)
                                                                                                      : std::ldexp(1.0, -24);
            const double dzdd = n * f * (f - n) / ((f - wall * (f - n)) * (f - wall * (f - n)));
            const double bound = (0.08 + 0.6) * step * dzdd;
            EXPECT_LE(worst, bound) << "format " << format << ": the copied depth must give the depth texture's image within one depth step";
        }
    }
}

TEST_F(HostDepthCopyGL, WithoutACopyOrADepthBufferTheNotesSaySo) {
    Scene s;
    auto noCopy = gl::FrameRenderer::create({.copyHostDepth = false});
    ASSERT_TRUE(noCopy);
    ASSERT_TRUE(noCopy->upload(s.materials));
    {
        Target rb(GL_DEPTH_COMPONENT24);
        noCopy->render(s.frame, {.framebuffer = rb.fbo, .drawOpaque = [] { drawHost(1.0); }});
        EXPECT_FALSE(noCopy->stats().fog.host);
        EXPECT_NE(noCopy->stats().fog.error.find("copyHostDepth"), std::string::npos) << noCopy->stats().fog.error;
    }
    auto fr = gl::FrameRenderer::create();
    ASSERT_TRUE(fr);
    ASSERT_TRUE(fr->upload(s.materials));
    Target none(0);
    fr->render(s.frame, {.framebuffer = none.fbo, .drawOpaque = [] {
                             glClearColor(0.1f, 0.2f, 0.3f, 1.0f);
                             glClear(GL_COLOR_BUFFER_BIT);
                         }});
    EXPECT_FALSE(fr->stats().hostDepthCopied);
    EXPECT_FALSE(fr->stats().fog.host);
    EXPECT_NE(fr->stats().fog.error.find("no depth buffer"), std::string::npos) << fr->stats().fog.error;
}

} // namespace
} // namespace splatfx
