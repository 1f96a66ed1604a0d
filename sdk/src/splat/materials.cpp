#include "splatfx/materials.hpp"

#include <algorithm>
#include <cassert>

namespace splatfx {

Materials::Materials(const Footprint& footprint, const MaterialsDesc& desc) : mFootprint(footprint), mDesc(desc) {
    assert(desc.layerSize >= 4 && "MaterialsDesc::layerSize must be at least 4");
    assert(desc.colorTableSize >= 2 && "MaterialsDesc::colorTableSize must be at least 2");
    // Layer 0: the plain footprint, for traditional splatting.
    mLayers.push_back(TextureSet::footprintOnly(mFootprint, desc.layerSize).layers[0]);
}

std::uint32_t Materials::addTextureSet(const TextureSet& set) {
    assert(set.count() > 0 && "Materials::addTextureSet: the set is empty");
    // Window at the set's own resolution, then resample: windowing first keeps
    // the footprint's edge exact for high-resolution photo patches.
    TextureSet w = set.windowed(mFootprint).resized(mDesc.layerSize);
    SetRange range;
    range.first = static_cast<std::uint32_t>(mLayers.size());
    range.count = static_cast<std::uint32_t>(w.count());
    range.color = w.color;
    double plain = 0.0, textured = 0.0;
    for (size_t t = 3; t < mLayers[0].size(); t += 4) plain += mLayers[0][t];
    for (const auto& layer : w.layers)
        for (size_t t = 3; t < layer.size(); t += 4) textured += layer[t] / double(w.layers.size());
    range.gain = textured > 1e-9 ? float(std::min(plain / textured, 16.0)) : 1.0f;
    for (auto& layer : w.layers) mLayers.push_back(std::move(layer));
    mSets.push_back(range);
    ++mVersion;
    return static_cast<std::uint32_t>(mSets.size() - 1);
}

std::uint32_t Materials::addColorTable(const ColorTable& table) {
    mTables.push_back(table);
    mRows.push_back(table.resampled(mDesc.colorTableSize));
    ++mVersion;
    return static_cast<std::uint32_t>(mTables.size() - 1);
}

} // namespace splatfx
