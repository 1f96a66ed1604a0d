// Object dynamics: keyframed and procedural poses (King et al. 1999, sec. 3.1).
#include "splatfx/motion.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

namespace splatfx {
namespace {

constexpr double kTwoPi = 6.283185307179586;

bool finite3(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

float ease(Easing e, float u) {
    switch (e) {
    case Easing::Linear: return u;
    case Easing::Smooth: return u * u * (3.0f - 2.0f * u);
    case Easing::Step: return u >= 1.0f ? 1.0f : 0.0f;
    }
    return u;
}

Pose lerpPose(const Pose& a, const Pose& b, float u) {
    Pose p;
    p.position = glm::mix(a.position, b.position, u);
    p.rotation = glm::slerp(a.rotation, b.rotation, u);
    p.scale = glm::mix(a.scale, b.scale, u);
    p.opacity = a.opacity + (b.opacity - a.opacity) * u;
    p.growth = a.growth + (b.growth - a.growth) * u;
    return p;
}

glm::vec3 spinAxis(const ProceduralMotion& m) {
    const float len = glm::length(m.spinAxis);
    return len > 0.0f ? m.spinAxis / len : glm::vec3(0, 1, 0);
}

bool sameRotation(const glm::quat& a, const glm::quat& b) {
    // q and -q are the same rotation.
    return (a.w == b.w && a.x == b.x && a.y == b.y && a.z == b.z) || (a.w == -b.w && a.x == -b.x && a.y == -b.y && a.z == -b.z);
}

} // namespace

glm::mat4 Pose::matrix() const {
    glm::mat4 m = glm::translate(glm::mat4(1.0f), position);
    m = m * glm::mat4_cast(glm::normalize(rotation));
    return glm::scale(m, scale);
}

Motion::Motion(std::vector<Keyframe> keys, const ProceduralMotion& procedural) : mKeys(std::move(keys)), mProc(procedural) {
#ifndef NDEBUG
    Result<Motion> checked = create(mKeys, mProc);
    assert(checked.ok() && "Motion: invalid keyframes (call Motion::create for the message)");
#endif
}

Result<Motion> Motion::create(std::vector<Keyframe> keys, const ProceduralMotion& p) {
    for (size_t i = 0; i < keys.size(); ++i) {
        const Keyframe& k = keys[i];
        const std::string at = "keyframe " + std::to_string(i) + ": ";
        if (!std::isfinite(k.timeSec)) return makeError(at + "timeSec is not finite");
        if (i > 0 && !(k.timeSec > keys[i - 1].timeSec))
            return makeError(at + "timeSec " + std::to_string(k.timeSec) + " must be greater than the previous key's " +
                             std::to_string(keys[i - 1].timeSec));
        if (!finite3(k.pose.position)) return makeError(at + "pose.position is not finite");
        const glm::quat& q = k.pose.rotation;
        const float qn = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
        if (!std::isfinite(qn) || qn < 1e-12f) return makeError(at + "pose.rotation must be a finite, non-zero quaternion");
        if (!finite3(k.pose.scale) || k.pose.scale.x <= 0.0f || k.pose.scale.y <= 0.0f || k.pose.scale.z <= 0.0f)
            return makeError(at + "pose.scale must be positive and finite on every axis");
        if (!std::isfinite(k.pose.opacity) || k.pose.opacity < 0.0f)
            return makeError(at + "pose.opacity must be finite and >= 0, got " + std::to_string(k.pose.opacity));
        if (!std::isfinite(k.pose.growth) || k.pose.growth < 0.0f || k.pose.growth > 1.0f)
            return makeError(at + "pose.growth must be in [0, 1], got " + std::to_string(k.pose.growth));
    }
    if (!finite3(p.velocity) || !finite3(p.spinAxis) || !std::isfinite(p.spinRadPerSec) || !finite3(p.bobAmplitude) || !std::isfinite(p.bobHz) ||
        !std::isfinite(p.bobPhaseRad))
        return makeError("procedural motion: every field must be finite");
    for (Keyframe& k : keys) k.pose.rotation = glm::normalize(k.pose.rotation);
    Motion m;
    m.mKeys = std::move(keys);
    m.mProc = p;
    return m;
}

Pose Motion::keyed(double t) const {
    if (mKeys.empty()) return Pose{};
    if (t <= mKeys.front().timeSec) return mKeys.front().pose;
    if (t >= mKeys.back().timeSec) return mKeys.back().pose;
    // First key strictly after t.
    const auto it = std::upper_bound(mKeys.begin(), mKeys.end(), t, [](double v, const Keyframe& k) { return v < k.timeSec; });
    const Keyframe& b = *it;
    const Keyframe& a = *(it - 1);
    const float u = float((t - a.timeSec) / (b.timeSec - a.timeSec));
    return lerpPose(a.pose, b.pose, ease(a.easing, std::clamp(u, 0.0f, 1.0f)));
}

Pose Motion::sample(double t) const {
    Pose p = keyed(t);
    p.position += mProc.velocity * float(t);
    if (mProc.bobHz != 0.0f) p.position += mProc.bobAmplitude * float(std::sin(kTwoPi * mProc.bobHz * t + mProc.bobPhaseRad));
    if (mProc.spinRadPerSec != 0.0f) p.rotation = glm::angleAxis(float(std::fmod(mProc.spinRadPerSec * t, kTwoPi)), spinAxis(mProc)) * p.rotation;
    return p;
}

bool Motion::isStatic() const {
    if (mProc.velocity != glm::vec3(0.0f) || mProc.spinRadPerSec != 0.0f) return false;
    if (mProc.bobHz != 0.0f && mProc.bobAmplitude != glm::vec3(0.0f)) return false;
    for (size_t i = 1; i < mKeys.size(); ++i) {
        const Pose &a = mKeys[i - 1].pose, &b = mKeys[i].pose;
        if (a.position != b.position || !sameRotation(a.rotation, b.rotation) || a.scale != b.scale || a.opacity != b.opacity || a.growth != b.growth)
            return false;
    }
    return true;
}

float Motion::maxScale(double t0, double t1) const {
    if (t1 < t0) std::swap(t0, t1);
    auto big = [](const Pose& p) { return std::max({std::abs(p.scale.x), std::abs(p.scale.y), std::abs(p.scale.z)}); };
    float s = std::max(big(keyed(t0)), big(keyed(t1)));
    for (const Keyframe& k : mKeys)
        if (k.timeSec > t0 && k.timeSec < t1) s = std::max(s, big(k.pose));
    return s;
}

Aabb Motion::sweep(const Aabb& box, double t0, double t1) const {
    if (box.empty()) return {};
    if (t1 < t0) std::swap(t0, t1);
    // Breakpoints: the interval ends and every key inside it.
    std::vector<double> ts{t0};
    for (const Keyframe& k : mKeys)
        if (k.timeSec > t0 && k.timeSec < t1) ts.push_back(k.timeSec);
    ts.push_back(t1);

    float radius = 0.0f; // object-space distance of the farthest box point from the origin
    for (int c = 0; c < 8; ++c) radius = std::max(radius, glm::length(box.corner(c)));

    Aabb keyedPart;
    for (size_t s = 0; s + 1 < ts.size(); ++s) {
        const Pose a = keyed(ts[s]), b = keyed(ts[s + 1]);
        if (sameRotation(a.rotation, b.rotation)) {
            // Constant rotation: position + R (scale * x) is affine in the eased
            // parameter, so the extremes are at the segment ends.
            for (const Pose* p : {&a, &b}) {
                glm::mat4 m = p->matrix();
                for (int c = 0; c < 8; ++c) keyedPart.extend(glm::vec3(m * glm::vec4(box.corner(c), 1.0f)));
            }
        } else {
            const float r = radius * std::max(maxScale(ts[s], ts[s + 1]), 0.0f);
            keyedPart.extend(Aabb{a.position, a.position}.expanded(r));
            keyedPart.extend(Aabb{b.position, b.position}.expanded(r));
        }
    }
    if (mProc.spinRadPerSec != 0.0f) {
        // Spin turns the keyed frame about the object's position, so every point
        // stays within radius * scale of the keyed position (affine per segment).
        Aabb centres;
        for (double t : ts) centres.extend(keyed(t).position);
        keyedPart = centres.expanded(radius * std::max(maxScale(t0, t1), 0.0f));
    }
    // Procedural translation: velocity * t is linear (ends bound it), the bob is
    // bounded by its amplitude.
    Aabb translation{glm::min(mProc.velocity * float(t0), mProc.velocity * float(t1)),
                     glm::max(mProc.velocity * float(t0), mProc.velocity * float(t1))};
    if (mProc.bobHz != 0.0f) {
        const glm::vec3 amp = glm::abs(mProc.bobAmplitude);
        translation = translation.plus(Aabb{-amp, amp});
    }
    return keyedPart.plus(translation);
}

float growthFactor(float distance, float maxDistance, float growth, float softness) {
    // Present while distance < growth * (maxDistance + softness): growth 0 shows
    // nothing, growth 1 shows every voxel fully.
    const float s = std::max(softness, 1e-6f);
    const float front = std::clamp(growth, 0.0f, 1.0f) * (maxDistance + s);
    return std::clamp((front - distance) / s, 0.0f, 1.0f);
}

} // namespace splatfx
