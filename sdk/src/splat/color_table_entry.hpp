// Private to the SDK: a colour-table entry read exactly as the splat builder
// reads it (splats.cpp), for code that must agree with the drawn splats (the
// density a light sees, the lit splat colours).
#pragma once

#include <algorithm>
#include <cstddef>

#include <glm/glm.hpp>

#include "splatfx/color_table.hpp"

namespace splatfx::detail {

// The entry at t, clamped to [0, 1] like the builder's; no table (or one of
// fewer than two entries) reads white, fully opaque.
inline glm::vec4 colorTableEntry(const ColorTable* table, float t) {
    if (!table || table->entries.size() < 2) return glm::vec4(1.0f);
    const std::vector<glm::vec4>& e = table->entries;
    const float f = std::clamp(t, 0.0f, 1.0f) * float(e.size() - 1);
    const std::size_t i = std::min(std::size_t(f), e.size() - 2);
    return glm::clamp(glm::mix(e[i], e[i + 1], f - float(i)), glm::vec4(0.0f), glm::vec4(1.0f));
}

} // namespace splatfx::detail
