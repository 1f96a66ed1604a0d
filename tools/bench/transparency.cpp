// splatfx-bench transparency: the order-exact transparency path (issue 15,
// items 2 and 4): glass panes among a 1560-voxel fire at 640x480. Frame cost
// of the fragment lists against the opaque-only frame and the ordered blend,
// error of each against the exact reference (ReferenceSurface panes, splats
// cut into exact sections), the fragment budget knob, list memory.
// --images DIR also writes the fire with one pane in front of it, through it
// and behind it, GL (fragment lists) above the exact reference, as one PNG.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include <glm/gtc/type_ptr.hpp>

#include "bench_gl.hpp"
#include "options.hpp"
#include "splatfx/splatfx.hpp"
#include "splatfx/context.hpp"
#include "splatfx/transparency.hpp"

namespace transparency_cmd { // one namespace per command: the commands build as one unity translation unit

namespace {

using Clock = std::chrono::steady_clock;

const glm::vec4 kBackground{0.05f, 0.05f, 0.08f, 1.0f};

// The Table I fire (table1.cpp): 12x26x5 voxels over 3.5 x 10 x 2.5 units.
splatfx::Grid fire1560() {
    const glm::ivec3 d{12, 26, 5};
    splatfx::Grid g = *splatfx::Grid::box(d, glm::vec3(3.5f / d.x, 10.0f / d.y, 2.5f / d.z));
    std::uint32_t h = 7;
    for (splatfx::Voxel& v : g.voxels) {
        const float t = float(v.cell.y) / float(d.y - 1);
        v.opacity = 0.5f * (1.0f - 0.6f * t);
        h = h * 1664525u + 1013904223u;
        v.texture = h >> 8;
    }
    return g;
}

struct Pane {
    float z;
    glm::vec4 premultiplied;
};

// The host's glass: the integration snippet's shader (emitting into the
// lists) and a plain blending one (the ordered path).
class Glass {
public:
    bool init(std::string& error) {
        const char* vs = "#version 450 core\nlayout(location = 0) in vec3 aPosition;\nuniform mat4 uViewProj;\n"
                         "void main() { gl_Position = uViewProj * vec4(aPosition, 1.0); }\n";
        const std::string emit = "#version 450 core\n" + splatfx::transparentGlsl() +
                                 "uniform vec4 uPremultiplied;\nout vec4 oColor;\n"
                                 "void main() { oColor = splatfx_emitTransparent(uPremultiplied, gl_FragCoord.z); }\n";
        const char* blend = "#version 450 core\nuniform vec4 uPremultiplied;\nout vec4 oColor;\nvoid main() { oColor = uPremultiplied; }\n";
        auto a = splatfx::gl::linkProgram({vs}, {emit.c_str()}, "bench glass (lists)");
        auto b = splatfx::gl::linkProgram({vs}, {blend}, "bench glass (blend)");
        if (!a || !b) {
            error = !a ? a.error() : b.error();
            return false;
        }
        mProgram[0] = *a, mProgram[1] = *b;
        glCreateVertexArrays(1, &mVao);
        glCreateBuffers(1, &mVbo);
        glNamedBufferStorage(mVbo, 18 * sizeof(float), nullptr, GL_DYNAMIC_STORAGE_BIT);
        glVertexArrayVertexBuffer(mVao, 0, mVbo, 0, 3 * sizeof(float));
        glVertexArrayAttribFormat(mVao, 0, 3, GL_FLOAT, GL_FALSE, 0);
        glVertexArrayAttribBinding(mVao, 0, 0);
        glEnableVertexArrayAttrib(mVao, 0);
        return true;
    }
    // lists: emit into the fragment lists; otherwise blend "over" (depth test on, no writes).
    void draw(const std::vector<Pane>& panes, const splatfx::Camera& cam, bool lists) const {
        const GLuint p = mProgram[lists ? 0 : 1];
        glUseProgram(p);
        const glm::mat4 vp = cam.proj * cam.view;
        glUniformMatrix4fv(glGetUniformLocation(p, "uViewProj"), 1, GL_FALSE, glm::value_ptr(vp));
        if (!lists) {
            glEnable(GL_BLEND);
            glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
            glEnable(GL_DEPTH_TEST);
            glDepthMask(GL_FALSE);
        }
        glBindVertexArray(mVao);
        for (const Pane& pane : panes) {
            const float v[18] = {-kHalf, -1, pane.z, kHalf, -1, pane.z, kHalf, 11, pane.z, -kHalf, -1, pane.z, kHalf, 11, pane.z, -kHalf, 11, pane.z};
            glNamedBufferSubData(mVbo, 0, sizeof(v), v);
            glUniform4fv(glGetUniformLocation(p, "uPremultiplied"), 1, glm::value_ptr(pane.premultiplied));
            glDrawArrays(GL_TRIANGLES, 0, 6);
        }
    }
    static splatfx::ReferenceSurface reference(const Pane& p) {
        return splatfx::ReferenceSurface::quad({-kHalf, -1, p.z}, {kHalf, -1, p.z}, {kHalf, 11, p.z}, {-kHalf, 11, p.z}, glm::dvec4(p.premultiplied));
    }
    static constexpr float kHalf = 7.0f; // panes cover the view: x in [-7, 7], y in [-1, 11]

private:
    GLuint mProgram[2] = {0, 0}, mVao = 0, mVbo = 0;
};

struct Error {
    double rmse = 0.0, max = 0.0;
};
Error compare(const splatfx::Image& a, const splatfx::Image& b) {
    double sum = 0.0, worst = 0.0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.pixels.size(); i += 4)
        for (int c = 0; c < 3; ++c) {
            const double d = double(a.pixels[i + c]) - double(b.pixels[i + c]);
            sum += d * d, worst = std::max(worst, std::abs(d)), ++n;
        }
    return {std::sqrt(sum / double(std::max<std::size_t>(n, 1))), worst};
}

} // namespace

