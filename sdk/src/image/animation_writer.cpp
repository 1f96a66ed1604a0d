// Animated GIFs, streamed frame by frame through a checked file (checked_file.hpp).
#include <cmath>
#include <filesystem>
#include <system_error>

#include <OpenImageIO/imageio.h>

#include "checked_file.hpp"
#include "splatfx/image_io.hpp"

namespace splatfx {

namespace fs = std::filesystem;

struct AnimationWriter::Impl {
    std::string path;
    double fps = 24.0;
    std::string tmp;
    std::unique_ptr<detail::CheckedFile> file;
    std::unique_ptr<OIIO::ImageOutput> out;
    int frames = 0, width = 0, height = 0;
    bool failed = false;
    std::vector<unsigned char> rgb; // one frame, 8-bit

    ~Impl() {
        if (!tmp.empty()) { // not finished: leave nothing behind
            out.reset();
            file.reset();
            std::error_code ec;
            fs::remove(tmp, ec);
        }
    }
    Status fail(const std::string& why) {
        failed = true;
        return makeError("animation '" + path + "': " + why);
    }
};

AnimationWriter::AnimationWriter(std::string path, double framesPerSecond) : mImpl(std::make_unique<Impl>()) {
    mImpl->path = std::move(path);
    mImpl->fps = framesPerSecond;
}
AnimationWriter::AnimationWriter(AnimationWriter&&) noexcept = default;
AnimationWriter& AnimationWriter::operator=(AnimationWriter&&) noexcept = default;
AnimationWriter::~AnimationWriter() = default;

int AnimationWriter::frames() const { return mImpl->frames; }

Status AnimationWriter::add(const Image& frame) {
    Impl& w = *mImpl;
    if (w.failed) return makeError("animation '" + w.path + "': an earlier frame failed");
    if (frame.width <= 0 || frame.height <= 0 || frame.channels < 3 || frame.pixels.size() != size_t(frame.width) * frame.height * frame.channels)
        return w.fail("frames must be RGB or RGBA, non-empty, with as many pixels as their size says");
    if (w.frames > 0 && (frame.width != w.width || frame.height != w.height))
        return w.fail("frame " + std::to_string(w.frames) + " is " + std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                      ", the first was " + std::to_string(w.width) + "x" + std::to_string(w.height));
    // GIF delays are whole hundredths of a second, 1 to 65535.
    const double delayCs = 100.0 / w.fps;
    if (!(std::isfinite(delayCs) && std::lround(delayCs) >= 1 && std::lround(delayCs) <= 65535))
        return w.fail("a GIF cannot show " + std::to_string(w.fps) + " frames per second (its frame delay is 1 to 65535 hundredths of a second)");
    w.rgb.resize(size_t(frame.width) * frame.height * 3);
    for (size_t p = 0, n = size_t(frame.width) * frame.height; p < n; ++p)
        for (int c = 0; c < 3; ++c) {
            const float v = frame.pixels[p * frame.channels + c];
            w.rgb[p * 3 + c] = (unsigned char)std::lround((v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f) * 255.0f);
        }
    OIIO::ImageSpec spec(frame.width, frame.height, 3, OIIO::TypeDesc::UINT8);
    // The rate as a rational with centisecond resolution (an integer rate would make 0.5 fps a zero delay).
    const int rate[2] = {100, int(std::lround(delayCs))};
    spec.attribute("FramesPerSecond", OIIO::TypeRational, rate);
    spec.attribute("oiio:Movie", 1);
    spec.attribute("gif:LoopCount", 0);
    if (w.frames == 0) {
        const fs::path target(w.path);
        w.out = OIIO::ImageOutput::create(target.string());
        if (!w.out) return w.fail("no writer for '" + target.extension().string() + "'");
        if (!w.out->supports("appendsubimage"))
            return w.fail("the '" + target.extension().string() + "' writer cannot hold several frames; use .gif");
        w.tmp = detail::temporaryNameFor(w.path);
        std::string why;
        w.file = detail::CheckedFile::create(w.tmp, why);
        if (!w.file) return w.fail(why);
        if (!w.out->set_ioproxy(w.file.get()) || !w.out->open(w.tmp, spec)) return w.fail(w.out->geterror());
        w.width = frame.width, w.height = frame.height;
    } else if (!w.out->open(w.tmp, spec, OIIO::ImageOutput::AppendSubimage)) {
        return w.fail(w.out->geterror());
    }
    if (!w.out->write_image(OIIO::TypeDesc::UINT8, w.rgb.data())) return w.fail(w.out->geterror());
    ++w.frames;
    return {};
}

Status AnimationWriter::finish() {
    Impl& w = *mImpl;
    if (w.failed) return makeError("animation '" + w.path + "': an earlier frame failed; nothing written");
    if (w.frames == 0) return makeError("animation '" + w.path + "': no frames to write");
    const bool closed = w.out->close();
    const std::string encoderError = closed ? std::string() : w.out->geterror();
    const Status written = w.file->finish();
    w.out.reset();
    w.file.reset();
    if (!closed || !written) {
        w.failed = true;
        return makeError("animation '" + w.path + "': " + (!written ? written.error() : encoderError)); // ~Impl removes tmp
    }
    const std::string tmp = std::exchange(w.tmp, std::string());
    w.failed = true; // finished: further add() calls are misuse
    return detail::publishTemporary(tmp, w.path);
}

} // namespace splatfx
