// Seeded 4D gradient noise (Perlin 1985, improved 2002 fade curve), private to texture sets.
#pragma once

#include <array>
#include <cstdint>

namespace splatfx::detail {

class Noise4 {
public:
    explicit Noise4(std::uint32_t seed);
    // Roughly in [-1, 1]; zero at lattice points.
    double operator()(double x, double y, double z, double w) const;

private:
    std::array<std::uint8_t, 512> mPerm{};
};

} // namespace splatfx::detail
