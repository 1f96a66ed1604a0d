// samples/common: the frame loop every sample shares, windowed or headless.
//
// A sample supplies setup (materials, grids) and a per-frame callback that
// draws into the given target; SampleApp handles the command line
// (--frames N --out DIR --size WxH --seed S; the host's frame: --reverse-z / --clip-01 / --infinite-far,
// --msaa N, --srgb, --hdr; --scale N), the context (a GLFW window by default, headless EGL when --frames is
// given), PNG frames (and EXR with --hdr), the animated GIF, progress output, the frame renderer's
// notes and a summary.
// Public SDK API only.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/output_set.hpp"
#include "splatfx/splatfx.hpp"

namespace samples {

struct Options {
    int frames = 0;          // > 0: headless, render this many frames then exit
    std::string out = "out"; // output folder (headless)
    glm::ivec2 size{640, 480};
    std::uint32_t seed = 1;
    float fps = 24.0f;
    bool traditional = false; // untextured splats (Fig. 1a)
    std::string extra;        // sample-specific flag value (see each sample's --help)
    // --reverse-z, --clip-01, --infinite-far: the depth convention the sample's host draws with
    // (the loop sets glClipControl and, reversed, a float depth buffer; the sample's camera and
    // clear follow FrameContext::depth).
    splatfx::DepthConvention depth{};
    // --msaa N, --srgb, --hdr: the colour target the sample's host draws into (docs/integration.md,
    // "what your engine does"): N-sample colour and depth, resolved for the PNG and the window;
    // GL_SRGB8_ALPHA8 with GL_FRAMEBUFFER_SRGB on; RGBA16F, each frame also as a linear EXR.
    int msaa = 0;
    bool srgb = false;
    bool hdr = false;
    // --scale N: the sample's volumes at 1/N resolution per axis (FrameRendererDesc::resolutionScale: 1, 2 or 4).
    int scale = 1;
};

// The frame renderer's fallbacks (gl::FrameRenderStats::notes), as splatfx-render
// says them: each line printed once, "<name>: note: <line>", the first frame it
// appears, and all of them again under the headless summary.
class Notes {
public:
    explicit Notes(std::string name) : mName(std::move(name)) {}
    void add(const std::vector<std::string>& lines);
    const std::vector<std::string>& lines() const { return mLines; }
    void setMidLine(bool midLine) { mMidLine = midLine; } // the loop's progress line is open: start a new one first

private:
    std::string mName;
    std::vector<std::string> mLines;
    bool mMidLine = false;
};

// Parses argv (samples/common/sample_options.hpp). Returns -1 when the sample
// goes on, else the exit code: 0 after printing the help, 2 after a bad option.
int parseOptions(int argc, char** argv, const char* name, const char* about, Options& options);

struct FrameContext {
    int index = 0;        // frame number
    double timeSec = 0.0; // index / fps: animation time never depends on the wall clock
    glm::ivec2 size{0};
    splatfx::gl::PassTarget target;
    // Headless: the run's output set, for extra files beside the frames
    // (write at outputs->path(f), then outputs->add(f)); null when windowed.
    splatfx::OutputSet* outputs = nullptr;
    splatfx::DepthConvention depth{}; // Options::depth: build the camera with it, clear depth to depth.farWindow()
    bool hdr = false;                 // Options::hdr: an RGBA16F target (a scene with lights: Scene::setHdrLit)
    Notes* notes = nullptr;           // add the frame renderer's stats().notes after each render (never null in run())
};

// Runs the loop. frame() draws one frame (the host part: clear, geometry, then
// splats) and returns false to stop with an error it has printed.
// Headless: writes DIR/<name>_NNNN.png (and, with --hdr, DIR/<name>_NNNN.exr)
// and DIR/<name>.gif as one output set (splatfx/output_set.hpp). Windowed with
// --msaa/--srgb/--hdr: the frame is drawn into a target of that kind and copied
// to the window, as splatfx-viewer does. Returns the process exit code.
int run(const Options& options, const char* name, const std::function<bool()>& setup, const std::function<bool(const FrameContext&)>& frame);

} // namespace samples
