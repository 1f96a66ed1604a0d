// [clouds, issue 17] The projected-tetrahedra pass (private to the GL backend,
// owned by gl::FrameRenderer): draws a FrameVolume's tetrahedra back to front
// with pre-integration (Roettger & Ertl 2002, sec. 4), premultiplied "over".
//
// Method ("ray-tetrahedron in the fragment shader"): every tetrahedron's four
// faces are drawn with back faces culled, so each covered pixel gets exactly
// one fragment (the front faces of a convex cell tile its projection). The
// fragment intersects its pixel's ray with the tetrahedron's four face planes
// (per-tetrahedron barycentric planes), which gives the entry and exit distances;
// the scalar and length scale at both ends come from per-tetrahedron linear
// functions. The exit is cut at the host's depth (from HostTarget's depth
// texture) before the lookup, so host geometry inside a cloud is exact. Near-
// plane clipping is done on the CPU (clipTetrahedron) and GL's own near/far
// clipping is switched off (depth clamp) so a face lying in the near plane is
// never lost to rounding. No CPU projection (Shirley-Tuchman classes) needed.
//
// A volume whose LodFrame carries an RGB source per vertex (a LowAlbedo cloud
// lit by lights of different colours) is drawn by the RGB variants (built on
// first use): three linear source functions per tetrahedron instead of one,
// and three lookups per segment, channel c read at (s_c front, s_c back,
// length). Exact for a transfer kappa(s) = A + B s of constant extinction
// (the table's entries are then affine in each scalar, per channel, and its
// alpha does not depend on s): the one-scalar variants are untouched.
//
// With a fog (setFog, issue 14) a second set of variants fogs each segment's
// colour as the splats do, f from the eye (also for orthographic cameras,
// like the splats) to the segment's opacity centroid (docs/fog.md).
//
// It does not sort (the list is already in order) and writes no depth.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "splatfx/camera.hpp"
#include "splatfx/fog.hpp"
#include "splatfx/frame.hpp"
#include "splatfx/result.hpp"
#include "pass.hpp"
#include "render/gl/program_library.hpp"

namespace splatfx::gl::detail {

struct TetraStats {
    std::uint64_t tetrahedra = 0;  // drawn this frame
    std::uint64_t transparent = 0; // skipped by the table's zero-opacity test
    std::uint64_t degenerate = 0;  // skipped: zero or non-finite volume
    std::uint64_t drawCalls = 0;
    std::uint64_t tableUploads = 0; // since creation
    std::size_t tableBytes = 0;     // GPU bytes held by uploaded tables
    std::uint64_t foggedDraws = 0;  // draws with the fog variant this frame
    std::uint64_t rgb = 0;          // drawn with an RGB source per vertex this frame
    std::string rgbError;           // this frame: an RGB source not drawn as given (a program that failed to build, a list of the wrong length)
};

class TetraPass final : public Pass {
public:
    static Result<TetraPass> create(Programs programs);
    TetraPass(TetraPass&&) noexcept;
    TetraPass& operator=(TetraPass&&) noexcept;
    ~TetraPass();

    // Step 0 of the frame: uploads the tables the frame's volumes use that
    // changed (new address or version), drops tables no longer used, and
    // builds the per-tetrahedron data of every volume. Resets the frame stats.
    void uploadTables(const Frame& frame);
    // Draws tetrahedra [begin, end) of frame.volumes()[volume] (after uploadTables).
    // `camera`: the one to project with instead of frame.camera() (the same eye; a
    // multisampled host's per-sample run shifts its image, StepContext::layerCamera).
    // `sampleRay`: each fragment's ray from its sample's window position (a
    // multisampled target drawn per sample), not the interpolated entry point.
    void draw(const Frame& frame, std::uint32_t volume, std::uint32_t begin, std::uint32_t end, const PassTarget& target,
              const Camera* camera = nullptr, bool sampleRay = false);
    // (issue 14) The fog every following draw is seen through (null
    // or empty: none): each segment's colour becomes f c + (1 - f) alpha C_fog
    // with f from the eye to the segment's opacity centroid. Builds the fog
    // variants when the fog's GLSL structure changed; an error leaves no fog.
    Status setFog(const Fog* fog, double timeSec);

    const TetraStats& stats() const;

    void prepare(const FramePlan& plan, const Frame& frame) override;  // the fog variant
    void execute(const PlanStep& step, StepContext& context) override; // PrepareTetrahedra, Tetrahedra
    void report(FrameRenderStats& stats) const override;

    struct Impl; // public so the .cpp's helpers can name Impl::Program; defined there only

private:
    explicit TetraPass(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> mImpl;
    std::string mFogError;
    bool mFogged = false;
    bool mActive = false;                                 // the frame has tetrahedra
    const std::vector<glm::vec4>* mFrameParams = nullptr; // the plan's fog parameters, while a step runs
};

} // namespace splatfx::gl::detail
