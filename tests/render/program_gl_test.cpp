// gl::linkProgram: the one program helper of the backend, the samples, the
// bench and the tests. It must report compile AND link failures (one of the
// copies it replaced checked neither) and leave no program behind.
#include <string>

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include "gl_fixture.hpp"
#include "splatfx/gl/program.hpp"

namespace splatfx {
namespace {

class ProgramGL : public test::GLTest {};

const char* kVersion = "#version 450 core\n";
const char* kVertex = "void main() { gl_Position = vec4(0.0, 0.0, 0.0, 1.0); }\n";
const char* kFragment = "out vec4 o; void main() { o = vec4(1.0); }\n";

TEST_F(ProgramGL, LinksAValidProgramFromPieces) {
    auto p = gl::linkProgram({kVersion, kVertex}, {kVersion, "#define ONE 1.0\n", kFragment}, "valid");
    ASSERT_TRUE(p) << p.error();
    EXPECT_NE(*p, 0u);
    GLint linked = 0;
    glGetProgramiv(*p, GL_LINK_STATUS, &linked);
    EXPECT_EQ(linked, GL_TRUE);
    glDeleteProgram(*p);
}

TEST_F(ProgramGL, ACompileErrorNamesTheStage) {
    auto p = gl::linkProgram({kVersion, kVertex}, {kVersion, "out vec4 o; void main() { o = vec4(1.0) }\n"}, "broken pass");
    ASSERT_FALSE(p);
    EXPECT_EQ(p.error().rfind("broken pass fragment shader failed to compile: ", 0), 0u) << p.error();
}

TEST_F(ProgramGL, AComputeProgramBuildsAndItsErrorsNameTheStage) {
    auto good = gl::linkComputeProgram({kVersion, "layout(local_size_x = 1) in; void main() {}\n"}, "probe");
    ASSERT_TRUE(good) << good.error();
    glDeleteProgram(*good);
    auto bad = gl::linkComputeProgram({kVersion, "layout(local_size_x = 1) in; void main() { x = 1; }\n"}, "probe");
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().rfind("probe compute shader failed to compile: ", 0), 0u) << bad.error();
}

TEST_F(ProgramGL, ALinkErrorIsReportedToo) {
    // Both stages compile; linking fails because the fragment stage reads an
    // input no vertex output feeds (GLSL 4.50, sec. 4.3.4).
    auto p = gl::linkProgram({kVersion, kVertex}, {kVersion, "in vec4 vMissing; out vec4 o; void main() { o = vMissing; }\n"}, "mismatched pass");
    ASSERT_FALSE(p);
    EXPECT_EQ(p.error().rfind("mismatched pass program failed to link: ", 0), 0u) << p.error();
}

} // namespace
} // namespace splatfx
