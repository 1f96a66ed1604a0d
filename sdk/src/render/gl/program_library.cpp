// The program library (program_library.hpp).
#include "program_library.hpp"

#include <epoxy/gl.h>

#include "context_check.hpp"
#include "splatfx/gl/program.hpp"

namespace splatfx::gl::detail {

ProgramLibrary::~ProgramLibrary() {
    // The context may already be gone at exit; its programs died with it then.
    if (!contextIsCurrent()) return;
    for (const auto& [key, p] : mPrograms) destroy(p);
}

void ProgramLibrary::destroy(const Program& p) {
    if (p.id) glDeleteProgram(p.id);
}

Result<const ProgramLibrary::Program*> ProgramLibrary::get(const glsl::ProgramKey& key, const glsl::ProgramData& data) {
    if (auto it = mPrograms.find(key); it != mPrograms.end()) return &it->second;
    auto stages = glsl::programSources(key, data);
    if (!stages) return makeError(stages.error());
    const std::string what = glsl::variantName(key);
    std::vector<const char*> vertex, fragment, compute;
    for (const glsl::StageSource& s : *stages)
        (s.stage == glsl::Stage::Vertex ? vertex : s.stage == glsl::Stage::Fragment ? fragment : compute).push_back(s.text.c_str());
    auto linked = compute.empty() ? linkProgram({vertex.at(0)}, {fragment.at(0)}, what.c_str()) : linkComputeProgram({compute[0]}, what.c_str());
    if (!linked) return makeError(linked.error());
    Program p;
    p.id = *linked;
    for (const char* name : glsl::programDesc(key.id).uniforms) p.locations.push_back(glGetUniformLocation(p.id, name));
    return &mPrograms.emplace(key, std::move(p)).first->second;
}

} // namespace splatfx::gl::detail
