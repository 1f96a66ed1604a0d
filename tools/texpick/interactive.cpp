// texpick: the interactive mode (OpenCV HighGUI).
//
// One window: the photograph with the patches (left), the set and a large
// cross-fading preview of the cycling textured splat (right), a status line.
// Left click adds a patch centre (positions) or a path vertex (path), right
// click removes the last; keys switch modes and save. Saving calls produce(),
// the command line's own code, so the folder is the same either way.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include <nlohmann/json.hpp>
#include <opencv2/highgui.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "texpick.hpp"

namespace texpick {

using json = nlohmann::json;

namespace {

const char* kWindow = "splatfx-texpick";
const char* kHelp =
    "click: add  right-click: undo  p: positions/path  r: random  f: spectral spread  o: order  +/-: patch  c: clear  s: save  q: quit";

struct Event {
    std::string kind; // click | rclick | key
    cv::Point2d at;
    int key = 0;
};

splatfx::Result<std::vector<Event>> parseEvents(const std::string& text) {
    std::vector<Event> events;
    std::string part;
    std::istringstream in(text);
    while (std::getline(in, part, ';')) {
        if (part.empty()) continue;
        const size_t colon = part.find(':');
        Event e;
        e.kind = part.substr(0, colon);
        const std::string arg = colon == std::string::npos ? "" : part.substr(colon + 1);
        if (e.kind == "click" || e.kind == "rclick") {
            auto p = parsePoint(arg, "--events " + e.kind);
            if (!p) return splatfx::makeError(p.error());
            e.at = *p;
        } else if (e.kind == "key" && arg.size() == 1) {
            e.key = arg[0];
        } else {
            return splatfx::makeError("--events: '" + part + "' is not click:X,Y, rclick:X,Y or key:C");
        }
        events.push_back(e);
    }
    return events;
}

struct App {
    Options options; // a copy: keys change the processing (o toggles ordering)
    const Source& source;
    bool pathMode = false;
    int patch = 64;
    std::uint32_t seed = 1;
    std::vector<cv::Point3i> centers;
    std::vector<cv::Point2d> path;
    std::string method = "positions";
    Selection selection;
    splatfx::TextureSet windowed;
    std::string status;
    double scale = 1.0; // window pixels per source pixel
    bool dirty = true;
    bool quit = false;
    int savedCount = 0;

    App(const Options& o, const Source& s) : options(o), source(s), patch(o.patch), seed(o.seed) {
        // Fit the photograph into about 720 x 720 window pixels.
        scale = std::min(1.0, 720.0 / std::max(s.width, s.height));
        if (scale < 1.0 / 16) scale = 1.0 / 16;
        if (std::max(s.width, s.height) * 2 <= 720) scale = 2.0;
        status = kHelp;
    }

    void rebuild() {
        dirty = false;
        selection = {};
        windowed = {};
        splatfx::Result<Selection> sel = splatfx::makeError("");
        if (pathMode) {
            if (path.size() < 2) {
                status = "path mode: click at least two points (" + std::to_string(path.size()) + " so far)";
                return;
            }
            sel = pickPath(source, {.points = path, .patch = patch, .step = options.step, .count = options.countGiven ? options.count : 0});
        } else {
            if (centers.empty()) return;
            sel = pickPositions(source, {.centers = centers, .defaultSize = patch});
        }
        if (!sel) {
            status = sel.error();
            return;
        }
        selection = *sel;
        auto made = makeSet(source, selection.patches, options.process);
        if (!made) {
            status = made.error();
            return;
        }
        windowed = made->set.windowed(splatfx::Footprint(options.process.footprint));
        std::vector<Patch> ordered;
        for (int k : made->order) ordered.push_back(selection.patches[size_t(k)]);
        selection.patches = ordered;
    }

    std::string parameters() const {
        json p{{"patch", patch}, {"interactive", true}};
        if (pathMode) {
            json pts = json::array();
            for (const cv::Point2d& q : path) pts.push_back({q.x, q.y});
            p["path"] = pts;
            p["step"] = options.step;
            p["overlap"] = patch - options.step;
        } else {
            json at = json::array();
            for (const cv::Point3i& c : centers) at.push_back({c.x, c.y, c.z > 0 ? c.z : patch});
            p["at"] = at;
            if (method != "positions") p["pickedBy"] = method;
        }
        return p.dump();
    }

    void save() {
        auto sel = pathMode
                       ? pickPath(source, {.points = path, .patch = patch, .step = options.step, .count = options.countGiven ? options.count : 0})
                       : pickPositions(source, {.centers = centers, .defaultSize = patch});
        if (!sel) {
            status = "not saved: " + sel.error();
            return;
        }
        status = "saving to " + options.out + "/ ...";
        if (auto s = produce(options, source, *sel, pathMode ? "path" : "positions", parameters()); !s) {
            status = "not saved: " + s.error();
            std::fprintf(stderr, "%s: %s\n", kToolName, s.error().c_str());
            return;
        }
        ++savedCount;
        status = "saved " + std::to_string(sel->patches.size()) + " textures to " + options.out + "/";
        std::printf("%s: interactive: %s\n", kToolName, status.c_str());
    }

