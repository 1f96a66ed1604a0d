// splatfx-bench table1: the paper's Table I on this machine, plus the fill
// limit of this GL implementation, a naive baseline renderer, and the CPU
// cost per voxel from 10^2 to 10^6 voxels (issue 7).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <numeric>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <epoxy/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "options.hpp"
#include "splatfx/context.hpp"
#include "splatfx/gl/program.hpp"
#include "splatfx/gl/scaled_renderer.hpp"
#include "splatfx/splatfx.hpp"

namespace table1_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

using Clock = std::chrono::steady_clock;
double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

struct Row {
    glm::ivec2 window;
    int voxels;
    double o2, indy, octane, onyx2; // Hz, King et al. 1999, Table I
};
const Row kRows[] = {
    {{320, 240}, 1560, 12, 0.39, 36, 60}, {{640, 480}, 1560, 12, 0.063, 24, 60}, {{1280, 960}, 1560, 5, 0.02, 8, 30},
    {{320, 240}, 780, 20, 0.8, 36, 60},   {{320, 240}, 390, 30, 1.6, 40, 60},    {{320, 240}, 195, 60, 3, 72, 60},
};

// The paper's fire grid proportions (7x20x5) at each voxel count, always
// 3.5 x 10 x 2.5 world units so the fire fills the window height in every row.
glm::ivec3 dimsFor(int voxels) {
    switch (voxels) {
    case 195: return {3, 13, 5};
    case 390: return {6, 13, 5};
    case 780: return {6, 26, 5};
    case 1560: return {12, 26, 5};
    default: {
        const int side = std::max(1, int(std::round(std::cbrt(voxels / 4.0))));
        return {side, 4 * side, side};
    }
    }
}

splatfx::Grid fireGrid(int voxels, std::uint32_t seed) {
    const glm::ivec3 d = dimsFor(voxels);
    splatfx::Grid g = *splatfx::Grid::box(d, glm::vec3(3.5f / d.x, 10.0f / d.y, 2.5f / d.z));
    std::uint32_t h = seed;
    for (splatfx::Voxel& v : g.voxels) {
        const float t = float(v.cell.y) / float(std::max(d.y - 1, 1));
        v.opacity = 0.5f * (1.0f - 0.6f * t);
        h = h * 1664525u + 1013904223u;
        v.texture = h >> 8;
    }
    return g;
}

splatfx::Camera fireCamera(glm::ivec2 window) {
    // 45 degree vertical field of view; the 10-unit fire spans ~85 % of the height.
    return splatfx::Camera::lookAt({0, 5.0f, 14.0f}, {0, 5.0f, 0}, {0, 1, 0}, glm::radians(45.0f), window, 0.1f, 100.0f);
}

// Local dynamics used in every timed frame: texture cycling with cross-fade,
// a pure function of time (what the campfire sample does).
void cycle(const splatfx::Grid& base, splatfx::Grid& grid, double t) {
    const double steps = t * 6.0;
    const auto whole = std::uint32_t(std::floor(steps));
    const float phase = float(steps - std::floor(steps));
    for (size_t i = 0; i < grid.voxels.size(); ++i) {
        grid.voxels[i].texture = base.voxels[i].texture + whole;
        grid.voxels[i].phase = phase;
    }
}

// The probes' programs; a failure is printed and leaves 0 (the probe then reports nothing).
GLuint compileProgram(const char* vs, const char* fs) {
    const splatfx::Result<GLuint> p = splatfx::gl::linkProgram({vs}, {fs}, "table1 bench");
    if (!p) std::fprintf(stderr, "table1: %s\n", p.error().c_str());
    return p ? *p : 0;
}

// Draw state both probes share: the target, premultiplied "over", no depth test.
void beginOver(GLuint fbo, glm::ivec2 size, GLuint program) {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, size.x, size.y);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glDisable(GL_DEPTH_TEST);
    glUseProgram(program);
}

// Median seconds per call of f over `frames` frames, after `warm` untimed ones.
template <class F>
double medianFrame(int warm, int frames, F f) {
    for (int i = 0; i < warm; ++i) f(i);
    std::vector<double> t;
    for (int i = 0; i < frames; ++i) {
        const auto a = Clock::now();
        f(warm + i);
        t.push_back(seconds(a, Clock::now()));
    }
    std::sort(t.begin(), t.end());
    return t[t.size() / 2];
}

