// splatfx-viewer: interactive viewer for scene files (GLFW + Dear ImGui).
//
//   splatfx-viewer samples/03-cow-through-fire/scene.json
//   xvfb-run -s "-screen 0 1280x720x24" splatfx-viewer SCENE --auto-quit-after 30 --screenshot shot.png
//
// Cameras: the scene's path, orbit (left drag rotates, right drag pans, wheel
// zooms) and fly (WASD, Q/E down/up, right drag looks; "inside effect" puts
// the eye in an effect's centre). Each scale of dynamics can be switched off
// per scene (Effect::setToggles), effects enabled one by one, parameters
// tweaked live (opacity, time rate, field of view, the scene text itself),
// and the overlay shows frame time and counts from Scene::counters().
//
// [SECTION] Command line
// [SECTION] Viewer state and cameras
// [SECTION] UI
// [SECTION] Main loop
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <GLFW/glfw3.h>
#include <glm/gtc/matrix_transform.hpp>

#include "options.hpp"
#include "backends/imgui_impl_glfw.h"
#include "backends/imgui_impl_opengl3.h"
#include "imgui.h"

#include "scene_player.hpp"
#include "splatfx/context.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/image_io.hpp"

namespace fs = std::filesystem;

namespace {

// [SECTION] Command line

struct Args {
    std::string scene;
    glm::ivec2 size{1280, 720};
    int autoQuitAfter = 0;  // > 0: quit after this many frames (fixed time step)
    std::string screenshot; // written after the last frame (with --auto-quit-after)
    std::optional<std::uint32_t> seed;
    std::string camera = "path";
    bool hideUi = false;
    bool intoWindow = false; // draw into the window's default framebuffer (its depth copied by splatfx) instead of an own one
    // An engine's frame, as splatfx-render's flags of the same names (docs/integration.md, "What your engine does").
    splatfx::DepthConvention depth{}; // --reverse-z, --clip-01, --infinite-far
    int msaa = 0;                     // --msaa N: the viewer's own target multisampled, resolved before the window
    bool srgb = false;                // --srgb: the viewer's own target sRGB, GL_FRAMEBUFFER_SRGB on while splatfx draws
    bool hdr = false;        // an RGBA16F target of its own and HDR lit colours (shown clamped at 1 in the 8-bit window)
};

// Returns -1 to go on, else the exit code (0 after --help, 2 after a bad command line).
int parse(int argc, char** argv, Args& a) {
    CLI::App app{"splatfx-viewer: interactive splatfx scene viewer", "splatfx-viewer"};
    app.add_option("scene", a.scene, "the scene file (default: none; open one from the UI)")->type_name("SCENE.json");
    cli::addSize(app, "--size", a.size.x, a.size.y, 64, 8192, "window size");
    std::uint32_t seed = 0;
    CLI::Option* seedOption = cli::addNumber(app, "--seed", seed, 0u, 4294967295u, "scene seed (default: the file's)");
    seedOption->description("scene seed, in [0, 4294967295] (default: the file's)");
    cli::addOneOf<std::string>(app, "--camera", a.camera, {{"path", "path"}, {"orbit", "orbit"}, {"fly", "fly"}},
                               "--camera expects path, orbit or fly", "path (the scene's camera path, default), orbit or fly");
    cli::addNumber(app, "--auto-quit-after", a.autoQuitAfter, 1, 1000000, "render N frames at the scene's fps (fixed steps), then quit");
    app.add_option("--screenshot", a.screenshot, "write the last frame (with the UI) to FILE (PNG)")->type_name("FILE");
    app.add_flag("--hide-ui", a.hideUi, "no UI panel");
    app.add_flag("--into-window", a.intoWindow,
                 "draw straight into the window's default framebuffer, as many hosts do (splatfx copies its depth once a frame: "
                 "FrameRendererDesc::copyHostDepth); default: into a framebuffer of the viewer's own, copied to the window");
    app.add_flag_callback(
        "--reverse-z", [&a] { a.depth.reversed = true, a.depth.clip = splatfx::ClipDepth::ZeroToOne; },
        "draw as a reverse-Z engine: glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE), near at depth 1, far at 0, 32-bit float depth "
        "(the window's own depth, with --into-window)");
    app.add_flag_callback(
        "--clip-01", [&a] { a.depth.clip = splatfx::ClipDepth::ZeroToOne; }, "clip depth [0, 1] (glClipControl GL_ZERO_TO_ONE) without reversing");
    app.add_flag_callback(
        "--infinite-far", [&a] { a.depth.infiniteFar = true; }, "an infinite far plane (the scene's camera farPlane unused)");
    app.add_option("--msaa", a.msaa, "draw into an N-sample (MSAA) colour and depth target, resolved before it is copied to the window")
        ->check(CLI::IsMember({1, 2, 4, 8, 16}))
        ->type_name("N");
    app.add_flag("--srgb", a.srgb, "draw into an sRGB colour target with GL_FRAMEBUFFER_SRGB on (blending in linear; the window shows the sRGB codes)");
    app.add_flag("--hdr", a.hdr,
                 "draw into an RGBA16F framebuffer of the viewer's own with HDR lit colours (Scene::setHdrLit), as splatfx-render --hdr; "
                 "the 8-bit window shows it clamped at 1 (no tone curve: exposure is the host's)")
        ->excludes("--into-window")
        ->excludes("--srgb");
    if (const int code = cli::parse(app, argc, argv); code >= 0) return code;
    if (seedOption->count()) a.seed = seed;
    // The window's default framebuffer is single-sampled RGBA8: the engine targets are the viewer's own.
    if (a.intoWindow && (a.msaa > 1 || a.srgb)) {
        std::fprintf(stderr, "splatfx-viewer: --msaa and --srgb draw into the viewer's own target; --into-window draws into the window's "
                             "single-sampled RGBA8 default framebuffer: give one or the other\n");
        return 2;
    }
    return -1;
}

// [SECTION] Viewer state and cameras

enum class CameraMode { Path, Orbit, Fly };

// Texture sampling choices offered in the panel: compare quality and cost live.
struct SamplingChoice {
    const char* label;
    splatfx::gl::TextureSampling mode;
    int upsample;
};
constexpr SamplingChoice kSamplings[] = {
    {"auto (SDK default)", splatfx::gl::TextureSampling::Auto, 0}, {"bilinear", splatfx::gl::TextureSampling::Bilinear, 0},
    {"nearest", splatfx::gl::TextureSampling::Nearest, 0},         {"upsampled 2x", splatfx::gl::TextureSampling::Upsampled, 2},
    {"upsampled 4x", splatfx::gl::TextureSampling::Upsampled, 4},
};

struct Viewer {
    Args args;
    std::optional<scenehost::ScenePlayer> player;
    std::optional<splatfx::gl::Framebuffer> target;   // what the frame is drawn into, then copied to the window
    std::optional<splatfx::gl::Framebuffer> resolved; // --msaa: the target's samples averaged, as Framebuffer::read does
    std::string path;
    std::string error;
    std::vector<std::string> catalogue; // scene files next to the current one
    std::string editorText;
    double time = 0.0;
    bool paused = false;
    float timeRate = 1.0f;
    CameraMode mode = CameraMode::Path;
    splatfx::DynamicsToggles toggles;
    scenehost::FrameOptions frame;
    int sampling = 0;        // index into kSamplings
    int resolutionScale = 1; // 1, 2 or 4
    float fovDeg = 45.0f;
    // Orbit
    glm::vec3 orbitTarget{0, 1, 0};
    float orbitYaw = 0.0f, orbitPitch = 0.2f, orbitDistance = 10.0f;
    // Fly
    glm::vec3 flyPos{0, 2, 10};
    float flyYaw = -1.5708f, flyPitch = 0.0f;
    double frameMs = 0.0;
    char pathInput[1024] = {};

