// The host's transparent surfaces for the fragment-list tests: panes drawn
// with the docs/integration.md snippet (its two ```glsl blocks between the
// transparent-snippet markers, transparentGlsl() in place of its marker), so
// the documented snippet is what the tests compile and draw.
#pragma once

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "gl_fixture.hpp"
#include "splatfx/camera.hpp"
#include "splatfx/gl/program.hpp"
#include "splatfx/transparency.hpp"

namespace splatfx::test {

// The two ```glsl blocks between the transparent-snippet markers of docs/integration.md.
inline std::vector<std::string> snippetShaders() {
    std::ifstream in(sourcePath("docs/integration.md"));
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string doc = ss.str();
    const std::size_t a = doc.find("<!-- transparent-snippet-begin"), b = doc.find("<!-- transparent-snippet-end");
    std::vector<std::string> out;
    if (a == std::string::npos || b == std::string::npos) return out;
    std::size_t p = a;
    while ((p = doc.find("```glsl\n", p)) != std::string::npos && p < b) {
        const std::size_t start = p + 8, end = doc.find("```", start);
        out.push_back(doc.substr(start, end - start));
        p = end + 3;
    }
    return out;
}

// A pane: the square |x - centre.x|, |y - centre.y| <= half at world z, one
// premultiplied colour. The default covers the campfire camera's view from
// z = 5 to z = -5 while its corners stay near the viewport: far outside, the
// rasterizer clips the two triangles separately and their shared edge may
// gain or lose pixels, which is not what these tests measure.
struct Pane {
    float z = 0.0f;
    glm::vec4 premultiplied{0.0f};
    float half = 12.0f;
    glm::vec2 centre{0.0f, 4.6f};
};

// The host's transparent geometry, drawn with the integration snippet.
class Glass {
public:
    Glass() {
        std::vector<std::string> sh = snippetShaders();
        if (sh.size() != 2) {
            mError = "docs/integration.md must hold the vertex and fragment snippet between the transparent-snippet markers";
            return;
        }
        std::string& frag = sh[1];
        const std::size_t marker = frag.find("// SPLATFX_TRANSPARENT");
        if (marker == std::string::npos) {
            mError = "no // SPLATFX_TRANSPARENT marker in the snippet";
            return;
        }
        frag.replace(marker, frag.find('\n', marker) - marker, transparentGlsl());
        auto prog = gl::linkProgram({sh[0].c_str()}, {frag.c_str()}, "integration snippet (transparent)");
        if (!prog) {
            mError = prog.error();
            return;
        }
        mProgram = *prog;
        glCreateVertexArrays(1, &mVao);
        glCreateBuffers(1, &mVbo);
        glNamedBufferStorage(mVbo, 6 * 3 * sizeof(float), nullptr, GL_DYNAMIC_STORAGE_BIT);
        glVertexArrayVertexBuffer(mVao, 0, mVbo, 0, 3 * sizeof(float));
        glVertexArrayAttribFormat(mVao, 0, 3, GL_FLOAT, GL_FALSE, 0);
        glVertexArrayAttribBinding(mVao, 0, 0);
        glEnableVertexArrayAttrib(mVao, 0);
    }
    ~Glass() {
        if (mProgram) glDeleteProgram(mProgram);
        glDeleteVertexArrays(1, &mVao);
        glDeleteBuffers(1, &mVbo);
    }
    const std::string& error() const { return mError; }
    void draw(const std::vector<Pane>& panes, const Camera& camera) const {
        const glm::mat4 vp = camera.proj * camera.view;
        glUseProgram(mProgram);
        glUniformMatrix4fv(glGetUniformLocation(mProgram, "uViewProj"), 1, GL_FALSE, glm::value_ptr(vp));
        glBindVertexArray(mVao);
        for (const Pane& p : panes) {
            const float h = p.half, cx = p.centre.x, cy = p.centre.y;
            const float v[18] = {cx - h, cy - h, p.z, cx + h, cy - h, p.z, cx + h, cy + h, p.z,
                                 cx - h, cy - h, p.z, cx + h, cy + h, p.z, cx - h, cy + h, p.z};
            glNamedBufferSubData(mVbo, 0, sizeof(v), v);
            glUniform4fv(glGetUniformLocation(mProgram, "uPremultiplied"), 1, glm::value_ptr(p.premultiplied));
            glDrawArrays(GL_TRIANGLES, 0, 6);
        }
    }

private:
    std::string mError;
    GLuint mProgram = 0, mVao = 0, mVbo = 0;
};

} // namespace splatfx::test