// Fragments that reached the blender in what draw() submits (GL_SAMPLES_PASSED).
template <class F>
GLuint64 samplesPassed(F draw) {
    GLuint query = 0;
    glGenQueries(1, &query);
    glBeginQuery(GL_SAMPLES_PASSED, query);
    draw();
    glEndQuery(GL_SAMPLES_PASSED);
    GLuint64 samples = 0;
    glGetQueryObjectui64v(query, GL_QUERY_RESULT, &samples);
    glDeleteQueries(1, &query);
    return samples;
}

// The splat fragment's work: one texture-array fetch, exp2, colour multiply.
const char* kSplatWork = R"(#version 450 core
    layout(binding = 0) uniform sampler2DArray uLayers;
    in vec2 vTex; flat in float vLayer; out vec4 o;
    void main() { vec4 t = texture(uLayers, vec3(vTex, vLayer));
                  float a = 1.0 - exp2(-0.05 * t.a); o = vec4(vec3(1.0, 0.6, 0.2) * t.rgb * a, a); })";

// The fill limit: full-screen quads doing a fragment's work (by default the
// splat's, fetching from the renderer's own texture array with its sampling,
// premultiplied "over" into the same RGBA8 target). Nothing else can make
// splat fragments cheaper.
class FillProbe {
public:
    explicit FillProbe(const char* fragment = kSplatWork) {
        program = compileProgram(R"(#version 450 core
            const vec2 k[4] = vec2[4](vec2(-1,-1), vec2(1,-1), vec2(-1,1), vec2(1,1));
            out vec2 vTex; flat out float vLayer;
            void main() { vTex = k[gl_VertexID] * 0.5 + 0.5; vLayer = float(gl_InstanceID % 8 + 1);
                          gl_Position = vec4(k[gl_VertexID], 0.5, 1.0); })",
                                 fragment);
        glCreateVertexArrays(1, &vao);
    }
    ~FillProbe() {
        glDeleteProgram(program);
        glDeleteProgram(squares);
        glDeleteVertexArrays(1, &vao);
    }
    // Fragments per second for `quads` full-screen quads.
    double rate(GLuint fbo, glm::ivec2 size, GLuint layers, int quads, bool blend = true) {
        beginOver(fbo, size, program);
        if (!blend) glDisable(GL_BLEND);
        glBindTextureUnit(0, layers);
        glBindVertexArray(vao);
        const double sec = medianFrame(1, 5, [&](int) {
            glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, quads);
            glFinish();
        });
        glDisable(GL_BLEND);
        return double(quads) * size.x * size.y / sec;
    }
    // Fragments per second for `count` screen-aligned squares of `side`
    // pixels scattered over `region` (x0, y0, x1, y1 in pixels), one draw:
    // the fill rate this rasterizer reaches for primitives of the splats'
    // size, with the same per-fragment work.
    double rateSquares(GLuint fbo, glm::ivec2 size, GLuint layers, int count, float side, glm::vec4 region) {
        if (!squares)
            squares = compileProgram(R"(#version 450 core
                const vec2 k[4] = vec2[4](vec2(0,0), vec2(1,0), vec2(0,1), vec2(1,1));
                uniform vec2 uViewport; uniform float uSide; uniform vec4 uRegion;
                out vec2 vTex; flat out float vLayer;
                float hash(uint x) { x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16; return float(x) / 4294967296.0; }
                void main() {
                    uint i = uint(gl_InstanceID);
                    vec2 at = uRegion.xy + vec2(hash(2u * i), hash(2u * i + 1u)) * max(uRegion.zw - uRegion.xy - uSide, vec2(0.0));
                    vec2 p = at + k[gl_VertexID] * uSide;
                    vTex = k[gl_VertexID]; vLayer = float(gl_InstanceID % 8 + 1);
                    gl_Position = vec4(p / uViewport * 2.0 - 1.0, 0.5, 1.0); })",
                                     kSplatWork);
        beginOver(fbo, size, squares);
        glUniform2f(glGetUniformLocation(squares, "uViewport"), float(size.x), float(size.y));
        glUniform1f(glGetUniformLocation(squares, "uSide"), side);
        glUniform4fv(glGetUniformLocation(squares, "uRegion"), 1, glm::value_ptr(region));
        glBindTextureUnit(0, layers);
        glBindVertexArray(vao);
        const auto draw = [&] { glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, count); };
        const GLuint64 samples = samplesPassed(draw); // also the warm-up
        const double sec = medianFrame(0, 15, [&](int) {
            draw();
            glFinish();
        });
        glDisable(GL_BLEND);
        return double(samples) / sec;
    }
    GLuint program = 0, squares = 0, vao = 0;
};

