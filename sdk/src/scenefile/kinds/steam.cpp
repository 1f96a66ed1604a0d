// Effect kind "steam" (Fig. 5: presets::steam).
#include "scenefile/kinds/lattice_preset.hpp"

namespace splatfx::scenefile {

std::optional<Effect> readSteam(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    return readLatticePreset<presets::SteamDesc>(
        c, o, e, pl, [](presets::SteamDesc&) {}, &presets::steam);
}

} // namespace splatfx::scenefile
