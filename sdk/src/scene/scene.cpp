#include "splatfx/scene.hpp"

#include <algorithm>
#include <cmath>

namespace splatfx {

EffectId Scene::add(Effect effect, EffectOptions options) {
    Entry e{std::move(effect), std::move(options), {}, 0.0};
    e.simulatedTo = e.effect.time();
    mEntries.push_back(std::move(e));
    mCounters.declared = mEntries.size();
    return EffectId(mEntries.size() - 1);
}

bool Scene::inFrustum(const Aabb& box, const Camera& camera) {
    if (box.empty()) return false;
    // Gribb & Hartmann planes; a box is outside if all 8 corners are behind one plane.
    const glm::mat4 vp = camera.proj * camera.view;
    for (int i = 0; i < 3; ++i)
        for (int sign = -1; sign <= 1; sign += 2) {
            const glm::vec4 plane = glm::vec4(vp[0][3], vp[1][3], vp[2][3], vp[3][3]) +
                                    float(sign) * glm::vec4(vp[0][i], vp[1][i], vp[2][i], vp[3][i]);
            // The corner farthest along the plane normal decides.
            const glm::vec3 p(plane.x >= 0 ? box.hi.x : box.lo.x, plane.y >= 0 ? box.hi.y : box.lo.y,
                              plane.z >= 0 ? box.hi.z : box.lo.z);
            if (glm::dot(glm::vec3(plane), p) + plane.w < 0.0f) return false;
        }
    return true;
}

bool Scene::alive(const Entry& e, double t) const {
    if (e.effect.isStateless()) {
        // Material is present unless the object's fade or growth is at zero now.
        const Pose pose = e.effect.desc().motion.sample(t);
        return pose.opacity > 0.0f && pose.growth > 0.0f;
    }
    const FluidSolver* s = e.effect.solver();
    for (const Emitter& em : s->emitters())
        if (em.desc.density > 0.0f && em.desc.rate > 0.0f) return true;
    return s->totalDensity() > e.options.deadDensity;
}

void Scene::bringUpToDate(Entry& e, double t, bool wasNeeded) {
    if (e.effect.isStateless()) {
        e.effect.update(t); // a pure function of time: nothing to catch up
        e.simulatedTo = t;
        return;
    }
    const double gap = t - e.simulatedTo;
    if (gap <= 0.0) return;
    // Seen last frame: ordinary steps. Returning from a gap: a bounded number
    // of coarse steps (the solver is unconditionally stable).
    if (!wasNeeded && e.status.framesNeeded > 0) ++e.status.catchUps;
    const int n = std::clamp(int(std::ceil(gap / std::max(e.options.catchUpStepSec, 1e-6))), 1, std::max(e.options.maxCatchUpSteps, 1));
    for (int i = 0; i < n; ++i) e.effect.step(gap / n);
    e.simulatedTo = t;
}

void Scene::update(double timeSec, const Camera& camera) {
    const double previous = mUpdated ? std::min(mTime, timeSec) : timeSec;
    mTime = timeSec;
    mUpdated = true;
    mCounters.needed = mCounters.simulated = 0;
    const glm::vec3 eye = camera.eye();
    for (Entry& e : mEntries) {
        EffectStatus& s = e.status;
        const bool wasNeeded = s.needed;
        s.enabled = e.options.enabled;
        s.needed = false;
        if (!s.enabled) {
            ++s.framesSkipped;
            continue;
        }
        // Bounds over the interval since the last update: motion between frames is covered.
        s.bounds = e.effect.bounds(std::max(0.0, previous), timeSec);
        const glm::vec3 nearest = glm::clamp(eye, s.bounds.lo, s.bounds.hi);
        s.inRange = !s.bounds.empty() && glm::length(eye - nearest) <= e.options.rangeWorld;
        // Cheapest tests first: a hidden effect costs one bounds query and a frustum test.
        s.inView = s.inRange && inFrustum(s.bounds, camera);
        s.alive = s.inView && alive(e, timeSec);
        if (!s.alive) {
            ++s.framesSkipped;
            continue;
        }
        bringUpToDate(e, timeSec, wasNeeded);
        s.needed = true;
        ++s.framesNeeded;
        ++mCounters.needed;
        ++mCounters.simulated;
    }
}

std::size_t Scene::emit(SplatBuilder& builder, const Materials& materials, const EmitOptions& options) {
    std::size_t total = 0;
    for (Entry& e : mEntries) {
        const EmitOptions draw{.textured = e.options.draw.textured && options.textured,
                               .opacityScale = e.options.draw.opacityScale * options.opacityScale};
        e.status.splatsDrawn = e.status.needed ? e.effect.emit(builder, materials, draw) : 0;
        total += e.status.splatsDrawn;
    }
    mCounters.splats = total;
    return total;
}

void Scene::prepare(double timeSec, const Camera& camera, const Materials& materials, Frame& frame, const EmitOptions& options) {
    update(timeSec, camera);
    frame.begin(timeSec, camera);
    emit(frame.builder(), materials, options);
    frame.end();
    FrameCounters& c = frame.counters();
    c.declared = mCounters.declared;
    c.needed = mCounters.needed;
    c.simulated = mCounters.simulated;
    c.drawn = 0;
    for (const Entry& e : mEntries) c.drawn += e.status.splatsDrawn > 0 ? 1 : 0;
}

} // namespace splatfx