    splatfx::gl::FrameRendererDesc rendererDesc() const {
        return {.splats = {.sampling = kSamplings[sampling].mode, .upsample = kSamplings[sampling].upsample},
                .resolutionScale = resolutionScale,
                .reduceTetrahedra = true};
    }

    void load(const std::string& p, const std::string* text = nullptr) {
        const scenehost::PlayerOptions options{.seed = args.seed, .renderer = rendererDesc()};
        auto r = text ? scenehost::ScenePlayer::fromText(*text, p, options) : scenehost::ScenePlayer::load(p, options);
        if (!r) {
            error = r.error();
            std::fprintf(stderr, "splatfx-viewer: %s\n", error.c_str());
            return;
        }
        error.clear();
        player.emplace(std::move(*r));
        player->file().scene.setHdrLit(args.hdr);
        path = p;
        std::snprintf(pathInput, sizeof pathInput, "%s", p.c_str());
        time = 0.0;
        if (!text) {
            std::ifstream in(p);
            std::stringstream ss;
            ss << in.rdbuf();
            editorText = ss.str();
        }
        applyToggles();
        // Start orbit and fly cameras where the scene's camera is.
        const splatfx::CameraKey k = player->file().camera.keys.front();
        fovDeg = glm::degrees(k.fovYRad);
        orbitTarget = k.target;
        const glm::vec3 d = k.position - k.target;
        orbitDistance = std::max(glm::length(d), 0.1f);
        orbitYaw = std::atan2(d.x, d.z);
        orbitPitch = std::asin(std::clamp(d.y / orbitDistance, -1.0f, 1.0f));
        flyPos = k.position;
        const glm::vec3 f = glm::normalize(k.target - k.position);
        flyYaw = std::atan2(f.z, f.x);
        flyPitch = std::asin(std::clamp(f.y, -1.0f, 1.0f));
        catalogue.clear();
        std::error_code ec;
        const fs::path samples = fs::path(p).parent_path().parent_path();
        for (const auto& e : fs::directory_iterator(samples.empty() ? "." : samples, ec))
            if (fs::is_regular_file(e.path() / "scene.json", ec)) catalogue.push_back((e.path() / "scene.json").string());
        std::sort(catalogue.begin(), catalogue.end());
    }

