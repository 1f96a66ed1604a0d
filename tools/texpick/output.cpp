// texpick: provenance, contact sheet, headless preview, and the all-or-nothing output folder.
//
// [SECTION] Provenance
// [SECTION] Contact sheet
// [SECTION] Preview
// [SECTION] Output folder
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>

#include <signal.h>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "splatfx/context.hpp"
#include "splatfx/splatfx.hpp"
#include "texpick.hpp"

namespace texpick {

namespace fs = std::filesystem;
using json = nlohmann::json;
using splatfx::makeError;

// [SECTION] Provenance

namespace {

// Rounded for a manifest people read; 6 significant digits are far below what
// 8-bit textures resolve.
double r6(double v) {
    if (v == 0.0 || !std::isfinite(v)) return 0.0;
    const double scale = std::pow(10.0, 5 - int(std::floor(std::log10(std::abs(v)))));
    return std::round(v * scale) / scale;
}

const char* contrastName(Contrast c) { return c == Contrast::Patch ? "patch" : c == Contrast::Set ? "set" : "none"; }
const char* kernelName(splatfx::Kernel k) { return k == splatfx::Kernel::CrawfisMax ? "crawfis-max" : "gaussian"; }

} // namespace

std::string provenanceJson(const Provenance& p) {
    json j;
    j["tool"] = kToolName;
    j["toolVersion"] = kToolVersion;
    j["provenanceVersion"] = kProvenanceVersion;
    json src;
    src["file"] = p.sourceFile;
    if (p.sourceWidth > 0) src["width"] = p.sourceWidth, src["height"] = p.sourceHeight;
    if (!p.credit.empty()) src["credit"] = p.credit;
    if (!p.license.empty()) src["license"] = p.license;
    j["source"] = src;
    j["method"] = p.method;
    j["parameters"] = json::parse(p.parametersJson, nullptr, false);
    if (j["parameters"].is_discarded()) j["parameters"] = json::object();
    if (p.process) {
        json pr;
        pr["textureSize"] = p.process->textureSize;
        pr["color"] = p.process->color;
        pr["alpha"] = "composited over black";
        pr["contrast"] = contrastName(p.process->contrast);
        pr["contrastMean"] = 0.5;
        pr["contrastStd"] = r6(p.process->contrastStd);
        pr["windowed"] = p.process->window;
        pr["footprint"] = kernelName(p.process->footprint.kernel);
        pr["ordered"] = p.process->order;
        j["processing"] = pr;
    }
    if (!p.order.empty()) j["order"] = p.order;
    if (p.selection) {
        json spectral;
        spectral["version"] = 1;
        spectral["bandEdgesCyclesPerPixel"] = bandEdges();
        spectral["method"] = "luminance of the source patch, window-weighted mean removed, separable Hann window, "
                             "DFT power summed in radial bands (last band includes the corners); fractions of non-DC power";
        j["spectral"] = spectral;
        json patches = json::array();
        for (size_t k = 0; k < p.selection->patches.size(); ++k) {
            // Texture k of the set came from patch order[k].
            const size_t i = p.order.empty() ? k : size_t(p.order[k]);
            const Patch& pa = p.selection->patches[i];
            const SpectralStats& st = p.selection->stats[i];
            char name[32];
            std::snprintf(name, sizeof name, "t%03zu.png", k);
            json e;
            e["texture"] = name;
            e["patch"] = int(i);
            e["x"] = pa.x;
            e["y"] = pa.y;
            e["size"] = pa.size;
            json bands = json::array();
            for (double b : st.bandEnergy) bands.push_back(r6(b));
            e["bandEnergy"] = bands;
            e["power"] = r6(st.power);
            e["centroidCyclesPerPixel"] = r6(st.centroid);
            e["mean"] = r6(st.mean);
            e["std"] = r6(st.stddev);
            e["coverage"] = r6(st.coverage);
            patches.push_back(e);
        }
        j["patches"] = patches;
    }
    return j.dump();
}

// [SECTION] Contact sheet

splatfx::Image contactSheet(const splatfx::TextureSet& set, const splatfx::FootprintDesc& fpDesc, const Source* source,
                            const std::vector<Patch>* patches) {
    const int n = set.count();
    const int cell = std::max(64, set.size);
    const int gap = 6, label = 16;
    const int cols = std::min(n, 8), rows = (n + cols - 1) / cols;
    const int blockH = 2 * cell + gap + label;
    const int gridW = cols * (cell + gap) + gap, gridH = rows * (blockH + gap) + gap;
    const splatfx::TextureSet windowed = set.windowed(splatfx::Footprint(fpDesc));

    // The source thumbnail: as tall as the texture grid (at least 256 px).
    cv::Mat thumb;
    double scale = 1.0;
    if (source) {
        const int h = std::max(gridH, 256);
        scale = double(h - 2 * gap) / source->height;
        cv::resize(source->rgb, thumb, cv::Size(std::max(1, int(std::lround(source->width * scale))), h - 2 * gap), 0, 0,
                   scale < 1.0 ? cv::INTER_AREA : cv::INTER_LINEAR);
    }
    const int thumbW = source ? thumb.cols + gap : 0;
    const int W = gap + thumbW + gridW, H = std::max(gridH, source ? thumb.rows + 2 * gap : 0);
    cv::Mat sheet(H, W, CV_32FC3, cv::Scalar(0.12f, 0.12f, 0.14f));
    const cv::Scalar outline(1.0f, 0.85f, 0.1f), text(0.9f, 0.9f, 0.9f);
    if (source) {
        thumb.copyTo(sheet(cv::Rect(gap, gap, thumb.cols, thumb.rows)));
        if (patches)
            for (size_t i = 0; i < patches->size(); ++i) {
                const Patch& p = (*patches)[i];
                const cv::Point a(gap + int(p.x * scale), gap + int(p.y * scale));
                const cv::Point b(gap + int((p.x + p.size) * scale), gap + int((p.y + p.size) * scale));
                cv::rectangle(sheet, a, b, outline, 1);
                cv::putText(sheet, std::to_string(i), a + cv::Point(2, 11), cv::FONT_HERSHEY_PLAIN, 0.8, outline, 1);
            }
    }
    auto texel = [&](const splatfx::TextureSet& s, int k, int x, int y) {
        const float* t = &s.layers[size_t(k)][(size_t(y) * s.size + x) * 4];
        // Shown as the splat looks over black: colour times opacity (detail lives in A once windowed).
        return cv::Vec3f(t[0] * t[3], t[1] * t[3], t[2] * t[3]);
    };
    for (int k = 0; k < n; ++k) {
        const int x0 = gap + thumbW + gap + (k % cols) * (cell + gap), y0 = gap + (k / cols) * (blockH + gap);
        for (int y = 0; y < cell; ++y)
            for (int x = 0; x < cell; ++x) {
                const int tx = x * set.size / cell, ty = y * set.size / cell; // nearest: texels stay visible
                sheet.at<cv::Vec3f>(y0 + y, x0 + x) = texel(set, k, tx, ty);
                sheet.at<cv::Vec3f>(y0 + cell + gap + y, x0 + x) = texel(windowed, k, tx, ty);
            }
        cv::putText(sheet, std::to_string(k), cv::Point(x0 + 2, y0 + 2 * cell + gap + label - 3), cv::FONT_HERSHEY_PLAIN, 0.9, text, 1);
    }
    splatfx::Image img;
    img.width = W;
    img.height = H;
    img.channels = 3;
    img.pixels.assign(sheet.ptr<float>(0), sheet.ptr<float>(0) + size_t(W) * H * 3);
    return img;
}

// [SECTION] Preview

namespace {

splatfx::ColorTable previewTable(const std::string& name) {
    if (name == "fire") return splatfx::ColorTable::fire();
    if (name == "steam") return splatfx::ColorTable::steam();
    if (name == "dust") return splatfx::ColorTable::dust();
    if (name == "white") return splatfx::ColorTable::constant({1, 1, 1, 1});
    return splatfx::ColorTable::smoke();
}

std::uint32_t hash(glm::ivec3 c) {
    std::uint32_t x = std::uint32_t(c.x * 73856093) ^ std::uint32_t(c.y * 19349663) ^ std::uint32_t(c.z * 83492791);
    x ^= x >> 13;
    x *= 0x5bd1e995u;
    x ^= x >> 15;
    return x;
}

// Looks at the grid's bounding sphere (voxel centres plus the kernel's reach) so it fills the view.
splatfx::Camera frame(const splatfx::Grid& g, float support, glm::ivec2 viewport) {
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const splatfx::Voxel& v : g.voxels) {
        lo = glm::min(lo, g.worldPosition(v.cell));
        hi = glm::max(hi, g.worldPosition(v.cell));
    }
    const glm::vec3 centre = 0.5f * (lo + hi);
    // The footprint is faint beyond about half its support radius, so framing
    // the half-extent plus half the support leaves little empty border; a lone
    // splat gets its whole support so its edge is visible.
    const float extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    const float radius = 0.5f * extent + (extent > 0.0f ? 0.6f : 1.0f) * support * g.spacing.x;
    const float fov = glm::radians(40.0f);
    const float dist = 1.05f * radius / std::sin(0.5f * fov);
    return splatfx::Camera::lookAt(centre + glm::vec3(0.0f, 0.0f, dist), centre, {0, 1, 0}, fov, viewport);
}

} // namespace