    void click(cv::Point2d at, bool right) {
        if (right) {
            if (pathMode && !path.empty()) path.pop_back();
            else if (!pathMode && !centers.empty()) centers.pop_back();
        } else if (pathMode) {
            path.push_back(at);
        } else {
            centers.emplace_back(int(std::lround(at.x)), int(std::lround(at.y)), patch);
            method = "positions";
        }
        status = kHelp;
        dirty = true;
    }

    void key(int k) {
        switch (k) {
        case 'q':
        case 27: quit = true; break;
        case 'p':
            pathMode = !pathMode;
            status = pathMode ? "path mode: click the path's points" : "positions mode: click patch centres";
            dirty = true;
            break;
        case 'o':
            options.process.order = !options.process.order;
            dirty = true;
            break;
        case 'c':
            centers.clear();
            path.clear();
            dirty = true;
            break;
        case 'u': click({}, true); break;
        case '+':
        case '=':
            patch = std::min({patch + 8, source.width, source.height});
            resizeCenters();
            break;
        case '-':
            patch = std::max(kMinPatch, patch - 8);
            resizeCenters();
            break;
        case 'r':
        case 'f': {
            auto sel = k == 'r' ? pickRandom(source, {.count = options.count, .patch = patch, .seed = seed++, .accept = options.accept})
                                : pickSpectral(source, {.count = options.count, .patch = patch, .spread = true, .accept = options.accept});
            if (!sel) {
                status = sel.error();
                break;
            }
            pathMode = false;
            centers.clear();
            for (const Patch& p : sel->patches) centers.emplace_back(p.x + p.size / 2, p.y + p.size / 2, p.size);
            method = k == 'r' ? "random" : "spectral-spread";
            status = "picked " + std::to_string(centers.size()) + " patches (" + method + "); click to add more, s to save";
            dirty = true;
            break;
        }
        case 's': save(); break;
        default: break;
        }
    }

    void resizeCenters() {
        for (cv::Point3i& c : centers) c.z = patch;
        status = "patch " + std::to_string(patch) + " px";
        dirty = true;
    }

