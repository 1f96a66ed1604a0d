// TextureSet::sampleImage: texture windows cut from an image in memory
// (file reading stays with the caller, e.g. the scene-file reader).
#include <algorithm>
#include <cstdint>
#include <string>

#include "splatfx/dynamics.hpp"
#include "splatfx/texture_set.hpp"

namespace splatfx {

Result<TextureSet> TextureSet::sampleImage(const Image& source, const ImageSampleDesc& desc) {
    if (desc.count < 1) return makeError("ImageSampleDesc.count must be at least 1, got " + std::to_string(desc.count));
    if (desc.size < 1) return makeError("ImageSampleDesc.size must be at least 1, got " + std::to_string(desc.size));
    if (source.width < 0 || source.height < 0 || source.channels < 1 || source.channels > 4 ||
        source.pixels.size() != std::size_t(source.width) * std::size_t(source.height) * std::size_t(source.channels))
        return makeError(desc.sourceName + " holds " + std::to_string(source.pixels.size()) + " values, which does not match " +
                         std::to_string(source.width) + "x" + std::to_string(source.height) + " pixels of " + std::to_string(source.channels) +
                         " channels (1 to 4)");
    if (source.width < desc.size || source.height < desc.size)
        return makeError(desc.sourceName + " is " + std::to_string(source.width) + "x" + std::to_string(source.height) +
                         ", smaller than the sample size " + std::to_string(desc.size));
    std::vector<Image> crops;
    crops.reserve(std::size_t(desc.count));
    for (int i = 0; i < desc.count; ++i) {
        // A uniform corner over the positions that keep the window inside the
        // image (hashUnit < 1, so the product stays below the count; the
        // min only guards the bound).
        const int x0 = std::min(int(hashUnit(hashCell({i, 0, 0}, desc.seed, 11)) * float(source.width - desc.size + 1)), source.width - desc.size);
        const int y0 = std::min(int(hashUnit(hashCell({i, 0, 0}, desc.seed, 12)) * float(source.height - desc.size + 1)), source.height - desc.size);
        Image crop;
        crop.width = crop.height = desc.size;
        crop.channels = source.channels;
        crop.pixels.resize(std::size_t(desc.size) * std::size_t(desc.size) * std::size_t(source.channels));
        for (int y = 0; y < desc.size; ++y)
            for (int x = 0; x < desc.size; ++x)
                for (int ch = 0; ch < source.channels; ++ch) crop.at(x, y, ch) = source.at(x0 + x, y0 + y, ch);
        crops.push_back(std::move(crop));
    }
    return fromImages(crops, desc.keepColor);
}

} // namespace splatfx
