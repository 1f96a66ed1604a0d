// Effect kind "fire" (Fig. 1, 3: presets::fire).
#include "scenefile/kinds/lattice_preset.hpp"

namespace splatfx::scenefile {

std::optional<Effect> readFire(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    return readLatticePreset<presets::FireDesc>(
        c, o, e, pl, [&](presets::FireDesc& d) { o.boolean("crossfade", d.crossfade); }, &presets::fire);
}

} // namespace splatfx::scenefile
