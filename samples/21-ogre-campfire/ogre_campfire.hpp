// samples/21-ogre-campfire/ogre_campfire.hpp: splatfx's campfire drawn inside
// OGRE 1.12 (GL3Plus): into OGRE's render target, against OGRE's depth, from a
// RenderQueueListener in OGRE's own frame, with OGRE's camera.
//
// What it is: a small OGRE application (its Root, a hidden window for the GL
// context, a scene manager with a ground, a log in front of the fire and a
// wall behind it, drawn with GLSL materials made in code, lit by a sun that
// the fire's smoke shadows and by the fire's emitted lights) whose main render queue ends with splatfx's
// gl::FrameRenderer drawing the campfire into the framebuffer OGRE has bound. It shows what an engine hands over (its
// framebuffer name, its depth as a texture, its camera) and what state has
// to survive (docs/integration.md, "Inside an engine").
// What it does not do: load OGRE's sample media (Debian ships none), use
// OGRE's RTSS, draw to the window (the frame is a render texture, read back).
//
//   auto app = ogrefx::OgreCampfire::create({.width = 640, .height = 360});
//   if (!app) return fail(app.error());
//   (*app)->render({.timeSec = 1.0}); auto image = (*app)->readColour();
//
// Needs an X display (GLX; run headless under xvfb-run). Threading: one
// thread, the one that created it (OGRE's GL context is current there).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "splatfx/camera.hpp"
#include "splatfx/frame.hpp"
#include "splatfx/image.hpp"
#include "splatfx/result.hpp"

namespace ogrefx {

// Towards the sun (not normalised): high, from the left and a little in front,
// so the smoke drifting right above the fire throws its shadow onto the ground
// right of the fire, in front of the wall. One direction for OGRE's shader
// (uniform sunTowards, Lambert) and splatfx's scene light 0 (lights the smoke
// and casts its shadow).
inline constexpr float kSunTowards[3] = {-0.35f, 1.0f, 0.25f};
// The sun's colour x intensity in OGRE's shader (irradiance on a surface facing it).
inline constexpr float kSunColour[3] = {0.6f, 0.58f, 0.55f};

struct OgreCampfireDesc {
    int width = 640;         // render-texture size, pixels; default 640
    int height = 360;        // default 360
    std::uint32_t seed = 1;  // the fire's texture dynamics; default 1
    int resolutionScale = 1; // splatfx::gl::FrameRendererDesc::resolutionScale (1, 2, 4); default 1
    // splatfx's GL-state guard (RendererDesc::restoreState). false only to
    // show what OGRE's state cache does without it (the test's negative
    // control); default true.
    bool restoreState = true;
    std::string pluginDir{}; // OGRE's plugin folder; empty: the one OGRE's CMake package names; default empty
    // An engine's frame (docs/integration.md, "What your engine does"): OGRE's own
    // "Reversed Z-Buffer" option (glClipControl [0, 1], near at depth 1), its render
    // texture multisampled (FSAA) or sRGB (hardware gamma). Defaults: off, 0, false.
    bool reverseZ = false;
    int msaa = 0; // 0 or 1: single-sampled; 2, 4, 8: OGRE's FSAA on the render texture
    bool srgb = false;
    // The fire's smoke, lit by the sun that lights OGRE's surfaces (splatfx's
    // scene light 0), drifting right; its shadow falls on OGRE's ground through
    // shadowGlsl() in OGRE's material. Default true.
    bool smoke = true;
};

struct FrameOptions {
    double timeSec = 1.0; // the fire's time; default 1
    bool fire = true;     // draw splatfx's splats in OGRE's frame (off: its light on OGRE's surfaces stays); default true
    bool log = true;      // OGRE draws the log in front of the fire; default true
    bool fireLight = true; // the fire's emitted lights on OGRE's surfaces; off: none (the test's comparison); default true
    bool smokeShadow = true; // the smoke's shadow (the frame's scene-shadow table) on OGRE's surfaces; off: none; default true
};

// What the render-queue hook saw in the last frame (for the docs and tests).
struct HookInfo {
    int calls = 0;                    // times the hook drew splatfx in the last frame
    unsigned framebuffer = 0;         // OGRE's draw framebuffer at the hook
    unsigned framebufferFromOgre = 0; // the same, asked of OGRE (RenderTarget "GL_FBOID"/"FBO")
    unsigned depthObjectType = 0;     // GL_RENDERBUFFER or GL_TEXTURE: what OGRE attached as depth
    unsigned depthInternalFormat = 0; // its GL internal format (the copy's)
    bool depthCopied = false;         // the depth was blitted into a texture (renderbuffer depth)
    int viewport[4] = {0, 0, 0, 0};   // the GL viewport OGRE set
    bool scissor = false;             // OGRE left the scissor test on (it limits the depth blit)
    int scissorBox[4] = {0, 0, 0, 0}; // and its box
    bool flipped = false;             // OGRE renders this target upside down (requiresTextureFlipping)
    std::size_t splats = 0;           // splats splatfx drew
    std::string glRenderer;           // GL_RENDERER / GL_VERSION of OGRE's context
    int depthSamples = 0;             // OGRE's depth renderbuffer's samples (FSAA; then splatfx copies it)
    int msaaSamples = 0;              // FrameRenderStats::msaa.samples: what splatfx drew per sample (0: single-sampled)
    bool framebufferSrgb = false;     // OGRE had GL_FRAMEBUFFER_SRGB on at the hook
    bool clipZeroToOne = false;       // OGRE had glClipControl(..., GL_ZERO_TO_ONE) at the hook
    std::vector<std::string> notes;   // FrameRenderStats::notes: anything splatfx approximated
};

class OgreCampfire {
public:
    // Starts OGRE (GL3Plus plugin, a hidden window, the scene) and splatfx
    // (the fire preset, gl::FrameRenderer). Fails with OGRE's message when
    // there is no display or no GL3Plus plugin, and with splatfx's when the
    // context is not GL 4.5.
    static splatfx::Result<std::unique_ptr<OgreCampfire>> create(const OgreCampfireDesc& desc = {});
    ~OgreCampfire();
    OgreCampfire(const OgreCampfire&) = delete;
    OgreCampfire& operator=(const OgreCampfire&) = delete;

    // One OGRE frame (Root::renderOneFrame): OGRE clears and draws its
    // queues; at the end of the main queue the hook draws the fire.
    splatfx::Status render(const FrameOptions& options = {});
    // The render texture as OGRE reads it back: RGBA in [0, 1], top row first.
    splatfx::Result<splatfx::Image> readColour() const;
    // OGRE's depth as handed to splatfx (the copy), window depth in [0, 1],
    // width*height values, top row first (same rows as readColour()).
    splatfx::Result<std::vector<float>> readDepth() const;
    // The camera splatfx drew with (converted from Ogre::Camera, flip included).
    const splatfx::Camera& camera() const;
    // The camera computed from Ogre::Camera now (valid before any frame).
    splatfx::Camera convertedCamera() const;
    const splatfx::Frame& frame() const;
    const HookInfo& hook() const;
    int width() const;
    int height() const;

    struct Impl;

private:
    explicit OgreCampfire(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> mImpl;
};

} // namespace ogrefx
