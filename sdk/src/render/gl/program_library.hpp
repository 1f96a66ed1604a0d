// The GL backend's program library: one cache of linked programs keyed by
// variant (glsl::ProgramKey: the program, its #define values, the generated
// includes' key), each compiled once from the embedded GLSL files
// (glsl/programs.hpp) with its uniform locations looked up once at link.
// A pass asks for a variant per draw and indexes its locations by the
// program's uniform enum (glsl::splat::ViewProj, ...): no string lookups per
// frame.
//
//   auto p = library.get({glsl::ProgramId::Tetra, {1, 0, 0}});
//   if (!p) return makeError(p.error());
//   glUseProgram((*p)->id);
//   glUniform1i((*p)->uniform(glsl::tetra::First), first);
//
// A gl::FrameRenderer's passes share one library (Programs); a bare Renderer
// or ScaledRenderer makes its own. Each program id belongs to one pass, and a
// pass releases only its own ids. It does not bind anything or own other GL
// state. Threading: the GL thread, with the context its programs belong to
// current.
#pragma once

#include <map>
#include <memory>
#include <vector>

#include "glsl/programs.hpp"
#include "splatfx/result.hpp"

namespace splatfx::gl::detail {

class ProgramLibrary {
public:
    struct Program {
        unsigned id = 0;            // the GL program
        std::vector<int> locations; // per ProgramDesc::uniforms entry; -1 where the variant has none
        int uniform(int u) const { return locations[std::size_t(u)]; }
    };

    ProgramLibrary() = default;
    ProgramLibrary(const ProgramLibrary&) = delete;
    ProgramLibrary& operator=(const ProgramLibrary&) = delete;
    ~ProgramLibrary(); // deletes the programs while their context is current

    // The program of `key`, compiled and linked on first use from `data`
    // (the generated includes key.dataKey stands for). The pointer stays
    // valid until release() drops the program. On failure the message names
    // the variant and carries the driver's log; the failure is not cached.
    Result<const Program*> get(const glsl::ProgramKey& key, const glsl::ProgramData& data = {});
    // Deletes every program of `id` that `drop` returns true for (e.g. the
    // fog variants of a fog structure no longer drawn).
    template <class Pred>
    void release(glsl::ProgramId id, Pred drop) {
        for (auto it = mPrograms.begin(); it != mPrograms.end();)
            if (it->first.id == id && drop(it->first)) {
                destroy(it->second);
                it = mPrograms.erase(it);
            } else {
                ++it;
            }
    }

private:
    static void destroy(const Program& p);
    std::map<glsl::ProgramKey, Program> mPrograms;
};

// The library shared by the passes of one frame renderer.
using Programs = std::shared_ptr<ProgramLibrary>;

} // namespace splatfx::gl::detail