int runTransparency(int argc, char** argv) {
    glm::ivec2 size{640, 480};
    int frames = 15, rounds = 3;
    bool cut = true;       // RendererDesc::depthCut: sections weighted by the partial integral
    std::string imagesDir; // --images: the GL-vs-reference still
    std::string only;      // --only TEXT: the opaque-only frame and the configurations whose name contains TEXT
    bool quick = false, noCut = false;
    CLI::App app{"Glass panes among the 1560-voxel Table I fire: opaque-only frame, ordered blend and fragment lists, time and error\n"
                 "against the exact reference; the fragment budget knob; list memory.",
                 "splatfx-bench transparency"};
    CLI::Option* sizeOption = cli::addInts(app, "--size", &size.x, 2, 16, 8192, "frame size", "W H");
    CLI::Option* framesOption = cli::addNumber(app, "--frames", frames, 3, 100000, "timed frames per configuration");
    CLI::Option* roundsOption = cli::addNumber(app, "--rounds", rounds, 1, 1000, "rounds over the configurations");
    app.add_flag("--quick", quick, "5 frames x 1 round at 320x240 (unless given)");
    app.add_flag("--no-cut", noCut, "sections without the partial integral (RendererDesc::depthCut = false)");
    app.add_option("--only", only, "the opaque-only frame and the configurations whose name contains TEXT")->type_name("TEXT");
    app.add_option("--images", imagesDir,
                   "write DIR/transparency_gl_vs_reference.png: panes in front of, through and behind the fire, GL above the reference")
        ->type_name("DIR");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    cut = !noCut;
    if (quick) {
        if (framesOption->count() == 0) frames = 5;
        if (roundsOption->count() == 0) rounds = 1;
        if (sizeOption->count() == 0) size = {320, 240};
    }
    if (size.x < 16 || size.y < 16 || size.x > 4096 || size.y > 4096) {
        std::fprintf(stderr, "transparency: --size must be between 16 and 4096 on each side\n");
        return 2;
    }
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) {
        std::fprintf(stderr, "transparency: %s\n", ctx.error().c_str());
        return 1;
    }
    splatfx::Materials materials{splatfx::Footprint{}};
    const std::uint32_t set = materials.addTextureSet(splatfx::TextureSet::turbulence({.count = 8, .size = 32, .seed = 3}));
    const std::uint32_t table = materials.addColorTable(splatfx::ColorTable::fire());
    const splatfx::Camera cam = splatfx::Camera::lookAt({0, 5.0f, 14.0f}, {0, 5.0f, 0}, {0, 1, 0}, glm::radians(45.0f), size, 0.1f, 100.0f);
    splatfx::Frame frame;
    frame.begin(0.0, cam);
    frame.builder().add(fire1560(), materials, {.textureSet = set, .colorTable = table});
    frame.end();
    std::string err;
    Glass glass;
    if (!glass.init(err)) {
        std::fprintf(stderr, "transparency: %s\n", err.c_str());
        return 1;
    }
    auto fb = splatfx::gl::Framebuffer::create({.width = size.x, .height = size.y});
    if (!fb) {
        std::fprintf(stderr, "transparency: %s\n", fb.error().c_str());
        return 1;
    }
    const glm::vec4 glassTint{0.03f, 0.06f, 0.08f, 0.25f};
    // The fire spans z in [-1.25, 1.25].
    const std::vector<Pane> front{{2.5f, glassTint}};
    const std::vector<Pane> middle{{0.0f, glassTint}};
    const std::vector<Pane> behind{{-2.5f, glassTint}};
    const std::vector<Pane> three{{2.5f, glassTint}, {0.0f, {0.08f, 0.03f, 0.02f, 0.2f}}, {-0.6f, {0.02f, 0.07f, 0.03f, 0.2f}}};

    struct Config {
        std::string name;
        const std::vector<Pane>* panes; // null: opaque only
        bool lists;
        int budget;
        double ms = 1e30;
        Error error{};
        splatfx::gl::FrameRenderStats stats{};
    };
    std::vector<Config> configs{{"opaque only", nullptr, false, 8},
                                {"pane in front, ordered blend", &front, false, 8},
                                {"pane in front, fragment lists", &front, true, 8},
                                {"pane through the middle, ordered blend", &middle, false, 8},
                                {"pane through the middle, fragment lists", &middle, true, 8},
                                {"pane behind, fragment lists", &behind, true, 8}};
    for (int b : {1, 2, 4, 8, 16}) configs.push_back({"3 panes, fragment lists, budget " + std::to_string(b), &three, true, b});
    configs.push_back({"3 panes, ordered blend", &three, false, 8});
    if (!only.empty())
        configs.erase(std::remove_if(configs.begin() + 1, configs.end(), [&](const Config& c) { return c.name.find(only) == std::string::npos; }),
                      configs.end());

    std::vector<splatfx::gl::FrameRenderer> renderers;
    for (const Config& c : configs) {
        splatfx::gl::FrameRendererDesc rd{.fragmentsPerPixel = c.budget};
        rd.splats.depthCut = cut;
        auto fr = splatfx::gl::FrameRenderer::create(rd);
        if (!fr || !fr->upload(materials)) {
            std::fprintf(stderr, "transparency: %s\n", fr ? "upload failed" : fr.error().c_str());
            return 1;
        }
        renderers.push_back(std::move(*fr));
    }
    auto renderOnce = [&](std::size_t i) {
        const Config& c = configs[i];
        splatfx::gl::HostTarget target = bench::clearedTarget(*fb, kBackground);
        if (c.panes) {
            target.drawTransparent = [&] { glass.draw(*c.panes, cam, c.lists); };
            target.transparentToLists = c.lists;
        }
        renderers[i].render(frame, target);
        glFinish();
    };
    // Interleaved rounds; each configuration's time the least of its per-round medians (the machine is shared).
    for (int round = 0; round < rounds; ++round)
        for (std::size_t i = 0; i < configs.size(); ++i) {
            std::vector<double> ms;
            for (int f = 0; f < frames + 1; ++f) {
                const auto a = Clock::now();
                renderOnce(i);
                if (f > 0) ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - a).count());
            }
            std::sort(ms.begin(), ms.end());
            configs[i].ms = std::min(configs[i].ms, ms[ms.size() / 2]);
            std::printf("  round %d  %-44s %9.2f ms\n", round + 1, configs[i].name.c_str(), ms[ms.size() / 2]);
            std::fflush(stdout);
        }
    // Errors against the exact reference on the same input.
    std::printf("transparency on %s: 1560-voxel fire (%zu splats) at %dx%d, least of %d rounds' medians of %d frames (glFinish)\n",
                ctx->renderer().c_str(), frame.splats().size(), size.x, size.y, rounds, frames);
    std::printf("computing the exact references (seconds each) ...\n");
    std::fflush(stdout);
    auto reference = [&](const std::vector<Pane>* panes) {
        std::vector<splatfx::ReferenceSurface> surfaces;
        if (panes)
            for (const Pane& p : *panes) surfaces.push_back(Glass::reference(p));
        return *splatfx::renderSplatExact(frame.splats(), cam, materials, {.host = {.background = kBackground}, .surfaces = surfaces});
    };
    const splatfx::Image refOpaque = reference(nullptr), refFront = reference(&front), refMiddle = reference(&middle), refBehind = reference(&behind),
                         refThree = reference(&three);
    std::vector<const splatfx::Image*> mosaicRefs;
    std::vector<splatfx::Image> mosaicGl;
    for (std::size_t i = 0; i < configs.size(); ++i) {
        renderOnce(i);
        const Config& c = configs[i];
        const splatfx::Image& ref = !c.panes             ? refOpaque
                                    : c.panes == &front  ? refFront
                                    : c.panes == &middle ? refMiddle
                                    : c.panes == &behind ? refBehind
                                                         : refThree;
        const splatfx::Image img = fb->read();
        configs[i].error = compare(img, ref);
        configs[i].stats = renderers[i].stats();
        if (c.lists && (c.panes == &front || c.panes == &middle || c.panes == &behind)) mosaicGl.push_back(img), mosaicRefs.push_back(&ref);
    }
    if (!imagesDir.empty()) {
        // Columns: pane in front, through, behind; rows: GL (fragment lists), exact reference.
        splatfx::Image m;
        m.width = size.x * int(mosaicGl.size()), m.height = size.y * 2, m.channels = 4;
        m.pixels.assign(std::size_t(m.width) * m.height * 4, 1.0f);
        for (std::size_t k = 0; k < mosaicGl.size(); ++k)
            for (int row = 0; row < 2; ++row) {
                const splatfx::Image& src = row == 0 ? mosaicGl[k] : *mosaicRefs[k];
                // Framebuffer::read and the reference are both top row first, like the PNG.
                for (int y = 0; y < size.y; ++y)
                    for (int x = 0; x < size.x; ++x)
                        for (int ch = 0; ch < 4; ++ch) m.at(int(k) * size.x + x, row * size.y + y, ch) = src.at(x, y, ch);
            }
        const std::string path = imagesDir + "/transparency_gl_vs_reference.png";
        if (auto s = splatfx::writeImage(path, m); !s) {
            std::fprintf(stderr, "transparency: %s\n", s.error().c_str());
            return 1;
        }
        std::printf("wrote %s (columns: pane in front, through, behind the fire; rows: GL fragment lists, exact reference)\n", path.c_str());
    }
    const double opaqueMs = configs[0].ms;
    std::printf("\n%-44s %9s %9s %9s %8s %10s %10s %12s %9s\n", "configuration", "ms/frame", "vs opaque", "RMSE", "max", "fallback", "merged px",
                "list MB", "B/pixel");
    for (const Config& c : configs) {
        const double mb = double(c.stats.lists.bytes) / 1e6;
        std::printf("%-44s %9.2f %9.2f %9.4f %8.3f %10llu %10llu %12.2f %9.1f\n", c.name.c_str(), c.ms, c.ms / opaqueMs, c.error.rmse, c.error.max,
                    (unsigned long long)c.stats.lists.fallback, (unsigned long long)c.stats.lists.overflowPixels, c.lists ? mb : 0.0,
                    c.lists ? double(c.stats.lists.bytes) / double(size.x * size.y) : 0.0);
    }
    std::printf("\nHow the splats of the list frames were drawn (FrameRenderStats): behind every surface they cover / in front of\n"
                "every one (both: the ordinary splat pass) / cut into sections / of those, by the general (eye-plane) variant\n");
    for (const Config& c : configs)
        if (c.lists)
            std::printf("%-44s %6llu %6llu %6llu %6llu\n", c.name.c_str(), (unsigned long long)c.stats.lists.splatsBehind,
                        (unsigned long long)c.stats.lists.splatsFront, (unsigned long long)c.stats.lists.splatsSectioned,
                        (unsigned long long)c.stats.lists.general);
    std::printf("\nRMSE / max: linear RGB of the RGBA8 frame against renderSplatExact with the same panes (ReferenceSurface),\n"
                "each splat cut into exact sections at the panes; 1/255 = 0.0039.\n"
                "Targets (issue 15): one pane in front, lists <= 2x the opaque-only frame, error within the opaque-only error.\n");
    return 0;
}
} // namespace transparency_cmd

int runTransparency(int argc, char** argv) { return transparency_cmd::runTransparency(argc, argv); }
