// Effect kind "dust" (Fig. 4: presets::dust, a settling solver cloud).
#include "scenefile/kinds/solver_effect.hpp"

namespace splatfx::scenefile {

std::optional<Effect> readDust(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    return readSolverEffect<presets::DustDesc>(c, o, e, pl, &presets::dust);
}

} // namespace splatfx::scenefile
