// The shadow include compiled by a GL driver, sampling an uploaded table, against the CPU look-up.
#include <cmath>
#include <string>
#include <vector>

#include <epoxy/gl.h>
#include <glm/gtc/type_ptr.hpp>

#include "gl_fixture.hpp"
#include "splatfx/lighting.hpp"
#include "test_scenes.hpp"

using namespace splatfx;

namespace {

GLuint compileCompute(const std::string& src, std::string& log) {
    auto p = gl::linkComputeProgram({src.c_str()}, "shadow include test");
    if (!p) return log = p.error(), 0u;
    return *p;
}

class ShadowGlsl : public test::GLTest {};

} // namespace

TEST_F(ShadowGlsl, IncludeCompilesAndMatchesTheCpuLookup) {
    Grid g = test::gaussianBlob(12, 0.2f, 0.8f);
    auto field = DensityField::fromGrid(g);
    ASSERT_TRUE(field);
    const glm::vec3 c = 0.5f * (field->boundsMin() + field->boundsMax());
    const Light lights[] = {Light::directional({0.3f, -1.0f, 0.2f}), Light::point(c + glm::vec3(0.2f, 0.3f, -0.1f)),
                            Light::point(c + glm::vec3(1.0f, 4.0f, 0.5f))};
    const std::string src = std::string("#version 450 core\nlayout(local_size_x = 64) in;\n") + shadowGlsl() +
                            "layout(std430, binding = 0) readonly buffer Points { vec4 points[]; };\n"
                            "layout(std430, binding = 1) writeonly buffer Results { float results[]; };\n"
                            "uniform uint uCount;\n"
                            "void main() { uint i = gl_GlobalInvocationID.x; if (i < uCount) results[i] = splatfx_shadow(points[i].xyz); }\n";
    std::string log;
    const GLuint prog = compileCompute(src, log);
    ASSERT_NE(prog, 0u) << log;

    // Points inside the gas, on a ground plane under it, beside it and above it.
    std::vector<glm::vec4> points;
    const glm::vec3 lo = field->boundsMin(), hi = field->boundsMax(), ext = hi - lo;
    for (int k = 0; k < 7; ++k)
        for (int j = 0; j < 7; ++j)
            for (int i = 0; i < 7; ++i) points.emplace_back(lo + ext * (glm::vec3(i, j, k) + 0.37f) / 6.5f, 1.0f);
    for (int j = 0; j < 9; ++j)
        for (int i = 0; i < 9; ++i) points.emplace_back(c + glm::vec3(float(i - 4) * 0.4f, -3.0f, float(j - 4) * 0.4f), 1.0f);
    points.emplace_back(c + glm::vec3(6.0f, 0.0f, 0.0f), 1.0f);
    points.emplace_back(c + glm::vec3(0.0f, 6.0f, 0.0f), 1.0f);
    const GLuint count = GLuint(points.size());

    GLuint buffers[2];
    glCreateBuffers(2, buffers);
    glNamedBufferStorage(buffers[0], GLsizeiptr(points.size() * sizeof(glm::vec4)), points.data(), 0);
    glNamedBufferStorage(buffers[1], GLsizeiptr(points.size() * sizeof(float)), nullptr, GL_MAP_READ_BIT);

    for (int li = 0; li < 3; ++li) {
        ShadowTable table({.dims = glm::ivec3(24, 20, 28)}); // unequal dims catch a swapped axis
        ASSERT_TRUE(table.update(*field, lights[li]));
        const glm::ivec3 n = table.dims();
        GLuint t = 0;
        glCreateTextures(GL_TEXTURE_3D, 1, &t);
        glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        for (GLenum w : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) glTextureParameteri(t, w, GL_CLAMP_TO_EDGE);
        glTextureStorage3D(t, 1, GL_R32F, n.x, n.y, n.z);
        glTextureSubImage3D(t, 0, 0, 0, 0, n.x, n.y, n.z, GL_RED, GL_FLOAT, table.data().data());
        glBindTextureUnit(0, t);
        glUseProgram(prog);
        glUniform1i(glGetUniformLocation(prog, "splatfx_shadowTable"), 0);
        glUniformMatrix4fv(glGetUniformLocation(prog, "splatfx_worldToTable"), 1, GL_FALSE, glm::value_ptr(table.worldToTable()));
        glUniform4fv(glGetUniformLocation(prog, "splatfx_shadowLight"), 1, glm::value_ptr(table.lightInTable()));
        glUniform1ui(glGetUniformLocation(prog, "uCount"), count);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buffers[0]);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, buffers[1]);
        glDispatchCompute((count + 63) / 64, 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        std::vector<float> gpu(count);
        glGetNamedBufferSubData(buffers[1], 0, GLsizeiptr(count * sizeof(float)), gpu.data());
        glDeleteTextures(1, &t);

        // GL lets the texture unit compute its filter weights with as few as
        // 8 fractional bits (the subtexel precision; llvmpipe uses 8), so a
        // trilinear sample may be off by up to 3 * 2^-8 of the largest step
        // between neighbouring nodes; exp2(-x) has slope at most ln 2; 1e-6
        // covers float rounding of the coordinates.
        const float tol = std::log(2.0f) * 3.0f / 256.0f * test::maxNeighbourStep(table) + 1e-6f;
        int shadowed = 0;
        for (GLuint i = 0; i < count; ++i) {
            const float cpu = table.transmittance(glm::vec3(points[i]));
            shadowed += cpu < 0.9f;
            ASSERT_NEAR(gpu[i], cpu, tol) << "light " << li << " point " << i << " (" << points[i].x << ", " << points[i].y << ", " << points[i].z
                                          << ")";
        }
        EXPECT_GT(shadowed, 20) << "light " << li; // the comparison covers real shadow, not only T = 1
    }
    glDeleteBuffers(2, buffers);
    glDeleteProgram(prog);
}