    void applyToggles() {
        if (!player) return;
        for (const auto& info : player->file().effects) player->file().scene.effect(info.id).setToggles(toggles);
    }

    splatfx::Camera camera(glm::ivec2 vp) const {
        const float fov = glm::radians(fovDeg);
        const splatfx::CameraPath& cp = player->file().camera;
        if (mode == CameraMode::Orbit) {
            const glm::vec3 eye = orbitTarget + orbitDistance * glm::vec3(std::cos(orbitPitch) * std::sin(orbitYaw), std::sin(orbitPitch),
                                                                          std::cos(orbitPitch) * std::cos(orbitYaw));
            return splatfx::Camera::lookAt(eye, orbitTarget, {0, 1, 0}, fov, vp, cp.nearPlane, cp.farPlane, args.depth);
        }
        if (mode == CameraMode::Fly) {
            const glm::vec3 f(std::cos(flyPitch) * std::cos(flyYaw), std::sin(flyPitch), std::cos(flyPitch) * std::sin(flyYaw));
            return splatfx::Camera::lookAt(flyPos, flyPos + f, {0, 1, 0}, fov, vp, cp.nearPlane, cp.farPlane, args.depth);
        }
        splatfx::Camera c = player->cameraAt(time, vp, args.depth);
        return c;
    }

    void handleInput(GLFWwindow* w, float dt) {
        ImGuiIO& io = ImGui::GetIO();
        if (io.WantCaptureMouse && io.WantCaptureKeyboard) return;
        const ImVec2 md = io.MouseDelta;
        if (!io.WantCaptureMouse) {
            if (mode == CameraMode::Orbit) {
                if (ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
                    orbitYaw -= 0.005f * md.x;
                    orbitPitch = std::clamp(orbitPitch + 0.005f * md.y, -1.5f, 1.5f);
                }
                if (ImGui::IsMouseDown(ImGuiMouseButton_Right)) {
                    const splatfx::Camera c = camera({1, 1});
                    orbitTarget += orbitDistance * 0.002f * (-md.x * c.right() + md.y * c.up());
                }
                if (io.MouseWheel != 0.0f) orbitDistance = std::clamp(orbitDistance * std::pow(0.9f, io.MouseWheel), 0.05f, 1000.0f);
            } else if (mode == CameraMode::Fly && ImGui::IsMouseDown(ImGuiMouseButton_Right)) {
                flyYaw += 0.004f * md.x;
                flyPitch = std::clamp(flyPitch - 0.004f * md.y, -1.55f, 1.55f);
            }
        }
        if (mode == CameraMode::Fly && !io.WantCaptureKeyboard) {
            const glm::vec3 f(std::cos(flyPitch) * std::cos(flyYaw), std::sin(flyPitch), std::cos(flyPitch) * std::sin(flyYaw));
            const glm::vec3 r = glm::normalize(glm::cross(f, glm::vec3(0, 1, 0)));
            const float speed = (glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ? 8.0f : 2.5f) * dt;
            if (glfwGetKey(w, GLFW_KEY_W) == GLFW_PRESS) flyPos += speed * f;
            if (glfwGetKey(w, GLFW_KEY_S) == GLFW_PRESS) flyPos -= speed * f;
            if (glfwGetKey(w, GLFW_KEY_D) == GLFW_PRESS) flyPos += speed * r;
            if (glfwGetKey(w, GLFW_KEY_A) == GLFW_PRESS) flyPos -= speed * r;
            if (glfwGetKey(w, GLFW_KEY_E) == GLFW_PRESS) flyPos.y += speed;
            if (glfwGetKey(w, GLFW_KEY_Q) == GLFW_PRESS) flyPos.y -= speed;
        }
    }