    cv::Mat draw(int frame) {
        if (dirty) rebuild();
        cv::Mat photo;
        cv::resize(source.rgb, photo, cv::Size(int(source.width * scale), int(source.height * scale)), 0, 0,
                   scale < 1.0 ? cv::INTER_AREA : cv::INTER_NEAREST);
        cv::cvtColor(photo, photo, cv::COLOR_RGB2BGR); // HighGUI shows BGR
        const int panel = 400, statusH = 24;
        const int W = photo.cols + panel, H = std::max(photo.rows, 460) + statusH;
        cv::Mat canvas(H, W, CV_32FC3, cv::Scalar(0.1f, 0.1f, 0.12f));
        photo.copyTo(canvas(cv::Rect(0, 0, photo.cols, photo.rows)));
        const cv::Scalar yellow(0.1f, 0.85f, 1.0f), cyan(1.0f, 0.9f, 0.2f), white(0.9f, 0.9f, 0.9f); // BGR on screen
        auto P = [&](double x, double y) { return cv::Point(int(x * scale), int(y * scale)); };
        for (size_t i = 0; i < selection.patches.size(); ++i) {
            const Patch& p = selection.patches[i];
            cv::rectangle(canvas, P(p.x, p.y), P(p.x + p.size, p.y + p.size), yellow, 1);
            if (!pathMode) cv::putText(canvas, std::to_string(i), P(p.x, p.y) + cv::Point(2, 12), cv::FONT_HERSHEY_PLAIN, 0.9, yellow);
        }
        for (size_t i = 0; i < path.size(); ++i) {
            cv::circle(canvas, P(path[i].x, path[i].y), 3, cyan, cv::FILLED);
            if (i > 0) cv::line(canvas, P(path[i - 1].x, path[i - 1].y), P(path[i].x, path[i].y), cyan, 2);
        }
        // The set as small windowed splats, and the cycling preview (3 frames per texture, cross-faded).
        const int x0 = photo.cols + 8;
        cv::putText(canvas, "textures (windowed)", cv::Point(x0, 16), cv::FONT_HERSHEY_PLAIN, 1.0, white);
        const int n = windowed.count();
        auto texel = [&](int k, float u, float v) {
            const int s = windowed.size;
            const int tx = std::clamp(int(u * s), 0, s - 1), ty = std::clamp(int(v * s), 0, s - 1);
            const float* t = &windowed.layers[size_t(k)][(size_t(ty) * s + tx) * 4];
            return cv::Vec3f(t[2] * t[3], t[1] * t[3], t[0] * t[3]); // BGR for HighGUI
        };
        const int thumb = 44;
        for (int k = 0; k < std::min(n, 16); ++k) {
            const int tx = x0 + (k % 8) * (thumb + 4), ty = 24 + (k / 8) * (thumb + 4);
            for (int y = 0; y < thumb; ++y)
                for (int x = 0; x < thumb; ++x) canvas.at<cv::Vec3f>(ty + y, tx + x) = texel(k, (x + 0.5f) / thumb, (y + 0.5f) / thumb);
        }
        const int big = 256, by = 130;
        cv::putText(canvas, "cycling preview", cv::Point(x0, by - 6), cv::FONT_HERSHEY_PLAIN, 1.0, white);
        if (n > 0) {
            // Three frames per texture, cross-faded, as the preview GIF and the samples cycle them.
            const int k0 = (frame / 3) % n, k1 = (k0 + 1) % n;
            const float t = (frame % 3) / 3.0f;
            const int s = windowed.size;
            cv::Mat small(s, s, CV_32FC3), large;
            for (int y = 0; y < s; ++y)
                for (int x = 0; x < s; ++x) {
                    const float u = (x + 0.5f) / s, v = (y + 0.5f) / s;
                    small.at<cv::Vec3f>(y, x) = texel(k0, u, v) * (1.0f - t) + texel(k1, u, v) * t;
                }
            cv::resize(small, large, cv::Size(big, big), 0, 0, cv::INTER_LINEAR);
            large.copyTo(canvas(cv::Rect(x0, by, big, big)));
        }
        std::ostringstream info;
        info << (pathMode ? "path" : "positions") << "  patch " << patch << " px  ->  " << options.process.textureSize << " texels  " << n
             << " textures" << (options.process.order ? "  ordered" : "");
        cv::putText(canvas, info.str(), cv::Point(x0, by + big + 20), cv::FONT_HERSHEY_PLAIN, 1.0, white);
        cv::putText(canvas, status.substr(0, 150), cv::Point(6, H - 8), cv::FONT_HERSHEY_PLAIN, 0.9, white);
        return canvas;
    }
};

} // namespace

int runInteractive(const Options& o) {
    auto src = loadSource(o.input, o.source);
    if (!src) {
        std::fprintf(stderr, "%s: %s\n", kToolName, src.error().c_str());
        return 1;
    }
    auto events = parseEvents(o.events);
    if (!events) {
        std::fprintf(stderr, "%s: %s\n", kToolName, events.error().c_str());
        return 2;
    }
    const char* display = std::getenv("DISPLAY");
    const char* wayland = std::getenv("WAYLAND_DISPLAY");
    if ((!display || !*display) && (!wayland || !*wayland)) {
        std::fprintf(stderr,
                     "%s: interactive mode needs a display and DISPLAY is not set; use the command-line modes, "
                     "or try it headless with: xvfb-run -a splatfx-texpick interactive ...\n",
                     kToolName);
        return 1;
    }
    Options opts = o;
    if (opts.patch > std::min(src->width, src->height)) opts.patch = std::max(kMinPatch, std::min(src->width, src->height));
    App app(opts, *src);
    try {
        cv::namedWindow(kWindow, cv::WINDOW_AUTOSIZE);
        cv::setMouseCallback(
            kWindow,
            [](int ev, int x, int y, int, void* user) {
                App& a = *static_cast<App*>(user);
                const cv::Point2d at(x / a.scale, y / a.scale);
                if (at.x >= a.source.width || at.y >= a.source.height) return; // the side panel
                if (ev == cv::EVENT_LBUTTONDOWN) a.click(at, false);
                if (ev == cv::EVENT_RBUTTONDOWN) a.click(at, true);
            },
            &app);
        std::printf("%s: interactive: %s (%dx%d); %s\n", kToolName, o.input.c_str(), src->width, src->height, kHelp);
        size_t next = 0;
        cv::Mat shown;
        for (int frame = 0; !app.quit; ++frame) {
            if (next < events->size()) {
                const Event& e = (*events)[next++];
                if (e.kind == "key") app.key(e.key);
                else app.click(e.at, e.kind == "rclick");
            }
            cv::Mat canvas = app.draw(frame);
            canvas.convertTo(shown, CV_8UC3, 255.0);
            cv::imshow(kWindow, shown);
            const int k = cv::waitKey(40);
            if (k >= 0) app.key(k & 0xff);
            if (o.autoQuitAfter > 0 && frame + 1 >= o.autoQuitAfter) break;
            if (cv::getWindowProperty(kWindow, cv::WND_PROP_VISIBLE) < 1.0) break;
        }
        if (!o.screenshot.empty() && !shown.empty() && !cv::imwrite(o.screenshot, shown))
            std::fprintf(stderr, "%s: cannot write --screenshot '%s'\n", kToolName, o.screenshot.c_str());
        cv::destroyAllWindows();
    } catch (const cv::Exception& e) {
        std::fprintf(stderr, "%s: the interactive window failed: %s\n", kToolName, e.what());
        return 1;
    }
    return 0;
}

} // namespace texpick
