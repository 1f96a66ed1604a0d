// What kind of OpenGL context is current on this thread (private to the GL backend).
#pragma once

namespace splatfx::gl::detail {

// Asks the EGL and GLX libraries already loaded in the process; a context can
// only be current if one of them made it so. Never loads a library itself,
// and never calls GL (which would abort inside the loader with no context).
bool contextIsCurrent();

// The context current on this thread (its EGLContext or GLXContext), or null:
// an identity to compare, so that GL objects made in one context are never
// used or deleted in another (names are per context).
const void* currentContext();

// Whether the current context renders on the CPU (Mesa's llvmpipe, softpipe,
// swrast), by its GL_RENDERER string. Needs a current context.
bool softwareRasterizer();

} // namespace splatfx::gl::detail
