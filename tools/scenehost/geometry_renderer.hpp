// tools/scenehost/geometry_renderer.hpp: draws a scene file's geometry (host side).
//
// A tiny OpenGL 4.5 renderer for the ground plane, boxes, cylinders, spheres
// and meshes of a scene file: one program (two-sided Lambert with a little
// ambient light, depth test and depth writes on), one vertex array per
// object. Its surface shader includes the SDK's shadowGlsl(): with the
// shadow binding of gl::FrameRenderer (GeometryLighting::shadow), smoke
// darkens the ground and the objects under it, and the frame's fires
// (EffectOptions::emitsLight) light them and the glass
// (splatfx_emittedIrradiance, albedo x E / pi). Drawn before the splats, its depth buffer is what makes the splats
// depth-correct (a cow inside the fire is partly hidden by it, and hides the
// part behind it). Meshes are loaded once, by path, through mesh.hpp.
// Not part of the SDK (it is the host's job to draw its own scene).
//
//   auto geo = scenehost::GeometryRenderer::create(file.geometry);  // GL context current
//   geo->draw(timeSec, camera);   // after clearing, before the splats
//
// GL state: draw() leaves depth test on (LESS), depth writes on, blending
// off, and unbinds its program and vertex array.
// Threading: the GL thread only. Move-only.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "mesh.hpp"
#include "splatfx/camera.hpp"
#include "splatfx/gl/frame_renderer.hpp"
#include "splatfx/result.hpp"
#include "splatfx/scene_file.hpp"

namespace scenehost {

struct GeometryStats {
    std::size_t objects = 0;   // objects drawn (Empty ones are not)
    std::size_t triangles = 0; // triangles drawn
};

// One light the geometry is lit by. Lambertian, no distance falloff (the
// host's look: a light's colour times min(intensity, 1) for a sun, its colour
// for a point or spot light), inside a spot's cone only.
struct GeometryLight {
    glm::vec4 light{0.4f, 1.0f, 0.6f, 0.0f}; // direction towards the light (w = 0) or position (w = 1); default a sun
    glm::vec3 color{1.0f};                   // default white
    int shadowLight = 0;                     // splatfx_shadowTo's index (the scene light); -1: unshadowed
    glm::vec3 spotAxis{0.0f};                // spot: the direction it shines; zero: not a spot
    float cosInner = 1.0f, cosOuter = -1.0f; // spot: full light within the inner half-angle, none beyond the outer
};
inline constexpr int kMaxGeometryLights = 8;

// The lights the geometry is lit by, and the gas's shadows on it: each light
// darkened by its own shadow (splatfx_shadowTo).
struct GeometryLighting {
    std::array<GeometryLight, kMaxGeometryLights> lights{}; // the first lightCount are used
    int lightCount = 1;                                      // [0, kMaxGeometryLights]; default 1 (a sun)
    splatfx::gl::ShadowBinding shadow{};                     // FrameRenderer::shadowBinding(); default none (unshadowed)
    // Biri et al.'s buffer method (sec. 4.3): the opaque objects fog themselves,
    // the transmittance evaluated per vertex (at draw()'s time) and interpolated,
    // instead of the frame renderer's per-pixel pass (turn that off: fogHost).
    // Default none.
    const splatfx::Fog* vertexFog = nullptr;
};

class GeometryRenderer {
public:
    // Loads meshes and uploads every object. Errors name the object and file.
    // Mesh files are checked against `budgets` (meshFileBytes, meshElements) before they are read.
    static splatfx::Result<GeometryRenderer> create(const std::vector<splatfx::GeometryDesc>& geometry, const splatfx::Budgets& budgets = {});
    GeometryRenderer(GeometryRenderer&&) noexcept;
    GeometryRenderer& operator=(GeometryRenderer&&) noexcept;
    ~GeometryRenderer();

    // Draws every object at timeSec into the bound framebuffer and viewport.
    // Call it inside FrameRenderer's opaque hook when `lighting.shadow` is set
    // (the table is bound to its unit only there).
    void draw(double timeSec, const splatfx::Camera& camera, const GeometryLighting& lighting = {});
    // (issue 15) Objects with GeometryDesc::opacity < 1 are not drawn by
    // draw() but by drawTransparent(), inside FrameRenderer's transparent hook
    // with HostTarget::transparentToLists (they emit into the fragment lists).
    bool hasTransparent() const;
    void drawTransparent(double timeSec, const splatfx::Camera& camera, const GeometryLighting& lighting = {});
    const GeometryStats& stats() const;
    // Why the last draw() with GeometryLighting::vertexFog could not fog (its
    // program failed to build or take the fog's uniforms); empty when it did.
    const std::string& vertexFogError() const;
    // World-space box of object i at timeSec (empty for Empty objects).
    splatfx::Aabb worldBounds(std::size_t i, double timeSec) const;
    // [issue 17] Replaces object i's mesh by world-space triangles (3 points
    // each, e.g. a LOD ground fog's terrain: GroundFog::update), drawn with
    // smooth normals (corners welded by position) and no placement or motion
    // from then on. Expects i < the object count. Fails when the GL cannot
    // store the mesh (the object then draws nothing).
    splatfx::Status setWorldTriangles(std::size_t i, const std::vector<glm::vec3>& triangles);
    // Index of the object named `name`, or -1.
    long find(const std::string& name) const;

private:
    struct Impl;
    explicit GeometryRenderer(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> mImpl;
};

} // namespace scenehost