// What a user might write in an afternoon: instanced square billboards, no
// sort, no footprint math, one texture-array fetch and one colour-table fetch
// per fragment, buffer re-specified every frame.
class NaiveRenderer {
public:
    struct Instance {
        glm::vec4 centerSize;   // xyz, half size
        glm::vec4 opacityLayer; // opacity, layer, colour coordinate, unused
    };
    NaiveRenderer() {
        program = compileProgram(R"(#version 450 core
            layout(location = 0) in vec4 aCenterSize; layout(location = 1) in vec4 aOpacityLayer;
            uniform mat4 uViewProj; uniform vec3 uRight; uniform vec3 uUp;
            const vec2 k[4] = vec2[4](vec2(-1,-1), vec2(1,-1), vec2(-1,1), vec2(1,1));
            out vec2 vTex; flat out vec3 vData;
            void main() { vec2 c = k[gl_VertexID]; vTex = c * 0.5 + 0.5; vData = aOpacityLayer.xyz;
                          vec3 p = aCenterSize.xyz + aCenterSize.w * (c.x * uRight + c.y * uUp);
                          gl_Position = uViewProj * vec4(p, 1.0); })",
                                 R"(#version 450 core
            layout(binding = 0) uniform sampler2DArray uLayers; layout(binding = 1) uniform sampler2D uColors;
            in vec2 vTex; flat in vec3 vData; out vec4 o;
            void main() { vec4 t = texture(uLayers, vec3(vTex, vData.y)); vec3 c = texture(uColors, vec2(vData.z, 0.5)).rgb;
                          float a = clamp(vData.x * t.a, 0.0, 1.0); o = vec4(c * a, a); })");
        glCreateVertexArrays(1, &vao);
        glCreateBuffers(1, &buffer);
        glVertexArrayVertexBuffer(vao, 0, buffer, 0, sizeof(Instance));
        glVertexArrayBindingDivisor(vao, 0, 1);
        for (GLuint a = 0; a < 2; ++a) {
            glEnableVertexArrayAttrib(vao, a);
            glVertexArrayAttribFormat(vao, a, 4, GL_FLOAT, GL_FALSE, a * 16);
            glVertexArrayAttribBinding(vao, a, 0);
        }
    }
    ~NaiveRenderer() {
        glDeleteProgram(program);
        glDeleteVertexArrays(1, &vao);
        glDeleteBuffers(1, &buffer);
    }
    void draw(const splatfx::Grid& grid, const splatfx::Materials& m, const splatfx::Camera& cam, GLuint fbo, glm::ivec2 size, GLuint layers,
              GLuint colors) {
        instances.clear();
        const float half = m.footprint().radius() * std::max({grid.spacing.x, grid.spacing.y, grid.spacing.z});
        for (const splatfx::Voxel& v : grid.voxels)
            instances.push_back({glm::vec4(grid.worldPosition(v.cell), half), glm::vec4(v.opacity, float(1 + v.texture % 8), v.colorCoord, 0.0f)});
        glNamedBufferData(buffer, GLsizeiptr(instances.size() * sizeof(Instance)), instances.data(), GL_STREAM_DRAW);
        beginOver(fbo, size, program);
        const glm::mat4 vp = cam.proj * cam.view;
        glUniformMatrix4fv(glGetUniformLocation(program, "uViewProj"), 1, GL_FALSE, glm::value_ptr(vp));
        glUniform3fv(glGetUniformLocation(program, "uRight"), 1, glm::value_ptr(cam.right()));
        glUniform3fv(glGetUniformLocation(program, "uUp"), 1, glm::value_ptr(cam.up()));
        glBindTextureUnit(0, layers);
        glBindTextureUnit(1, colors);
        glBindVertexArray(vao);
        glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, GLsizei(instances.size()));
        glDisable(GL_BLEND);
    }
    GLuint program = 0, vao = 0, buffer = 0;
    std::vector<Instance> instances;
};

