// GL texture formats for the backend's public precision choices (private).
#pragma once

#include <epoxy/gl.h>

#include "splatfx/gl/framebuffer.hpp"

namespace splatfx::gl::detail {

// The colour attachment format for a Precision: Framebuffer's colour and
// ScaledRenderer's reduced-resolution target share it.
inline GLenum colorFormat(Precision precision) {
    switch (precision) {
    case Precision::U8: return GL_RGBA8;
    case Precision::F16: return GL_RGBA16F;
    case Precision::F32: return GL_RGBA32F;
    }
    return GL_RGBA8;
}

} // namespace splatfx::gl::detail
