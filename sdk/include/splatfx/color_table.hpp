// splatfx/color_table.hpp: 1D colour lookup tables.
//
// King et al. 1999, sec. 2 step 4: each splat's colour comes from a lookup
// table indexed by the voxel's colour coordinate; for fire the coordinate is
// the normalized height, a cheap stand-in for temperature. Entries are RGBA
// with straight (not premultiplied) alpha; alpha scales the voxel's opacity,
// so a table can fade an effect out (smoke thinning at the top).
//
//   auto fire = splatfx::ColorTable::fire();
//   glm::vec4 c = fire.sample(0.3f);
//
// Threading: a plain value.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace splatfx {

class ColorTable {
public:
    std::vector<glm::vec4> entries; // at least 2; entries[0] at t = 0, back() at t = 1

    // Linear interpolation; t clamped to [0, 1]; NaN reads entry 0.
    glm::vec4 sample(float t) const;
    // Resamples to n evenly spaced entries (what the GPU gets).
    std::vector<glm::vec4> resampled(int n) const;

    // Piecewise-linear table through (t, colour) stops, t increasing.
    static ColorTable gradient(const std::vector<std::pair<float, glm::vec4>>& stops, int size = 256);
    static ColorTable fire();  // white-yellow base, orange, red, dark fading tips
    static ColorTable smoke(); // grey, thinning with height
    static ColorTable steam(); // white, thinning with height
    static ColorTable dust();  // sandy brown
    static ColorTable constant(glm::vec4 rgba);
};

} // namespace splatfx
