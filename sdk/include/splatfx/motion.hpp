// splatfx/motion.hpp: object dynamics of a whole effect (keyframes + procedure).
//
// King et al. 1999, sec. 3.1: object dynamics are "large movements or
// deformations of the volume which change the perceived shape or location of
// the entire effect", done "procedurally (or explicitly) changing the coarse
// voxel grid". A Motion is a keyframe track of Poses (position, rotation,
// scale, an opacity multiplier and a growth fraction) plus a procedural part
// (constant velocity, spin, sinusoidal bob) added on top. It is a pure
// function of time, and it can bound where a box goes over a time interval
// (conservatively), which the scheduler uses for culling.
// It does not touch voxels (Effect applies a Pose to a grid) and does not
// simulate anything: see solver.hpp for the Eulerian part of sec. 3.1.
//
//   splatfx::Motion walk({{.timeSec = 0, .pose = {.position = {-5, 0, 0}}},
//                         {.timeSec = 4, .pose = {.position = {5, 0, 0}}}});
//   glm::mat4 m = walk.matrix(1.5);            // object to world at t = 1.5 s
//   splatfx::Aabb box = walk.sweep(localBox, 0.0, 4.0);
//
// Threading: a plain value; const member functions may be called from any thread.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "splatfx/result.hpp"

namespace splatfx {

// Axis-aligned box. Default-constructed boxes are empty (lo > hi).
struct Aabb {
    glm::vec3 lo{std::numeric_limits<float>::infinity()};
    glm::vec3 hi{-std::numeric_limits<float>::infinity()};

    bool empty() const { return !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z); }
    void extend(glm::vec3 p) { lo = glm::min(lo, p), hi = glm::max(hi, p); }
    void extend(const Aabb& b) {
        if (!b.empty()) extend(b.lo), extend(b.hi);
    }
    // Grown by r on every side (r >= 0).
    Aabb expanded(float r) const { return empty() ? *this : Aabb{lo - glm::vec3(r), hi + glm::vec3(r)}; }
    // Minkowski sum with another box (e.g. a translation range).
    Aabb plus(const Aabb& b) const { return empty() || b.empty() ? Aabb{} : Aabb{lo + b.lo, hi + b.hi}; }
    bool contains(glm::vec3 p) const { return glm::all(glm::greaterThanEqual(p, lo)) && glm::all(glm::lessThanEqual(p, hi)); }
    glm::vec3 corner(int i) const { return {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z}; }
};

// Where an object is at one moment, and how much of it there is.
struct Pose {
    glm::vec3 position{0.0f};       // world units; default origin
    glm::quat rotation{1, 0, 0, 0}; // unit quaternion (w, x, y, z); default identity
    glm::vec3 scale{1.0f};          // per axis, positive; default 1
    float opacity = 1.0f;           // multiplies every voxel's opacity (fades), >= 0; default 1
    float growth = 1.0f;            // fraction of the material present, [0, 1] (see GrowthDesc); default 1

    // Object to world: translate * rotate * scale.
    glm::mat4 matrix() const;
};

enum class Easing {
    Linear, // constant rate between keys (default)
    Smooth, // smoothstep: eases in and out of each key
    Step,   // holds the key until the next one
};

struct Keyframe {
    double timeSec = 0.0;           // seconds; keys must be strictly increasing; default 0
    Pose pose{};                    // default identity pose
    Easing easing = Easing::Linear; // of the segment from this key to the next; default Linear
};

// Procedural object motion, added on top of the keyframes:
//   position += velocity * t + bobAmplitude * sin(2 pi bobHz t + bobPhaseRad)
//   rotation  = angleAxis(spinRadPerSec * t, spinAxis) * keyed rotation
struct ProceduralMotion {
    glm::vec3 velocity{0.0f};     // world units / s; default 0
    glm::vec3 spinAxis{0, 1, 0};  // world axis, need not be unit; default +y
    float spinRadPerSec = 0.0f;   // radians / s; default 0
    glm::vec3 bobAmplitude{0.0f}; // world units per axis; default 0
    float bobHz = 0.0f;           // cycles / s; default 0
    float bobPhaseRad = 0.0f;     // radians; default 0
};

class Motion {
public:
    Motion() = default; // identity, at rest
    // Expects valid keys (see create); asserts otherwise.
    explicit Motion(std::vector<Keyframe> keys, const ProceduralMotion& procedural = {});
    // Checks keys: finite values, strictly increasing times, positive scales,
    // non-zero rotations, opacity >= 0, growth in [0, 1]. The message names
    // the key and field.
    static Result<Motion> create(std::vector<Keyframe> keys, const ProceduralMotion& procedural = {});

    // Pose at t (seconds; any finite value). Before the first key it holds the
    // first; after the last it holds the last; with no keys the identity pose.
    Pose sample(double timeSec) const;
    glm::mat4 matrix(double timeSec) const { return sample(timeSec).matrix(); }

    // A conservative world box of every point of objectBox (object space,
    // i.e. before this motion) over [t0, t1]. Exact where rotation is constant
    // on a segment: the motion is then affine in the segment's eased
    // parameter, so the corners at the segment ends bound it. Where rotation
    // varies it uses a sphere about the object origin.
    Aabb sweep(const Aabb& objectBox, double t0, double t1) const;
    // Largest scale component over [t0, t1] (scale is monotone in each segment).
    float maxScale(double t0, double t1) const;

    bool isStatic() const;
    const std::vector<Keyframe>& keys() const { return mKeys; }
    const ProceduralMotion& procedural() const { return mProc; }

private:
    Pose keyed(double t) const;
    std::vector<Keyframe> mKeys;
    ProceduralMotion mProc;
};

// How Pose::growth reveals material: a voxel is present when its distance
// from the origin is below growth * (largest distance + softness), with a
// soft edge. Fire spreading from its base: origin at the bottom centre.
struct GrowthDesc {
    glm::vec3 originCells{0.0f}; // lattice coordinates (cells) the material grows from; default cell (0, 0, 0)
    bool originAtCentre = true;  // ignore originCells and use the lattice centre of the base (y at its bottom); default true
    float softnessCells = 1.5f;  // width of the soft edge, cells, > 0; default 1.5
};

// Opacity factor in [0, 1] for a voxel distanceCells from the growth origin.
float growthFactor(float distanceCells, float maxDistanceCells, float growth, float softnessCells);

} // namespace splatfx
