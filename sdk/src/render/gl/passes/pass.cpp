#include "pass.hpp"

#include <algorithm>

namespace splatfx::gl::detail {

std::pair<std::size_t, std::size_t> StepContext::range(const PlanStep& step) const {
    const std::size_t n = frame.splats().size();
    const std::size_t behind = std::min(behindEnd, n), front = std::clamp(frontBegin, behind, n);
    switch (step.range) {
    case StepRange::Explicit: return {std::min(step.begin, n), std::min(step.end, n)};
    case StepRange::ListsBehind: return {0, behind};
    case StepRange::ListsBetween: return {behind, front};
    case StepRange::ListsFront: return {front, n};
    case StepRange::ListsBehindAndBetween: return {0, front};
    }
    return {0, 0};
}

} // namespace splatfx::gl::detail
