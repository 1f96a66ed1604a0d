// splatfx/splatfx.hpp: everything in the simulation side of the SDK, plus the GL backend.
// Contexts (EGL, GLFW) are in splatfx/context.hpp and the splatfx::context target.
#pragma once

#include "splatfx/camera.hpp"
#include "splatfx/color_table.hpp"
#include "splatfx/dynamics.hpp"
#include "splatfx/effect.hpp"
#include "splatfx/footprint.hpp"
#include "splatfx/gl/framebuffer.hpp"
#include "splatfx/gl/renderer.hpp"
#include "splatfx/gl/scaled_renderer.hpp"
#include "splatfx/grid.hpp"
#include "splatfx/image.hpp"
#include "splatfx/materials.hpp"
#include "splatfx/motion.hpp"
#include "splatfx/presets.hpp"
#include "splatfx/reference.hpp"
#include "splatfx/result.hpp"
#include "splatfx/scene.hpp"
#include "splatfx/scene_file.hpp"
#include "splatfx/solver.hpp"
#include "splatfx/splats.hpp"
#include "splatfx/texture_set.hpp"
