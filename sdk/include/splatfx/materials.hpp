// splatfx/materials.hpp: every texture set and colour table a frame may use.
//
// Materials gathers the textured splats (windowed by one footprint) into one
// array of equal-size layers and the colour tables into rows, the way the GL
// renderer uploads them (one texture array, one 2D colour texture) and the
// reference renderer reads them. Layer 0 is the plain footprint, used for
// traditional (untextured) splatting.
//
//   splatfx::Materials mat(splatfx::Footprint{});
//   auto fireSet = mat.addTextureSet(splatfx::TextureSet::turbulence({}));
//   auto fireLut = mat.addColorTable(splatfx::ColorTable::fire());
//
// Threading: a plain value; changes bump version() so renderers re-upload.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/color_table.hpp"
#include "splatfx/footprint.hpp"
#include "splatfx/texture_set.hpp"

namespace splatfx {

struct MaterialsDesc {
    int layerSize = 32;       // texels on a side of every layer; sets are resampled to it; default 32
    int colorTableSize = 256; // entries per colour row; default 256
};

class Materials {
public:
    struct SetRange {
        std::uint32_t first = 0; // first layer of the set
        std::uint32_t count = 0; // layers in the set
        bool color = false;
        // Optical-depth gain that gives the set the plain footprint's mean
        // opacity, so textured and traditional splats of one grid carry the
        // same amount of material (detail moves it around, it does not thin it).
        float gain = 1.0f;
    };

    explicit Materials(const Footprint& footprint, const MaterialsDesc& desc = {});

    // Windows the set with the footprint (Fig. 2) unless already windowed,
    // resamples it to layerSize, and appends it. Returns the set's id.
    // Expects a non-empty set.
    std::uint32_t addTextureSet(const TextureSet& set);
    // Appends a row; returns its id.
    std::uint32_t addColorTable(const ColorTable& table);

    const Footprint& footprint() const { return mFootprint; }
    int layerSize() const { return mDesc.layerSize; }
    int colorTableSize() const { return mDesc.colorTableSize; }
    std::uint32_t layerCount() const { return static_cast<std::uint32_t>(mLayers.size()); }
    std::uint32_t colorTableCount() const { return static_cast<std::uint32_t>(mTables.size()); }
    const SetRange& set(std::uint32_t id) const { return mSets.at(id); }
    std::uint32_t setCount() const { return static_cast<std::uint32_t>(mSets.size()); }
    const ColorTable& colorTable(std::uint32_t id) const { return mTables.at(id); }

    // RGBA float, layerSize^2 texels, row-major: what the GPU samples.
    const std::vector<float>& layer(std::uint32_t index) const { return mLayers.at(index); }
    // colorTableSize RGBA entries for row id.
    const std::vector<glm::vec4>& colorRow(std::uint32_t id) const { return mRows.at(id); }

    std::uint64_t version() const { return mVersion; }

private:
    Footprint mFootprint;
    MaterialsDesc mDesc;
    std::vector<std::vector<float>> mLayers;
    std::vector<SetRange> mSets;
    std::vector<ColorTable> mTables;
    std::vector<std::vector<glm::vec4>> mRows;
    std::uint64_t mVersion = 1;
};

} // namespace splatfx