    // Puts the fly camera at the centre of effect `id`'s current bounds, looking along the path camera's direction.
    void jumpInside(splatfx::EffectId id) {
        const splatfx::Aabb b = player->file().scene.status(id).bounds;
        if (b.empty()) return;
        const splatfx::Camera c = camera({1, 1});
        mode = CameraMode::Fly;
        flyPos = 0.5f * (b.lo + b.hi);
        const glm::vec3 f = c.forward();
        flyYaw = std::atan2(f.z, f.x);
        flyPitch = std::asin(std::clamp(f.y, -1.0f, 1.0f));
    }

    // [SECTION] UI

    void ui() {
        ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
        ImGui::SetNextWindowSize(ImVec2(380, 0), ImGuiCond_FirstUseEver);
        ImGui::Begin("splatfx");
        const scenehost::FrameStats fs = player ? player->stats() : scenehost::FrameStats{};
        const splatfx::FrameCounters& s = fs.counters;
        ImGui::Text("%.2f ms/frame (%.0f fps)   t = %.2f s", frameMs, frameMs > 0 ? 1000.0 / frameMs : 0.0, time);
        ImGui::Text("effects: %zu declared, %zu simulated, %zu visible, %zu drawn", s.declared, s.simulated, s.needed, s.drawn);
        ImGui::Text("voxels: %llu   splats: %llu", (unsigned long long)s.voxels, (unsigned long long)s.splats);
        ImGui::Text("prepare %.2f ms  render %.2f ms", fs.prepareMs, fs.renderMs);
        if (!error.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.3f, 1), "%s", error.c_str());
        // Lighting, shadows or a terrain this frame is drawn without (ScenePlayer::problem).
        if (player && !player->problem().empty()) {
            ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.4f, 0.3f, 1));
            ImGui::TextWrapped("drawn without: %s", player->problem().c_str());
            ImGui::PopStyleColor();
        }
        // What the frame renderer could not do as asked (FrameRenderStats::notes): said where the user looks.
        if (player)
            for (const std::string& note : player->renderer().stats().notes) {
                ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.8f, 0.3f, 1));
                ImGui::TextWrapped("note: %s", note.c_str());
                ImGui::PopStyleColor();
            }
        ImGui::Separator();

        if (ImGui::CollapsingHeader("Scene", ImGuiTreeNodeFlags_DefaultOpen)) {
            if (player && !player->file().title.empty()) ImGui::TextWrapped("%s", player->file().title.c_str());
            if (ImGui::BeginCombo("samples", path.empty() ? "(none)" : fs::path(path).parent_path().filename().string().c_str())) {
                for (const std::string& c : catalogue)
                    if (ImGui::Selectable(fs::path(c).parent_path().filename().string().c_str(), c == path)) load(c);
                ImGui::EndCombo();
            }
            ImGui::InputText("file", pathInput, sizeof pathInput);
            ImGui::SameLine();
            if (ImGui::Button("Load")) load(pathInput);
            if (ImGui::Button(paused ? "Play" : "Pause")) paused = !paused;
            ImGui::SameLine();
            if (ImGui::Button("Restart") && !path.empty()) load(path, &editorText);
            ImGui::SliderFloat("time rate", &timeRate, 0.0f, 4.0f);
        }
        if (ImGui::CollapsingHeader("Camera", ImGuiTreeNodeFlags_DefaultOpen)) {
            int m = int(mode);
            ImGui::RadioButton("path", &m, 0);
            ImGui::SameLine();
            ImGui::RadioButton("orbit", &m, 1);
            ImGui::SameLine();
            ImGui::RadioButton("fly", &m, 2);
            mode = CameraMode(m);
            ImGui::SliderFloat("fov (deg)", &fovDeg, 10.0f, 120.0f);
            ImGui::TextDisabled(mode == CameraMode::Orbit ? "left drag: rotate, right drag: pan, wheel: zoom"
                                : mode == CameraMode::Fly ? "WASD move, Q/E down/up, shift fast, right drag look"
                                                          : "the scene file's camera path");
        }
        if (ImGui::CollapsingHeader("Dynamics and drawing", ImGuiTreeNodeFlags_DefaultOpen)) {
            bool changed = ImGui::Checkbox("object (sec. 3.1)", &toggles.object);
            ImGui::SameLine();
            changed |= ImGui::Checkbox("global (3.2)", &toggles.global);
            ImGui::SameLine();
            changed |= ImGui::Checkbox("local (3.3)", &toggles.local);
            if (changed) applyToggles();
            ImGui::Checkbox("traditional splats (Fig. 1a)", &frame.traditional);
            ImGui::Checkbox("geometry", &frame.drawGeometry);
            ImGui::SliderFloat("opacity scale", &frame.opacityScale, 0.0f, 3.0f);
            if (ImGui::BeginCombo("texture sampling", kSamplings[sampling].label)) {
                for (int i = 0; i < int(std::size(kSamplings)); ++i)
                    if (ImGui::Selectable(kSamplings[i].label, i == sampling) && i != sampling) {
                        sampling = i;
                        if (player)
                            if (auto st = player->setRenderer(rendererDesc()); !st) error = st.error();
                    }
                ImGui::EndCombo();
            }
            static const char* kScales[] = {"full resolution", "1/2 resolution", "1/4 resolution"};
            int scaleIndex = resolutionScale == 4 ? 2 : resolutionScale - 1;
            if (ImGui::Combo("volumes drawn at", &scaleIndex, kScales, 3)) { // splats, clouds, ground fog
                resolutionScale = scaleIndex == 2 ? 4 : scaleIndex + 1;
                if (player)
                    if (auto st = player->setRenderer(rendererDesc()); !st) error = st.error();
            }
            if (player) {
                const splatfx::gl::Renderer& r = player->renderer().splatRenderer();
                if (r.sampling() == splatfx::gl::TextureSampling::Upsampled)
                    ImGui::TextDisabled("in use: layers upsampled %dx, nearest", r.upsampleFactor());
                else ImGui::TextDisabled("in use: %s", r.sampling() == splatfx::gl::TextureSampling::Bilinear ? "bilinear" : "nearest");
            }
        }
        if (player && ImGui::CollapsingHeader("Effects", ImGuiTreeNodeFlags_DefaultOpen)) {
            splatfx::Scene& scene = player->file().scene;
            const auto& perEffect = player->stats().splatsPerEffect;
            // One row per entry of any kind: the Scene switches each off by its id alike.
            auto row = [&](splatfx::EffectId id, const std::string& name, const std::string& kind, unsigned long long count, const char* what) {
                ImGui::PushID(int(id));
                bool on = scene.options(id).enabled;
                if (ImGui::Checkbox("##on", &on)) scene.setEnabled(id, on);
                ImGui::SameLine();
                ImGui::Text("%s (%s)%s %llu %s", name.c_str(), kind.c_str(), scene.status(id).needed ? "" : " [skipped]", count, what);
                ImGui::SameLine();
                if (ImGui::SmallButton("inside")) jumpInside(id);
                ImGui::PopID();
            };
            for (std::size_t i = 0; i < player->file().effects.size(); ++i) {
                const splatfx::SceneEffectInfo& info = player->file().effects[i];
                row(info.id, info.name, info.kind, i < perEffect.size() ? perEffect[i] : 0, "splats");
            }
            for (const splatfx::SceneVolumeInfo& info : player->file().volumes)
                row(info.id, info.name, info.kind, scene.status(info.id).tetrahedraDrawn, "tetrahedra");
        }
        if (ImGui::CollapsingHeader("Scene file (edit, then Apply)")) {
            static std::vector<char> buf;
            if (buf.size() < editorText.size() + 65536) buf.resize(editorText.size() + 65536);
            if (std::strncmp(buf.data(), editorText.c_str(), buf.size()) != 0) std::snprintf(buf.data(), buf.size(), "%s", editorText.c_str());
            if (ImGui::InputTextMultiline("##text", buf.data(), buf.size(), ImVec2(-1, 300))) editorText = buf.data();
            if (ImGui::Button("Apply") && !path.empty()) load(path, &editorText);
        }
        ImGui::End();
    }
};

