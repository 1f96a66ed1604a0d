// Effect kind "smoke" (Fig. 9: presets::smoke, a solver plume).
#include "scenefile/kinds/solver_effect.hpp"

namespace splatfx::scenefile {

std::optional<Effect> readSmoke(Context& c, ObjectReader& o, const EffectCommon& e, const Placement& pl) {
    return readSolverEffect<presets::SmokeDesc>(c, o, e, pl, &presets::smoke);
}

} // namespace splatfx::scenefile
