// tools/scenehost/camera_path.hpp: evaluating a scene file's camera path (host side).
//
// Interpolates position, target and field of view between keys (linear or
// smoothstep per CameraPath::smooth), holding the first and last key
// outside their range, and builds a splatfx::Camera for a viewport.
//
//   splatfx::Camera cam = scenehost::evaluate(file.camera, timeSec, {640, 480});
//
// Threading: pure functions.
#pragma once

#include "splatfx/camera.hpp"
#include "splatfx/scene_file.hpp"

namespace scenehost {

// Expects at least one key.
splatfx::CameraKey sampleKey(const splatfx::CameraPath& path, double timeSec);
// `depth`: the host's depth convention, which the camera's projection follows.
splatfx::Camera evaluate(const splatfx::CameraPath& path, double timeSec, glm::ivec2 viewport, const splatfx::DepthConvention& depth = {});

} // namespace scenehost
