#include "splatfx/color_table.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace splatfx {

glm::vec4 ColorTable::sample(float t) const {
    assert(entries.size() >= 2 && "ColorTable needs at least two entries");
    if (!(t > 0.0f)) return entries.front(); // also NaN
    if (t >= 1.0f) return entries.back();
    const float f = t * float(entries.size() - 1);
    const size_t i = size_t(f);
    return glm::mix(entries[i], entries[std::min(i + 1, entries.size() - 1)], f - float(i));
}

std::vector<glm::vec4> ColorTable::resampled(int n) const {
    std::vector<glm::vec4> out(size_t(std::max(n, 2)));
    for (size_t i = 0; i < out.size(); ++i) out[i] = sample(float(i) / float(out.size() - 1));
    return out;
}

ColorTable ColorTable::gradient(const std::vector<std::pair<float, glm::vec4>>& stops, int size) {
    assert(!stops.empty() && size >= 2);
    ColorTable table;
    table.entries.resize(size_t(size));
    for (int i = 0; i < size; ++i) {
        const float t = float(i) / float(size - 1);
        glm::vec4 c = stops.front().second;
        for (size_t s = 0; s + 1 < stops.size(); ++s)
            if (t >= stops[s].first && t <= stops[s + 1].first) {
                const float span = std::max(stops[s + 1].first - stops[s].first, 1e-6f);
                c = glm::mix(stops[s].second, stops[s + 1].second, (t - stops[s].first) / span);
                break;
            }
        if (t > stops.back().first) c = stops.back().second;
        table.entries[size_t(i)] = c;
    }
    return table;
}

// Fire: hottest (lowest) voxels near white-yellow, cooling through orange and
// red; opacity falls at the tips so flames end softly.
ColorTable ColorTable::fire() {
    return gradient({{0.0f, {1.0f, 0.95f, 0.7f, 1.0f}},
                     {0.25f, {1.0f, 0.75f, 0.2f, 1.0f}},
                     {0.55f, {1.0f, 0.4f, 0.05f, 0.9f}},
                     {0.8f, {0.8f, 0.12f, 0.02f, 0.6f}},
                     {1.0f, {0.3f, 0.05f, 0.02f, 0.2f}}});
}

ColorTable ColorTable::smoke() {
    return gradient({{0.0f, {0.25f, 0.24f, 0.23f, 0.9f}}, {0.6f, {0.45f, 0.45f, 0.45f, 0.6f}}, {1.0f, {0.6f, 0.6f, 0.62f, 0.15f}}});
}

ColorTable ColorTable::steam() {
    return gradient({{0.0f, {0.95f, 0.95f, 0.97f, 0.8f}}, {0.7f, {0.9f, 0.92f, 0.95f, 0.4f}}, {1.0f, {0.9f, 0.92f, 0.95f, 0.0f}}});
}

ColorTable ColorTable::dust() { return gradient({{0.0f, {0.55f, 0.45f, 0.3f, 0.9f}}, {1.0f, {0.7f, 0.62f, 0.48f, 0.3f}}}); }

ColorTable ColorTable::constant(glm::vec4 rgba) { return gradient({{0.0f, rgba}, {1.0f, rgba}}, 2); }

} // namespace splatfx
