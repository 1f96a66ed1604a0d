// The GLSL files of the GL backend (sdk/src/render/gl/glsl), embedded at build
// time (cmake/embed_glsl.cmake), and the small preprocessor that resolves
// their named includes. GL-free text: the core's GLSL for hosts (fogGlsl,
// partialGlsl, shadowGlsl, transparentGlsl) and the GL passes' programs are
// built from the same files.
//
// Includes: a line `#include "name.glsl"` (leading blanks allowed) is
// replaced by that file's expanded text; each file is included at most once
// per expansion (the second include of a name expands to nothing), so shared
// declarations may be included from several files. Includes are resolved
// before GLSL's own preprocessor runs: an include inside `#if FOG` is
// inlined and then skipped by the compiler when FOG is 0.
// An override replaces a file's text for one expansion: how the generated
// parts (a fog's terms, a footprint's constants) take the place of
// fog.glsl and partial.glsl.
//
//   auto text = splatfx::glsl::expand("splat.frag", {{"fog.glsl", fogSource}});
//
// Threading: pure functions; any thread.
#pragma once

#include <cstddef>
#include <initializer_list>
#include <string>
#include <string_view>

#include "splatfx/result.hpp"

namespace splatfx::glsl {

namespace detail {
struct EmbeddedFile {
    const char* name; // file name under render/gl/glsl, e.g. "fog.glsl"
    const char* text;
};
extern const EmbeddedFile kEmbeddedFiles[]; // sorted by name
extern const std::size_t kEmbeddedFileCount;
} // namespace detail

// The embedded text of `name` (e.g. "shadow.glsl"), unexpanded; empty when no such file.
std::string_view file(std::string_view name);
// Whether `name` is an embedded file.
bool hasFile(std::string_view name);

struct Override {
    std::string_view name; // the file it replaces, e.g. "fog.glsl"
    std::string_view text; // inserted as is (not expanded)
};
// `name`'s text with its includes resolved. On failure (an unknown file or
// include) the message names the file and the line.
Result<std::string> expand(std::string_view name, std::initializer_list<Override> overrides = {});

// `text` with every whole-word occurrence of each `from` replaced by `to`
// (the generated includes' constants: partial.glsl's SPLATFX_PARTIAL_*).
std::string substitute(std::string text, std::initializer_list<std::pair<std::string_view, std::string_view>> words);

} // namespace splatfx::glsl
