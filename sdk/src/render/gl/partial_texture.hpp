// The partial-integral table (Footprint::partialTable, issue 15) as a GL
// texture, for any pass that cuts splats at a depth (private to gl).
// partialGlsl(footprint, binding) is the matching GLSL lookup; the pass binds
// texture() to that unit before drawing.
#pragma once

#include <epoxy/gl.h>

#include <vector>

#include "splatfx/footprint.hpp"

namespace splatfx::gl::detail {

class PartialTexture {
public:
    PartialTexture() = default;
    PartialTexture(const PartialTexture&) = delete;
    PartialTexture& operator=(const PartialTexture&) = delete;
    ~PartialTexture();
    // (Re)uploads when the footprint's table differs from the last one
    // uploaded (size or contents); cheap otherwise.
    void update(const Footprint& footprint);
    GLuint texture() const { return mTexture; }

private:
    GLuint mTexture = 0;
    int mRows = 0, mCols = 0;
    std::vector<float> mUploaded;
};

} // namespace splatfx::gl::detail