splatfx::Status renderPreview(const splatfx::TextureSet& set, const OutputDesc& d,
                              const std::function<splatfx::Status(const splatfx::Image&)>& sink) {
    if (set.count() < 1) return makeError("preview: the set has no textures");
    if (d.previewSize < 32 || d.previewSize > 2048)
        return makeError("--preview-size must be between 32 and 2048 pixels, got " + std::to_string(d.previewSize));
    auto ctx = splatfx::HeadlessContext::create();
    if (!ctx) return makeError("cannot render the preview: " + ctx.error() + " (pass --no-preview to skip it)");
    const int h = d.previewSize;
    auto fb = splatfx::gl::Framebuffer::create({.width = 2 * h, .height = h});
    if (!fb) return makeError("cannot render the preview: " + fb.error());
    const splatfx::Footprint fp(d.footprint);
    splatfx::Materials mat(fp, {.layerSize = set.size});
    const std::uint32_t setId = mat.addTextureSet(set);
    const std::uint32_t tableId = mat.addColorTable(previewTable(d.previewColors));
    auto renderer = splatfx::gl::FrameRenderer::create();
    if (!renderer) return makeError("cannot render the preview: " + renderer.error());
    if (auto s = renderer->upload(mat); !s) return makeError("cannot render the preview: " + s.error());

    // Left: one big splat, so the artist sees each windowed texture (Fig. 2).
    // Opacity 0.6 rather than 1: a saturated splat would hide the detail it carries.
    auto single = splatfx::Grid::fromDense({1, 1, 1}, {0.6f});
    // Right: a puff of splats, each starting at its own texture (sec. 2 step 3).
    const float r = 3.0f;
    auto puff = splatfx::Grid::sphere(r);
    if (!single || !puff) return makeError("cannot build the preview grids");
    single->voxels[0].colorCoord = 0.3f;
    for (splatfx::Voxel& v : puff->voxels) {
        const glm::vec3 p = puff->localPosition(v.cell) - glm::vec3(0.0f, r, 0.0f);
        v.opacity = std::clamp(0.45f * (1.0f - glm::length(p) / (r + 1.0f)), 0.0f, 1.0f);
        v.texture = hash(v.cell);
    }
    puff->colorByHeight();
    const splatfx::Grid puffBase = *puff;
    const glm::ivec2 vp(h, h);
    const splatfx::Camera camSingle = frame(*single, fp.radius(), vp), camPuff = frame(*puff, fp.radius(), vp);

    const int frames = d.previewFrames > 0 ? d.previewFrames : 3 * set.count();
    splatfx::Frame singleFrame, puffFrame; // one frame per view, drawn side by side
    for (int f = 0; f < frames; ++f) {
        // Three frames per texture with cross-fades: one full cycle, so the GIF loops seamlessly.
        const double steps = f / 3.0;
        const auto whole = std::uint32_t(std::floor(steps));
        const float phase = float(steps - std::floor(steps));
        single->voxels[0].texture = whole;
        single->voxels[0].phase = phase;
        for (size_t i = 0; i < puff->voxels.size(); ++i) {
            puff->voxels[i].texture = puffBase.voxels[i].texture + whole;
            puff->voxels[i].phase = phase;
        }
        fb->clear({0.02f, 0.02f, 0.04f, 1.0f});
        const splatfx::SplatStyle style{.textureSet = setId, .colorTable = tableId, .crossfade = true};
        singleFrame.begin(f, camSingle);
        singleFrame.builder().add(*single, mat, style);
        singleFrame.end();
        renderer->render(singleFrame, {.framebuffer = fb->handle(), .x = 0, .y = 0});
        puffFrame.begin(f, camPuff);
        puffFrame.builder().add(*puff, mat, style);
        puffFrame.end();
        renderer->render(puffFrame, {.framebuffer = fb->handle(), .x = h, .y = 0});
        // One frame at a time to the sink: memory stays one frame whatever the preview's length.
        if (auto s = sink(fb->read()); !s) return s;
    }
    return {};
}

