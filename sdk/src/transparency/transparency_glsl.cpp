// The transparent-surface include (transparency.hpp): transparent.glsl and
// the list layout it includes (render/gl/glsl), the same text the fragment
// lists' passes compile.
#include "splatfx/transparency.hpp"

#include <cassert>

#include "glsl/glsl_files.hpp"

namespace splatfx {

std::string transparentGlsl() {
    auto text = glsl::expand("transparent.glsl");
    assert(text && "transparent.glsl is embedded with the files it includes");
    return text ? *text : std::string();
}

} // namespace splatfx
