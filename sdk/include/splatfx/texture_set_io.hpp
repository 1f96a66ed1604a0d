// splatfx/texture_set_io.hpp: texture-set folders on disk (splatfx::io).
//
// A texture-set folder is manifest.json {"format": "splatfx-texture-set",
// "version": 1, "textures": ["t00.png", ...], "color": false, ...} plus the
// images, all the same square size (see splatfx/texture_set.hpp). Unknown
// manifest keys are kept for provenance. It does not window or resize: the
// set comes back as written (TextureSet::windowed does the rest).
//
//   auto set = splatfx::loadTextureSet("textures/fire8");
//   if (!set) return fail(set.error());
//   splatfx::saveTextureSet(*set, "out/fire8-copy");
//
// Threading: free functions; safe from any thread on distinct folders.
#pragma once

#include <string>

#include "splatfx/result.hpp"
#include "splatfx/texture_set.hpp"

namespace splatfx {

// Loads a texture-set folder. Manifest entries must name files inside the
// folder; errors name the file and the reason.
Result<TextureSet> loadTextureSet(const std::string& folder);

// Writes `set` as a texture-set folder atomically (a temporary folder, then a
// rename), with provenanceJson (a JSON object) kept in the manifest.
Status saveTextureSet(const TextureSet& set, const std::string& folder, const std::string& provenanceJson = "{}");

} // namespace splatfx