splatfx::Result<std::vector<splatfx::Image>> renderPreview(const splatfx::TextureSet& set, const OutputDesc& d) {
    std::vector<splatfx::Image> frames;
    if (auto s = renderPreview(set, d,
                               [&](const splatfx::Image& f) {
                                   frames.push_back(f);
                                   return splatfx::Status{};
                               });
        !s)
        return makeError(s.error());
    return frames;
}

// [SECTION] Output folder

namespace {

// ".<name><tag><pid>": beside the target, hidden, unique to this process.
// Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "." + std::string.
std::string hiddenName(const fs::path& target, const char* tag) {
    std::string name(1, '.');
    name += target.filename().string();
    name += tag;
    name += std::to_string(getpid());
    return name;
}

// What a killed run left beside `target`, named by hiddenName with a process
// id that is no longer running: a staging folder (removed), or the previous
// set moved aside at the swap (put back when the new one never arrived,
// removed when it did).
splatfx::Status recoverKilledRuns(const fs::path& parent, const fs::path& target) {
    std::error_code ec;
    std::string stem(1, '.'); // piecewise, as hiddenName (GCC 12's false -Wrestrict)
    stem += target.filename().string();
    stem += ".texpick-";
    for (const auto& entry : fs::directory_iterator(parent, ec)) {
        const std::string n = entry.path().filename().string();
        if (n.rfind(stem, 0) != 0) continue;
        const bool old = n.compare(stem.size(), 4, "old-") == 0;
        const std::string pidText = n.substr(stem.size() + (old ? 4 : 0));
        if (pidText.empty() || pidText.find_first_not_of("0123456789") != std::string::npos) continue;
        const long pid = std::strtol(pidText.c_str(), nullptr, 10);
        if (pid == long(getpid()) || ::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue; // its owner is still running
        std::error_code e2;
        if (old && !fs::exists(target, e2)) {
            fs::rename(entry.path(), target, e2);
            if (e2)
                return makeError("a killed run left the previous '" + target.string() + "' at '" + entry.path().string() +
                                 "' and it cannot be put back: " + e2.message());
        } else {
            fs::remove_all(entry.path(), e2);
        }
    }
    return {};
}

} // namespace

splatfx::Status writeOutput(const std::string& folder, const splatfx::TextureSet& set, const std::string& provenance, const OutputDesc& d,
                            const Source* source, const std::vector<Patch>* patches) {
    std::error_code ec;
    if (folder.empty()) return makeError("--out is required: the folder to write the texture set to");
    const fs::path target = fs::path(folder).lexically_normal();
    if (target.filename().empty() || target.filename() == "." || target.filename() == "..")
        return makeError("--out '" + folder + "' must name a folder (not '.', '..' or end in '/')");
    if (fs::exists(target, ec)) {
        if (!fs::is_directory(target, ec)) return makeError("refusing to replace '" + folder + "': it is a file, not a texture-set folder");
        if (!fs::is_empty(target, ec) && !fs::exists(target / "manifest.json", ec))
            return makeError("refusing to replace '" + folder +
                             "': it exists and is not a texture-set folder (no manifest.json); remove it or choose another --out");
    }
    const fs::path parent = target.parent_path().empty() ? fs::path(".") : target.parent_path();
    // Remember the first missing ancestor so a failed run can remove what it created.
    fs::path created;
    for (fs::path p = parent; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
        created = p;
        if (p == p.parent_path()) break;
    }
    fs::create_directories(parent, ec);
    if (ec) return makeError("cannot create the folder '" + parent.string() + "' for '" + folder + "': " + ec.message());
    if (auto s = recoverKilledRuns(parent, target); !s) return s;
    const fs::path staging = parent / hiddenName(target, ".texpick-");
    fs::remove_all(staging, ec);
    auto fail = [&](const std::string& why) {
        fs::remove_all(staging, ec);
        if (!created.empty()) fs::remove_all(created, ec);
        return splatfx::Status(makeError("nothing written to '" + folder + "': " + why));
    };
    // The set itself, atomically, into the staging folder...
    if (auto s = saveTextureSet(set, staging.string(), provenance); !s) return fail(s.error());
    // ...then the pictures beside it...
    if (d.contactSheet)
        if (auto s = splatfx::writeImage((staging / "contact.png").string(), contactSheet(set, d.footprint, source, patches)); !s)
            return fail(s.error());
    if (d.preview) {
        splatfx::AnimationWriter gif((staging / "preview.gif").string(), d.previewFps);
        if (auto s = renderPreview(set, d, [&](const splatfx::Image& f) { return gif.add(f); }); !s) return fail(s.error());
        if (auto s = gif.finish(); !s) return fail(s.error());
    }
    // ...and a check that the SDK reads back what was written, before anything is replaced.
    if (auto back = splatfx::loadTextureSet(staging.string()); !back) return fail("the written set does not load: " + back.error());
    // Finally the swap: the old folder steps aside, the new one takes its name.
    const fs::path old = parent / hiddenName(target, ".texpick-old-");
    fs::remove_all(old, ec);
    const bool had = fs::exists(target, ec);
    if (had) {
        fs::rename(target, old, ec);
        if (ec) return fail("cannot move the existing '" + folder + "' aside: " + ec.message());
    }
    fs::rename(staging, target, ec);
    if (ec) {
        const std::string why = ec.message();
        if (had) fs::rename(old, target, ec);
        return fail("cannot move the finished set into place: " + why);
    }
    fs::remove_all(old, ec);
    return {};
}

} // namespace texpick
