#include "splatfx/materials.hpp"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <numeric>

namespace splatfx {
namespace {

// FNV-1a over raw bytes: a content fingerprint only (equal hashes are
// confirmed by comparing the texels), so its quality affects speed, not results.
struct Fnv {
    std::uint64_t h = 1469598103934665603ull;
    void add(const void* data, std::size_t bytes) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ull;
    }
};

std::uint64_t hashSet(const TextureSet& w) {
    Fnv f;
    const std::uint32_t head[3] = {std::uint32_t(w.size), std::uint32_t(w.count()), w.color ? 1u : 0u};
    f.add(head, sizeof head);
    for (const auto& layer : w.layers) f.add(layer.data(), layer.size() * sizeof(float));
    return f.h;
}

std::uint64_t hashTable(const ColorTable& t) {
    Fnv f;
    const std::uint64_t n = t.entries.size();
    f.add(&n, sizeof n);
    f.add(t.entries.data(), t.entries.size() * sizeof(glm::vec4));
    return f.h;
}

bool sameBits(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

} // namespace

Materials::Materials(const Footprint& footprint, const MaterialsDesc& desc) : mFootprint(footprint), mDesc(desc) {
    assert(desc.layerSize >= 4 && "MaterialsDesc::layerSize must be at least 4");
    assert(desc.colorTableSize >= 2 && "MaterialsDesc::colorTableSize must be at least 2");
    // Layer 0: the plain footprint, for traditional splatting.
    mLayers.push_back(TextureSet::footprintOnly(mFootprint, desc.layerSize).layers[0]);
}

std::optional<std::uint32_t> Materials::findSetContent(const TextureSet& w, std::uint64_t hash) const {
    auto [b, e] = mSetsByContent.equal_range(hash);
    for (auto it = b; it != e; ++it) {
        const SetRange& r = mSets[it->second];
        if (r.count != std::uint32_t(w.count()) || r.color != w.color) continue;
        bool same = true;
        for (std::uint32_t i = 0; i < r.count && same; ++i) same = sameBits(mLayers[r.first + i], w.layers[i]);
        if (same) return it->second;
    }
    return std::nullopt;
}

std::uint32_t Materials::appendSet(TextureSet&& w, std::uint64_t hash, const std::string& key) {
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
    mSetKeys.push_back(key);
    const auto id = static_cast<std::uint32_t>(mSets.size() - 1);
    mSetsByContent.emplace(hash, id);
    ++mVersion;
    return id;
}

std::uint32_t Materials::addTextureSet(const TextureSet& set) {
    assert(set.count() > 0 && "Materials::addTextureSet: the set is empty");
    // Window at the set's own resolution, then resample: windowing first keeps
    // the footprint's edge exact for high-resolution photo patches. Compare
    // after both, so sets that differ only in what the GPU never sees share.
    TextureSet w = set.windowed(mFootprint).resized(mDesc.layerSize);
    const std::uint64_t hash = hashSet(w);
    if (auto id = findSetContent(w, hash)) return *id;
    return appendSet(std::move(w), hash, {});
}

Result<std::uint32_t> Materials::addTextureSet(const TextureSet& set, const std::string& key) {
    if (key.empty()) return makeError("Materials::addTextureSet: key is empty (use the unkeyed overload)");
    if (set.count() == 0) return makeError("Materials::addTextureSet: the set '" + key + "' is empty");
    TextureSet w = set.windowed(mFootprint).resized(mDesc.layerSize);
    const std::uint64_t hash = hashSet(w);
    const std::optional<std::uint32_t> same = findSetContent(w, hash);
    if (auto bound = mSetsByKey.find(key); bound != mSetsByKey.end()) {
        if (same && *same == bound->second) return bound->second;
        return makeError("Materials::addTextureSet: key '" + key + "' already names texture set " + std::to_string(bound->second) +
                         ", whose content differs; give different content a different key");
    }
    const std::uint32_t id = same ? *same : appendSet(std::move(w), hash, key);
    if (mSetKeys[id].empty()) mSetKeys[id] = key;
    mSetsByKey.emplace(key, id);
    return id;
}

std::optional<std::uint32_t> Materials::findTextureSet(const std::string& key) const {
    auto it = mSetsByKey.find(key);
    if (it == mSetsByKey.end()) return std::nullopt;
    return it->second;
}

std::optional<std::uint32_t> Materials::findTableContent(const ColorTable& t, std::uint64_t hash) const {
    auto [b, e] = mTablesByContent.equal_range(hash);
    for (auto it = b; it != e; ++it) {
        const ColorTable& o = mTables[it->second];
        if (o.entries.size() == t.entries.size() && std::memcmp(o.entries.data(), t.entries.data(), t.entries.size() * sizeof(glm::vec4)) == 0)
            return it->second;
    }
    return std::nullopt;
}

std::uint32_t Materials::addColorTable(const ColorTable& table) {
    const std::uint64_t hash = hashTable(table);
    if (auto id = findTableContent(table, hash)) return *id;
    mTables.push_back(table);
    mTableKeys.emplace_back();
    mRows.push_back(table.resampled(mDesc.colorTableSize));
    const auto id = static_cast<std::uint32_t>(mTables.size() - 1);
    mTablesByContent.emplace(hash, id);
    ++mVersion;
    return id;
}

Result<std::uint32_t> Materials::addColorTable(const ColorTable& table, const std::string& key) {
    if (key.empty()) return makeError("Materials::addColorTable: key is empty (use the unkeyed overload)");
    const std::optional<std::uint32_t> same = findTableContent(table, hashTable(table));
    if (auto bound = mTablesByKey.find(key); bound != mTablesByKey.end()) {
        if (same && *same == bound->second) return bound->second;
        return makeError("Materials::addColorTable: key '" + key + "' already names colour table " + std::to_string(bound->second) +
                         ", whose entries differ; give different content a different key");
    }
    const std::uint32_t id = same ? *same : addColorTable(table);
    if (mTableKeys[id].empty()) mTableKeys[id] = key;
    mTablesByKey.emplace(key, id);
    return id;
}

std::optional<std::uint32_t> Materials::findColorTable(const std::string& key) const {
    auto it = mTablesByKey.find(key);
    if (it == mTablesByKey.end()) return std::nullopt;
    return it->second;
}

std::size_t Materials::texelBytes() const {
    std::size_t bytes = 0;
    for (const auto& l : mLayers) bytes += l.size() * sizeof(float);
    for (const auto& r : mRows) bytes += r.size() * sizeof(glm::vec4);
    return bytes;
}

Status Materials::checkLayerLimit(std::uint32_t maxLayers) const {
    if (layerCount() <= maxLayers) return {};
    // Name the largest sets first: those are the ones worth sharing or trimming.
    std::vector<std::uint32_t> order(mSets.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return mSets[a].count > mSets[b].count; });
    constexpr std::size_t kNamed = 8; // enough to see the pattern; the rest are summed
    std::string msg = "materials hold " + std::to_string(layerCount()) + " texture layers (the footprint and " + std::to_string(mSets.size()) +
                      " distinct texture sets); this renderer allows " + std::to_string(maxLayers) + ". Largest sets:";
    std::uint64_t rest = 0;
    for (std::size_t i = 0; i < order.size(); ++i) {
        const SetRange& r = mSets[order[i]];
        const std::string& key = mSetKeys[order[i]];
        if (i < kNamed) {
            msg += " set " + std::to_string(order[i]) + " (" + (key.empty() ? std::string("unkeyed") : "'" + key + "'") + ") " +
                   std::to_string(r.count) + " layers;";
        } else {
            rest += r.count;
        }
    }
    if (order.size() > kNamed) msg += " and " + std::to_string(order.size() - kNamed) + " more sets with " + std::to_string(rest) + " layers.";
    msg += " Equal sets are registered once, so share them: give presets the same textureSeed and texture parameters, "
           "reuse one set id across effects, use fewer textures per set (textureCount), or split the level across several Materials (one renderer "
           "each).";
    return makeError(msg);
}

} // namespace splatfx
