// splatfx/materials.hpp: every texture set and colour table a frame may use.
//
// Materials gathers the textured splats (windowed by one footprint) into one
// array of equal-size layers and the colour tables into rows, the way the GL
// renderer uploads them (one texture array, one 2D colour texture) and the
// reference renderer reads them. Layer 0 is the plain footprint, used for
// traditional (untextured) splatting.
//
// Registration is by content: adding a texture set or colour table equal to
// one already registered returns the existing id and adds nothing, so a level
// of 1000 preset effects holds only its distinct sets (presets key their
// procedural sets by their parameters and skip regenerating them). Ids are
// stable: never reused, reordered or removed. It does not upload anything
// (gl::Renderer does) and never frees a set (make a new Materials for that).
//
//   splatfx::Materials mat(splatfx::Footprint{});
//   auto fireSet = mat.addTextureSet(splatfx::TextureSet::turbulence({}));
//   auto fireLut = mat.addColorTable(splatfx::ColorTable::fire());
//
// Storage: layers are kept as RGBA float (layerSize^2 * 16 bytes each, 16 KiB
// at the default 32), once per distinct set: the reference renderer and the
// GL upload (which may upsample before rounding to RGBA8) read the floats, so
// storing them rounded would change what both sample.
//
// Threading: a plain value; changes bump version() so renderers re-upload.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "splatfx/color_table.hpp"
#include "splatfx/footprint.hpp"
#include "splatfx/result.hpp"
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
    // resamples it to layerSize, and appends it; returns the set's id. When
    // the windowed, resampled layers and colour flag equal (bit for bit) a
    // registered set's, returns that set's id and adds nothing.
    // Expects a non-empty set.
    std::uint32_t addTextureSet(const TextureSet& set);
    // As above, and binds `key` (any string naming the content, e.g. the
    // parameters that generate it or a folder path) to the id, so a later
    // findTextureSet(key) finds the set without building it again. Returns
    // the existing id when the key is already bound to this content; an error
    // (adding nothing) when the key is empty or bound to different content.
    Result<std::uint32_t> addTextureSet(const TextureSet& set, const std::string& key);
    // The id bound to `key`, if any.
    std::optional<std::uint32_t> findTextureSet(const std::string& key) const;

    // Appends a row; returns its id. A table whose entries equal (bit for
    // bit) a registered table's returns that table's id and adds nothing.
    std::uint32_t addColorTable(const ColorTable& table);
    // Keyed, with the same rules as the keyed addTextureSet.
    Result<std::uint32_t> addColorTable(const ColorTable& table, const std::string& key);
    std::optional<std::uint32_t> findColorTable(const std::string& key) const;

    // An error when the layers exceed `maxLayers` (a renderer's limit, e.g.
    // GL_MAX_ARRAY_TEXTURE_LAYERS): it names the largest sets (id, key, layers)
    // and what to do. GL-free, so hosts can check before creating a renderer.
    Status checkLayerLimit(std::uint32_t maxLayers) const;

    const Footprint& footprint() const { return mFootprint; }
    int layerSize() const { return mDesc.layerSize; }
    int colorTableSize() const { return mDesc.colorTableSize; }
    std::uint32_t layerCount() const { return static_cast<std::uint32_t>(mLayers.size()); }
    std::uint32_t colorTableCount() const { return static_cast<std::uint32_t>(mTables.size()); }
    const SetRange& set(std::uint32_t id) const { return mSets.at(id); }
    std::uint32_t setCount() const { return static_cast<std::uint32_t>(mSets.size()); }
    const ColorTable& colorTable(std::uint32_t id) const { return mTables.at(id); }
    // The first key set `id` / table `id` was registered under; empty if none.
    const std::string& setKey(std::uint32_t id) const { return mSetKeys.at(id); }
    const std::string& colorTableKey(std::uint32_t id) const { return mTableKeys.at(id); }
    // Bytes of float texels held (layers and colour rows): what registering
    // by content saves.
    std::size_t texelBytes() const;

    // RGBA float, layerSize^2 texels, row-major: what the GPU samples.
    const std::vector<float>& layer(std::uint32_t index) const { return mLayers.at(index); }
    // colorTableSize RGBA entries for row id.
    const std::vector<glm::vec4>& colorRow(std::uint32_t id) const { return mRows.at(id); }

    std::uint64_t version() const { return mVersion; }

private:
    // Finds a registered set with exactly these (windowed, resampled) layers.
    std::optional<std::uint32_t> findSetContent(const TextureSet& w, std::uint64_t hash) const;
    std::uint32_t appendSet(TextureSet&& w, std::uint64_t hash, const std::string& key);
    std::optional<std::uint32_t> findTableContent(const ColorTable& t, std::uint64_t hash) const;

    Footprint mFootprint;
    MaterialsDesc mDesc;
    std::vector<std::vector<float>> mLayers;
    std::vector<SetRange> mSets;
    std::vector<std::string> mSetKeys;
    std::vector<ColorTable> mTables;
    std::vector<std::string> mTableKeys;
    std::vector<std::vector<glm::vec4>> mRows;
    // Content hash -> ids with that hash (equal hashes are compared in full).
    std::unordered_multimap<std::uint64_t, std::uint32_t> mSetsByContent, mTablesByContent;
    std::unordered_map<std::string, std::uint32_t> mSetsByKey, mTablesByKey;
    std::uint64_t mVersion = 1;
};

} // namespace splatfx
