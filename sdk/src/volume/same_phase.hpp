// Private to the SDK: whether two phase functions are the same lobes (cloud.cpp and
// ground_fog_light.cpp relight only when the lighting they were lit with changed).
#pragma once

#include "splatfx/lighting.hpp"

namespace splatfx::detail {

inline bool samePhase(const PhaseFunction& a, const PhaseFunction& b) {
    if (a.lobeCount() != b.lobeCount()) return false;
    for (int i = 0; i < a.lobeCount(); ++i)
        if (a.lobe(i).g != b.lobe(i).g || a.lobe(i).weight != b.lobe(i).weight) return false;
    return true;
}

} // namespace splatfx::detail
