// A header for package.core_declarations_can_fail: it declares a function
// that no library defines, as a core header once declared TextureSet::load
// (defined in splatfx::io). The check must report it.
#pragma once

namespace splatfx {

int probeDeclaredNowhere();
inline int probeDefinedInline() { return 1; } // has a body: not reported

} // namespace splatfx
