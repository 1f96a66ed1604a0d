#include "splatfx/image_io.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include <OpenImageIO/imageio.h>

#include "checked_file.hpp"
#include "header_checks.hpp"

namespace splatfx {

namespace fs = std::filesystem;

namespace {

// The checks every read makes before a decoder sees the file.
Status checkImageFile(const std::string& path) {
    const std::string what = "cannot read image '" + path + "': ";
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (ec && ec.value() == ELOOP) return makeError(what + "its symbolic links form a loop");
    if (ec || !fs::exists(st)) return makeError(what + "no such file");
    if (fs::is_directory(st)) return makeError(what + "it is a folder");
    // Only regular files: a FIFO would block forever, a device (a link to /dev/zero) never ends.
    if (!fs::is_regular_file(st)) return makeError(what + "not a regular file (a FIFO, device or socket is never read as an image)");
    const std::uintmax_t bytes = fs::file_size(path, ec);
    if (ec) return makeError(what + ec.message());
    if (bytes == 0) return makeError(what + "the file is empty");
    if (bytes > kMaxImageFileBytes)
        return makeError(what + std::to_string(bytes) + " bytes, over the image-file budget of " + std::to_string(kMaxImageFileBytes) + " bytes");
    return detail::checkImageHeader(path);
}

} // namespace

Result<ImageInfo> readImageInfo(const std::string& path) {
    if (Status s = checkImageFile(path); !s) return makeError(s.error());
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
        std::string why = OIIO::geterror();
        return makeError("cannot read image '" + path + "': " + (why.empty() ? "unknown format or corrupt data" : why));
    }
    return ImageInfo{in->spec().width, in->spec().height, in->spec().nchannels};
}

Result<Image> readImage(const std::string& path, Alpha alpha) {
    if (Status s = checkImageFile(path); !s) return makeError(s.error());
    OIIO::ImageSpec config;
    if (alpha == Alpha::Straight) config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) {
        std::string why = OIIO::geterror();
        if (why.empty()) why = "unknown format or corrupt data";
        return makeError("cannot read image '" + path + "': " + why);
    }
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) return makeError("cannot read image '" + path + "': it has no pixels");
    if (spec.width > kMaxImageSide || spec.height > kMaxImageSide)
        return makeError("cannot read image '" + path + "': " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " is larger than " +
                         std::to_string(kMaxImageSide) + " on a side");
    if (static_cast<long long>(spec.width) * spec.height > kMaxImagePixels)
        return makeError("cannot read image '" + path + "': " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                         " is over the budget of " + std::to_string(kMaxImagePixels) + " pixels");
    Image img;
    img.width = spec.width;
    img.height = spec.height;
    img.channels = std::min(spec.nchannels, 4);
    // Only the channels kept are decoded: a header claiming a thousand channels costs nothing.
    img.pixels.resize(size_t(img.width) * img.height * img.channels);
    if (!in->read_image(0, 0, 0, img.channels, OIIO::TypeDesc::FLOAT, img.pixels.data())) {
        std::string why = in->geterror();
        return makeError("cannot read image '" + path + "': " + (why.empty() ? "truncated or corrupt data" : why));
    }
    return img;
}

Status writeImage(const std::string& path, const Image& image, Alpha alpha) {
    if (image.width <= 0 || image.height <= 0 || image.channels <= 0 || image.pixels.size() != size_t(image.width) * image.height * image.channels)
        return makeError("cannot write image '" + path + "': the image is empty or its size does not match its pixels");
    const fs::path target(path);
    auto out = OIIO::ImageOutput::create(target.string());
    if (!out) return makeError("cannot write image '" + path + "': no writer for '" + target.extension().string() + "'");
    const std::string ext = target.extension().string();
    const bool eightBit = ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".gif" || ext == ".bmp";
    OIIO::ImageSpec spec(image.width, image.height, image.channels, eightBit ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
    if (alpha == Alpha::Straight) spec.attribute("oiio:UnassociatedAlpha", 1);
    std::vector<float> clamped;
    const float* data = image.pixels.data();
    if (eightBit) {
        clamped = image.pixels;
        for (float& v : clamped) v = v == v ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
        data = clamped.data();
    }
    const std::string tmp = detail::temporaryNameFor(path);
    std::string why;
    auto file = detail::CheckedFile::create(tmp, why);
    if (!file) return makeError("cannot write image '" + path + "': " + why);
    const bool encoded = out->set_ioproxy(file.get()) && out->open(tmp, spec) && out->write_image(OIIO::TypeDesc::FLOAT, data) && out->close();
    const Status written = file->finish();
    if (!encoded || !written) {
        std::error_code ec;
        fs::remove(tmp, ec);
        return makeError("cannot write image '" + path + "': " + (!written ? written.error() : out->geterror()));
    }
    return detail::publishTemporary(tmp, path);
}

Status writeFileAtomically(const std::string& path, const std::string& bytes) {
    const std::string tmp = detail::temporaryNameFor(path);
    std::string why;
    auto file = detail::CheckedFile::create(tmp, why);
    if (!file) return makeError("cannot write '" + path + "': " + why);
    file->write(bytes.data(), bytes.size());
    if (Status s = file->finish(); !s) {
        std::error_code ec;
        fs::remove(tmp, ec);
        return makeError("cannot write '" + path + "': " + s.error());
    }
    return detail::publishTemporary(tmp, path);
}

} // namespace splatfx
