#include <filesystem>
#include <system_error>

#include <OpenImageIO/imageio.h>

#include "splatfx/image.hpp"

namespace splatfx {

namespace fs = std::filesystem;

AnimationWriter::AnimationWriter(std::string path, int framesPerSecond) : mPath(std::move(path)), mFps(framesPerSecond) {}

Status AnimationWriter::add(const Image& frame) {
    if (frame.width <= 0 || frame.height <= 0 || frame.channels < 3)
        return makeError("animation '" + mPath + "': frames must be RGB or RGBA and non-empty");
    if (!mFrames.empty() && (frame.width != mFrames[0].width || frame.height != mFrames[0].height))
        return makeError("animation '" + mPath + "': frame " + std::to_string(mFrames.size()) + " is " +
                         std::to_string(frame.width) + "x" + std::to_string(frame.height) + ", the first was " +
                         std::to_string(mFrames[0].width) + "x" + std::to_string(mFrames[0].height));
    Image rgb;
    rgb.width = frame.width;
    rgb.height = frame.height;
    rgb.channels = 3;
    rgb.pixels.resize(size_t(frame.width) * frame.height * 3);
    for (size_t p = 0, n = size_t(frame.width) * frame.height; p < n; ++p)
        for (int c = 0; c < 3; ++c) {
            const float v = frame.pixels[p * frame.channels + c];
            rgb.pixels[p * 3 + c] = v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;
        }
    mFrames.push_back(std::move(rgb));
    return {};
}

Status AnimationWriter::finish() {
    if (mFrames.empty()) return makeError("animation '" + mPath + "': no frames to write");
    const fs::path target(mPath);
    const fs::path tmp = target.parent_path() / (".tmp-" + target.filename().string());
    auto out = OIIO::ImageOutput::create(target.string());
    if (!out) return makeError("animation '" + mPath + "': no writer for '" + target.extension().string() + "'");
    if (!out->supports("multiimage") || !out->supports("appendsubimage"))
        return makeError("animation '" + mPath + "': the '" + target.extension().string() + "' writer cannot hold several frames; use .gif");
    std::vector<OIIO::ImageSpec> specs(mFrames.size());
    for (size_t i = 0; i < mFrames.size(); ++i) {
        specs[i] = OIIO::ImageSpec(mFrames[i].width, mFrames[i].height, 3, OIIO::TypeDesc::UINT8);
        const int fps[2] = {mFps, 1};
        specs[i].attribute("FramesPerSecond", OIIO::TypeRational, fps);
        specs[i].attribute("oiio:Movie", 1);
        specs[i].attribute("gif:LoopCount", 0);
    }
    std::error_code ec;
    bool ok = out->open(tmp.string(), int(specs.size()), specs.data());
    for (size_t i = 0; ok && i < mFrames.size(); ++i) {
        if (i > 0) ok = out->open(tmp.string(), specs[i], OIIO::ImageOutput::AppendSubimage);
        ok = ok && out->write_image(OIIO::TypeDesc::FLOAT, mFrames[i].pixels.data());
    }
    ok = out->close() && ok;
    if (!ok) {
        fs::remove(tmp, ec);
        return makeError("animation '" + mPath + "': " + out->geterror());
    }
    fs::rename(tmp, target, ec);
    if (ec) {
        fs::remove(tmp, ec);
        return makeError("animation '" + mPath + "': " + ec.message());
    }
    return {};
}

} // namespace splatfx