bool writeScreenshot(const std::string& file, glm::ivec2 size) {
    splatfx::Image img;
    img.width = size.x, img.height = size.y, img.channels = 4;
    std::vector<unsigned char> px(std::size_t(size.x) * size.y * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, size.x, size.y, GL_RGBA, GL_UNSIGNED_BYTE, px.data());
    img.pixels.resize(px.size());
    for (int y = 0; y < size.y; ++y) // GL rows are bottom-up
        for (int x = 0; x < size.x * 4; ++x) img.pixels[std::size_t(y) * size.x * 4 + x] = px[std::size_t(size.y - 1 - y) * size.x * 4 + x] / 255.0f;
    for (std::size_t i = 3; i < img.pixels.size(); i += 4) img.pixels[i] = 1.0f;
    if (auto s = splatfx::writeImage(file, img); !s) {
        std::fprintf(stderr, "splatfx-viewer: %s\n", s.error().c_str());
        return false;
    }
    std::printf("splatfx-viewer: wrote %s\n", file.c_str());
    return true;
}

} // namespace

// [SECTION] Main loop

static int viewerMain(int argc, char** argv) {
    Viewer v;
    if (const int code = parse(argc, argv, v.args); code >= 0) return code;
    v.mode = v.args.camera == "orbit" ? CameraMode::Orbit : v.args.camera == "fly" ? CameraMode::Fly : CameraMode::Path;
    auto window =
        splatfx::Window::create({.width = v.args.size.x, .height = v.args.size.y, .title = "splatfx viewer", .vsync = v.args.autoQuitAfter == 0});
    if (!window) {
        std::fprintf(stderr,
                     "splatfx-viewer: %s\nsplatfx-viewer: the viewer is interactive; without a display run it under xvfb-run, or render "
                     "the scene headless with splatfx-render SCENE --out DIR\n",
                     window.error().c_str());
        return 1;
    }
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr; // no imgui.ini written next to the user's files
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForOpenGL(window->handle(), true);
    ImGui_ImplOpenGL3_Init("#version 450");

    if (!v.args.scene.empty()) {
        const CameraMode keep = v.mode;
        v.load(v.args.scene);
        v.mode = keep;
        if (!v.player && v.args.autoQuitAfter > 0) return 1;
    }
    const float fixedStep = v.player ? 1.0f / v.player->file().output.fps : 1.0f / 24.0f;
    using Clock = std::chrono::steady_clock;
    auto last = Clock::now();
    int rc = 0;
    for (int frameIndex = 0; !window->shouldClose(); ++frameIndex) {
        window->pollEvents();
        const auto now = Clock::now();
        const float wallDt = std::chrono::duration<float>(now - last).count();
        last = now;
        v.frameMs = 1000.0 * wallDt;
        // Auto-quit runs step by the scene's fps so screenshots are reproducible.
        const float dt = v.args.autoQuitAfter > 0 ? fixedStep : std::min(wallDt, 0.1f);
        if (glfwGetKey(window->handle(), GLFW_KEY_ESCAPE) == GLFW_PRESS) break;

        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
        v.handleInput(window->handle(), dt);
        if (!v.args.hideUi) v.ui();
        ImGui::Render();

        const glm::ivec2 fbSize = window->framebufferSize();
        if (v.player && fbSize.x > 0 && fbSize.y > 0) {
            if (!v.paused && frameIndex > 0) v.time += double(dt) * v.timeRate;
            const splatfx::Camera cam = v.camera(fbSize);
            // By default into a framebuffer of our own, as splatfx-render draws
            // (the same RGBA8 colour and depth texture), then copied to the
            // window. --into-window draws into the window's default framebuffer
            // as many hosts do: it has no depth texture, so the frame renderer
            // copies its depth buffer once a frame for the passes that read it
            // (the host fog, the depth cut); viewer_matches_render_window holds
            // that image to the tool's too.
            // The host's clip convention while splatfx and the scene host draw (GL state
            // read by nothing in splatfx but the rasterizer); GL's default again for the UI.
            glClipControl(GL_LOWER_LEFT, v.args.depth.clip == splatfx::ClipDepth::ZeroToOne ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
            if (v.args.intoWindow) {
                // The window's own depth buffer is copied by the frame renderer after the opaque pass.
                if (v.time > splatfx::kMaxTimeSec) v.time = 0.0;
                if (auto st = v.player->renderFrame(v.time, cam, 0, v.frame); !st) v.error = st.error();
                glBindFramebuffer(GL_FRAMEBUFFER, 0);
                glViewport(0, 0, fbSize.x, fbSize.y);
            } else if (!v.target || v.target->width() != fbSize.x || v.target->height() != fbSize.y) {
                v.target.reset();
                v.resolved.reset();
                // The same target splatfx-render draws into for the same flags.
                auto fb = splatfx::gl::Framebuffer::create({.width = fbSize.x,
                                                            .height = fbSize.y,
                                                            .color = v.args.hdr ? splatfx::gl::Precision::F16 : splatfx::gl::Precision::U8,
                                                            .floatDepth = v.args.depth.reversed,
                                                            .samples = v.args.msaa,
                                                            .srgb = v.args.srgb});
                if (!fb) {
                    std::fprintf(stderr, "splatfx-viewer: %s\n", fb.error().c_str());
                    rc = 1;
                    break;
                }
                v.target.emplace(std::move(*fb));
                if (v.args.msaa > 1) {
                    auto single = splatfx::gl::Framebuffer::create(
                        {.width = fbSize.x, .height = fbSize.y, .color = v.args.hdr ? splatfx::gl::Precision::F16 : splatfx::gl::Precision::U8, .srgb = v.args.srgb});
                    if (!single) {
                        std::fprintf(stderr, "splatfx-viewer: %s\n", single.error().c_str());
                        rc = 1;
                        break;
                    }
                    v.resolved.emplace(std::move(*single));
                }
            }
            if (!v.args.intoWindow) {
                // Past kMaxTimeSec (about 72.8 hours of scene time) the scene refuses the time: restart the clock.
                if (v.time > splatfx::kMaxTimeSec) v.time = 0.0;
                if (v.args.srgb) glEnable(GL_FRAMEBUFFER_SRGB);
                if (auto st = v.player->renderFrame(v.time, cam, v.target->handle(), v.frame); !st) v.error = st.error();
                unsigned shown = v.target->handle();
                if (v.resolved) {
                    // Resolved as splatfx-render's Framebuffer::read resolves (GL_FRAMEBUFFER_SRGB as while drawing:
                    // an sRGB target's samples are averaged in linear), then the codes copied as they are.
                    glBlitNamedFramebuffer(shown, v.resolved->handle(), 0, 0, fbSize.x, fbSize.y, 0, 0, fbSize.x, fbSize.y, GL_COLOR_BUFFER_BIT,
                                           GL_NEAREST);
                    shown = v.resolved->handle();
                }
                glDisable(GL_FRAMEBUFFER_SRGB); // the window gets the stored codes, as the tool's PNG
                glBlitNamedFramebuffer(shown, 0, 0, 0, fbSize.x, fbSize.y, 0, 0, fbSize.x, fbSize.y, GL_COLOR_BUFFER_BIT, GL_NEAREST);
                glBindFramebuffer(GL_FRAMEBUFFER, 0);
                glViewport(0, 0, fbSize.x, fbSize.y);
            }
            glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
        } else {
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            glViewport(0, 0, fbSize.x, fbSize.y);
            glClearColor(0.1f, 0.1f, 0.12f, 1.0f);
            glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        }
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        const bool lastFrame = v.args.autoQuitAfter > 0 && frameIndex + 1 >= v.args.autoQuitAfter;
        if (lastFrame && !v.args.screenshot.empty() && !writeScreenshot(v.args.screenshot, fbSize)) rc = 1;
        window->swapBuffers();
        if (lastFrame) {
            const splatfx::FrameCounters s = v.player ? v.player->stats().counters : splatfx::FrameCounters{};
            std::printf("splatfx-viewer: %d frames, t = %.2f s, %zu effects declared / %zu simulated / %zu visible, %llu splats\n", frameIndex + 1,
                        v.time, s.declared, s.simulated, s.needed, (unsigned long long)s.splats);
            break;
        }
    }
    v.player.reset(); // its GL objects go while the window's context is still current
    v.target.reset();
    v.resolved.reset();
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    return rc;
}

// Any exception that escapes (std::bad_alloc included) becomes a message and exit code 1.
int main(int argc, char** argv) {
    return cli::guardedMain("splatfx-viewer", [&] { return viewerMain(argc, argv); });
}