// Uploads the same layers and colour rows the SDK's renderer uses, for the
// probes that need them directly.
struct GpuMaterials {
    GLuint layers = 0, colors = 0;
    explicit GpuMaterials(const splatfx::Materials& m) {
        const int n = m.layerSize();
        glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &layers);
        glTextureStorage3D(layers, 1, GL_RGBA8, n, n, GLsizei(m.layerCount()));
        for (std::uint32_t i = 0; i < m.layerCount(); ++i)
            glTextureSubImage3D(layers, 0, 0, 0, GLint(i), n, n, 1, GL_RGBA, GL_FLOAT, m.layer(i).data());
        glTextureParameteri(layers, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTextureParameteri(layers, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glCreateTextures(GL_TEXTURE_2D, 1, &colors);
        glTextureStorage2D(colors, 1, GL_RGBA16F, m.colorTableSize(), 1);
        glTextureSubImage2D(colors, 0, 0, 0, m.colorTableSize(), 1, GL_RGBA, GL_FLOAT, m.colorRow(0).data());
        glTextureParameteri(colors, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTextureParameteri(colors, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    }
    ~GpuMaterials() {
        glDeleteTextures(1, &layers);
        glDeleteTextures(1, &colors);
    }
};

struct RowResult {
    double scaledHz = 0;
    int scale = 1; // reduced-resolution result where full resolution misses the Onyx2 rate
    double hz = 0, naiveHz = 0, fillFraction = 0, splatFragsPerSec = 0, fillRate = 0, covered = 0, overdraw = 0;
    double naiveFragsPerSec = 0;
    double sizedRate = 0, side = 0; // fill rate of screen-aligned squares of the splats' mean size, and that size
};

struct Settings {
    int frames = 30;
    splatfx::gl::RendererDesc renderer; // the SDK defaults unless an option says otherwise
    bool crossfade = false;
    // The presets' default; --paper-lattice: none (splats on the lattice, as in the paper).
    splatfx::SplatVariation variation = splatfx::SplatVariation::recommended(1);
};

RowResult measureRow(const Row& row, const Settings& settings) {
    const int frames = settings.frames;
    RowResult out;
    splatfx::Materials materials{splatfx::Footprint{}};
    const auto set = materials.addTextureSet(splatfx::TextureSet::turbulence({.count = 8, .size = 32, .seed = 1}));
    const auto lut = materials.addColorTable(splatfx::ColorTable::fire());
    auto fb = splatfx::gl::Framebuffer::create({.width = row.window.x, .height = row.window.y});
    auto renderer = splatfx::gl::FrameRenderer::create({.splats = settings.renderer});
    if (!fb || !renderer || !renderer->upload(materials)) {
        std::fprintf(stderr, "table1: GL setup failed\n");
        return out;
    }
    const splatfx::Grid base = fireGrid(row.voxels, 1);
    splatfx::Grid grid = base;
    const splatfx::Camera cam = fireCamera(row.window);
    splatfx::Frame frame;
    const splatfx::gl::HostTarget target{.framebuffer = fb->handle()};
    const splatfx::SplatStyle style{.textureSet = set, .colorTable = lut, .crossfade = settings.crossfade, .variation = settings.variation};

    // Full frame as an application runs it: dynamics, build, sort, upload,
    // draw, and wait for the pixels (glFinish), at 60 simulated frames/s.
    auto fullFrame = [&](splatfx::gl::FrameRenderer& r) {
        return [&](int i) {
            cycle(base, grid, i / 60.0);
            frame.begin(i / 60.0, cam);
            frame.builder().add(grid, materials, style);
            frame.end();
            fb->clear({0, 0, 0, 1});
            r.render(frame, target);
            glFinish();
        };
    };
    out.hz = 1.0 / medianFrame(5, frames, fullFrame(*renderer));

    // Coverage and overdraw: samples that reached the blender / pixels touched.
    fb->clear({0, 0, 0, 0});
    const GLuint64 samples = samplesPassed([&] { renderer->render(frame, target); });
    const splatfx::Image img = fb->read();
    size_t covered = 0;
    glm::vec4 region(float(row.window.x), float(row.window.y), 0.0f, 0.0f); // covered pixels' bounds
    for (size_t p = 3; p < img.pixels.size(); p += 4)
        if (img.pixels[p] > 0.0f) {
            ++covered;
            // Image rows run top down; GL's window y runs bottom up.
            const float x = float((p / 4) % size_t(img.width)), y = float(img.height - 1 - int((p / 4) / size_t(img.width)));
            region = glm::vec4(std::min(region.x, x), std::min(region.y, y), std::max(region.z, x + 1), std::max(region.w, y + 1));
        }
    out.covered = double(covered);
    out.overdraw = covered ? double(samples) / double(covered) : 0.0;

    // The splat pass alone (splats already built), as fragments per second.
    const double drawSec = medianFrame(3, frames, [&](int) {
        renderer->render(frame, target);
        glFinish();
    });
    out.splatFragsPerSec = double(samples) / drawSec;
    GpuMaterials gpu(materials);
    FillProbe fill;
    // At least 64 screens of fragments so the timing is not dominated by one draw's fixed cost.
    const int quads = std::max(64, int(samples / (double(row.window.x) * row.window.y)));
    // The renderer's own layer texture: the same texels, size and sampling per fragment.
    out.fillRate = fill.rate(fb->handle(), row.window, renderer->splatRenderer().layerTexture(), quads);
    out.fillFraction = out.splatFragsPerSec / out.fillRate;
    // The same fragments as squares of the splats' mean size: what limits small splats.
    const int splats = int(frame.splats().size());
    const float side = std::sqrt(float(samples) / float(std::max(splats, 1)));
    out.sizedRate = fill.rateSquares(fb->handle(), row.window, renderer->splatRenderer().layerTexture(), splats, side, region);
    out.side = side;

    // Where full resolution misses the Onyx2 rate, the same full frame with
    // the splat pass at half, then quarter resolution (depth-aware upsampling;
    // its accuracy cost is in the accuracy benchmark's render-scale rows).
    if (out.hz < row.onyx2) {
        for (int scale : {2, 4}) {
            auto scaled = splatfx::gl::FrameRenderer::create({.splats = settings.renderer, .resolutionScale = scale});
            if (!scaled || !scaled->upload(materials)) break;
            out.scaledHz = 1.0 / medianFrame(5, frames, fullFrame(*scaled));
            out.scale = scale;
            if (out.scaledHz >= row.onyx2) break;
        }
    }

    NaiveRenderer naive;
    out.naiveHz = 1.0 / medianFrame(5, frames, [&](int i) {
                      cycle(base, grid, i / 60.0);
                      fb->clear({0, 0, 0, 1});
                      naive.draw(grid, materials, cam, fb->handle(), row.window, gpu.layers, gpu.colors);
                      glFinish();
                  });
    // The naive pass's own fragment rate (its draw alone, instance upload included).
    const GLuint64 naiveSamples = samplesPassed([&] { naive.draw(grid, materials, cam, fb->handle(), row.window, gpu.layers, gpu.colors); });
    const double naiveSec = medianFrame(3, frames, [&](int) {
        naive.draw(grid, materials, cam, fb->handle(), row.window, gpu.layers, gpu.colors);
        glFinish();
    });
    out.naiveFragsPerSec = double(naiveSamples) / naiveSec;
    return out;
}

// What one fragment costs on this GL: full-screen quads from the simplest
// fragment up to the splat's, so the fill fraction's reference is in view.
// The CSV is optional: a null file means the table is only printed.
[[gnu::format(printf, 2, 3)]] void csvPrintf(std::FILE* csv, const char* format, ...) {
    if (!csv) return;
    va_list args;
    va_start(args, format);
    std::vfprintf(csv, format, args);
    va_end(args);
}

void fragmentCosts(std::FILE* csv) {
    const glm::ivec2 size{640, 480};
    splatfx::Materials materials{splatfx::Footprint{}};
    materials.addTextureSet(splatfx::TextureSet::turbulence({.count = 8, .size = 32, .seed = 1}));
    materials.addColorTable(splatfx::ColorTable::fire());
    auto fb = splatfx::gl::Framebuffer::create({.width = size.x, .height = size.y});
    auto renderer = splatfx::gl::Renderer::create();
    if (!fb || !renderer || !renderer->upload(materials)) return;
    GpuMaterials bilinear(materials);
    const char* flat = "#version 450 core\nout vec4 o; void main() { o = vec4(0.5, 0.3, 0.2, 0.5); }";
    const char* fetch = R"(#version 450 core
        layout(binding = 0) uniform sampler2DArray uLayers; in vec2 vTex; flat in float vLayer; out vec4 o;
        void main() { o = texture(uLayers, vec3(vTex, vLayer)); })";
    struct Probe {
        const char *name, *fragment;
        bool blend;
        GLuint layers;
    };
    const std::string upsampled = "splat fragment, " +
                                  std::string(renderer->sampling() == splatfx::gl::TextureSampling::Upsampled
                                                  ? "upsampled " + std::to_string(renderer->upsampleFactor()) + "x, nearest"
                                                  : "bilinear") +
                                  " (default)";
    const Probe probes[] = {
        {"flat colour, no blend", flat, false, 0},
        {"flat colour, over blend", flat, true, 0},
        {"bilinear texture fetch, over blend", fetch, true, bilinear.layers},
        {"splat fragment (fetch, exp2, colour), bilinear", kSplatWork, true, bilinear.layers},
        {upsampled.c_str(), kSplatWork, true, renderer->layerTexture()},
    };
    std::printf("Fragment cost on this GL: full-screen quads at %dx%d into RGBA8, 64 screens per draw\n", size.x, size.y);
    csvPrintf(csv, "fragment_probe,mfrag_s\n");
    for (const Probe& p : probes) {
        FillProbe probe(p.fragment);
        const double rate = probe.rate(fb->handle(), size, p.layers, 64, p.blend);
        std::printf("  %-50s %8.0f Mfrag/s\n", p.name, rate / 1e6);
        csvPrintf(csv, "\"%s\",%.1f\n", p.name, rate / 1e6);
    }
    std::printf("\n");
    csvPrintf(csv, "\n");
}

// CPU work per frame (dynamics + build + sort + copy into the instance
// stream) at growing voxel counts.
void cpuScaling(std::FILE* csv, const splatfx::SplatVariation& variation) {
    const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
    std::printf("\nCPU work per frame (texture cycling + splat build + radix sort + copy to the instance stream),\n"
                "SplatBuilderDesc::threads = 1 (default) and = %u (this machine's hardware threads):\n",
                hw);
    std::printf("%10s %12s %12s %12s %12s | %8s %8s %8s\n", "voxels", "ms/frame", "ns/voxel", "ms/frame", "ns/voxel", "build", "sort", "other");
    std::printf("%10s %25s %25s | %26s\n", "", "1 thread", (std::to_string(hw) + " threads").c_str(), "1 thread, ns/voxel (median)");
    csvPrintf(csv, "\nvoxels,threads,ms_per_frame,ns_per_voxel,build_ns,sort_ns,other_ns\n");
    splatfx::Materials materials{splatfx::Footprint{}};
    const auto set = materials.addTextureSet(splatfx::TextureSet::turbulence({}));
    const auto lut = materials.addColorTable(splatfx::ColorTable::fire());
    for (int n : {100, 1000, 10000, 100000, 1000000}) {
        const int side = std::max(1, int(std::round(std::cbrt(double(n)))));
        splatfx::Grid base = *splatfx::Grid::box({side, side, side}, glm::vec3(10.0f / side));
        splatfx::Grid grid = base;
        std::vector<splatfx::Splat> stream(grid.voxels.size());
        const splatfx::Camera cam = splatfx::Camera::lookAt({3, 8, 30}, {0, 5, 0}, {0, 1, 0}, 0.8f, {640, 480});
        const int frames = n >= 1000000 ? 5 : n >= 100000 ? 15 : 50;
        std::printf("%10zu", grid.voxels.size());
        // Three rounds alternating the thread counts; each round's median
        // frame, and the best round kept: other load on a shared machine only
        // ever adds time, and alternating spreads it over both settings.
        const unsigned counts[2] = {1u, hw};
        double best[2] = {1e30, 1e30};
        std::vector<double> phases[3]; // single thread: build, sort, cycling + copy, seconds per frame
        for (int round = 0; round < 3; ++round)
            for (int k = 0; k < 2; ++k) {
                splatfx::SplatBuilder builder({.threads = counts[k]}); // defaults: culling on (the grid is in view)
                const double sec = medianFrame(2, frames, [&](int i) {
                    const auto t0 = Clock::now();
                    cycle(base, grid, i / 60.0);
                    const auto t1 = Clock::now();
                    builder.begin(cam);
                    builder.add(grid, materials, {.textureSet = set, .colorTable = lut, .crossfade = true, .variation = variation});
                    const auto t2 = Clock::now();
                    builder.sort();
                    const auto t3 = Clock::now();
                    std::memcpy(stream.data(), builder.splats().data(), builder.splats().size() * sizeof(splatfx::Splat));
                    if (k == 0) {
                        phases[0].push_back(seconds(t1, t2));
                        phases[1].push_back(seconds(t2, t3));
                        phases[2].push_back(seconds(t0, t1) + seconds(t3, Clock::now()));
                    }
                });
                best[k] = std::min(best[k], sec);
            }
        double split[3];
        for (int p = 0; p < 3; ++p) {
            std::sort(phases[p].begin(), phases[p].end());
            split[p] = 1e9 * phases[p][phases[p].size() / 2] / double(grid.voxels.size());
        }
        for (int k = 0; k < 2; ++k) {
            const double ns = 1e9 * best[k] / double(grid.voxels.size());
            std::printf(" %12.3f %12.1f", 1e3 * best[k], ns);
            csvPrintf(csv, "%zu,%u,%.4f,%.2f,%.2f,%.2f,%.2f\n", grid.voxels.size(), counts[k], 1e3 * best[k], ns, split[0], split[1], split[2]);
        }
        std::printf(" | %8.1f %8.1f %8.1f\n", split[0], split[1], split[2]);
    }
}

} // namespace

int runTable1(int argc, char** argv) {
    Settings settings;
    int& frames = settings.frames;
    std::string csvPath; // no CSV unless --csv names one
    bool quick = false;
    CLI::App app{"What a fragment costs on this GL, then the paper's Table I rows on this machine (headless), with pixels covered,\n"
                 "overdraw, the splat pass as a fraction of this GL's fill rate and of its rate for squares of the splats' size, a naive\n"
                 "baseline, and CPU scaling. Renderer options default to the SDK's.",
                 "splatfx-bench table1"};
    CLI::Option* framesOption = cli::addNumber(app, "--frames", frames, 3, 100000, "timed frames per row");
    app.add_option("--csv", csvPath, "also write the figures as CSV to FILE (nothing is written without it)")->type_name("FILE");
    app.add_flag("--quick", quick, "5 frames per row (unless --frames is given)");
    // A fraction of the footprint's peak below which fragments are discarded.
    cli::addNumber(app, "--footprint-cut", settings.renderer.footprintCut, 0.0f, 1.0f,
                   "fragments below this fraction of the footprint's peak are discarded");
    cli::addChecked(
        app, "--sampling",
        [&settings](const std::string&, const std::string& v) -> splatfx::Status {
            using splatfx::gl::TextureSampling;
            if (v == "auto") settings.renderer.sampling = TextureSampling::Auto;
            else if (v == "bilinear") settings.renderer.sampling = TextureSampling::Bilinear;
            else if (v == "nearest") settings.renderer.sampling = TextureSampling::Nearest;
            else if (v.rfind("upsampled", 0) == 0) {
                settings.renderer.sampling = TextureSampling::Upsampled;
                settings.renderer.upsample = 0; // "upsampled": the renderer's default factor; "upsampled4" -> 4
                if (v.size() > 9) return cli::parseInt("--sampling upsampledN", v.substr(9), 2, 16, settings.renderer.upsample);
            } else {
                return splatfx::makeError("--sampling takes auto, bilinear, nearest, upsampled or upsampledN");
            }
            return {};
        },
        "texture sampling: auto, bilinear, nearest, upsampled or upsampledN (N in [2, 16])", "MODE");
    app.add_flag("--crossfade", settings.crossfade, "blend towards the next texture by the voxel's phase");
    app.add_flag_callback("--paper-lattice", [&] { settings.variation = {}; },
                          "splats on the voxel lattice as in the paper (no SplatVariation; default: the presets' recommended one)");
    CLI::Option* squares = app.add_flag_callback(
        "--squares", [&settings] { settings.renderer.trimCorners = false; }, "draw square splats");
    app.add_flag_callback(
           "--octagons", [&settings] { settings.renderer.trimCorners = true; }, "draw octagons (trimmed corners)")
        ->excludes(squares);
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    if (quick && framesOption->count() == 0) frames = 5;
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) {
        std::fprintf(stderr, "table1: %s\n", ctx.error().c_str());
        return 1;
    }
    std::FILE* csv = csvPath.empty() ? nullptr : std::fopen(csvPath.c_str(), "w");
    if (!csvPath.empty() && !csv) {
        std::fprintf(stderr, "table1: cannot write '%s'\n", csvPath.c_str());
        return 1;
    }
    fragmentCosts(csv);
    std::printf("Table I on %s (median of %d frames per row; paper columns in Hz)\n\n", ctx->renderer().c_str(), frames);
    std::printf("%-9s %6s | %6s %6s %7s %6s | %9s %9s %13s | %8s %8s %8s %6s | %6s %8s | %8s %8s %6s\n", "window", "voxels", "O2", "Indy", "Octane",
                "Onyx2", "splatfx", "vs Onyx2", "reduced res", "covered", "overdraw", "Mfrag/s", "fill", "side", "vs sized", "naive Hz", "Mfrag/s",
                "ratio");
    csvPrintf(csv, "window,voxels,o2_hz,indy_hz,octane_hz,onyx2_hz,splatfx_hz,pixels_covered,overdraw,splat_mfrag_s,fill_mfrag_s,"
                   "fill_fraction,mean_splat_side_px,sized_fill_mfrag_s,fraction_of_sized_fill,naive_hz,naive_mfrag_s,speedup_vs_naive,reduced_scale,"
                   "reduced_hz\n");
    for (const Row& row : kRows) {
        const RowResult r = measureRow(row, settings);
        char win[16];
        std::snprintf(win, sizeof win, "%dx%d", row.window.x, row.window.y);
        char reduced[32] = "-";
        if (r.scale > 1) std::snprintf(reduced, sizeof reduced, "%.1f Hz @1/%d", r.scaledHz, r.scale);
        std::printf("%-9s %6d | %6.0f %6.3g %7.0f %6.0f | %9.1f %8.2fx %13s | %8.0f %8.1f %8.0f %5.0f%% | %6.1f %7.0f%% | %8.1f %8.0f %5.2fx\n", win,
                    row.voxels, row.o2, row.indy, row.octane, row.onyx2, r.hz, r.hz / row.onyx2, reduced, r.covered, r.overdraw,
                    r.splatFragsPerSec / 1e6, 100 * r.fillFraction, r.side, 100 * r.splatFragsPerSec / r.sizedRate, r.naiveHz,
                    r.naiveFragsPerSec / 1e6, r.hz / r.naiveHz);
        csvPrintf(csv, "%s,%d,%g,%g,%g,%g,%.2f,%.0f,%.2f,%.1f,%.1f,%.3f,%.1f,%.1f,%.3f,%.2f,%.1f,%.3f,%d,%.2f\n", win, row.voxels, row.o2, row.indy,
                  row.octane, row.onyx2, r.hz, r.covered, r.overdraw, r.splatFragsPerSec / 1e6, r.fillRate / 1e6, r.fillFraction, r.side,
                  r.sizedRate / 1e6, r.splatFragsPerSec / r.sizedRate, r.naiveHz, r.naiveFragsPerSec / 1e6, r.hz / r.naiveHz, r.scale, r.scaledHz);
        std::fflush(stdout);
    }
    std::printf("\nfill = splat-pass fragments/s as a fraction of full-screen quads doing the same per-fragment work\n"
                "side = the splats' mean size in pixels (sqrt of fragments per splat); vs sized = splat-pass fragments/s as a\n"
                "  fraction of screen-aligned squares of that size doing the same work (the rasterizer's limit at that size)\n"
                "ratio = splatfx full frame (dynamics, sort, upload, draw) vs the naive baseline's frame (no sort, no footprint math)\n");
    cpuScaling(csv, settings.variation);
    if (csv) {
        const bool ok = std::ferror(csv) == 0;
        if (std::fclose(csv) != 0 || !ok) {
            std::fprintf(stderr, "table1: writing '%s' failed\n", csvPath.c_str());
            return 1;
        }
        std::printf("\nCSV: %s\n", csvPath.c_str());
    }
    return 0;
}
} // namespace table1_cmd

int runTable1(int argc, char** argv) { return table1_cmd::runTable1(argc, argv); }
