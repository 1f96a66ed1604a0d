// splatfx-bench subcommands. Each lives in its own .cpp in this folder (the
// CMakeLists globs them); to add one, declare its entry point here and add a
// row to kCommands. Every command takes the arguments after its name, prints
// progress and a summary, and returns the process exit code.
#pragma once

#include <string>

#include <glm/glm.hpp>

int runAccuracy(int argc, char** argv);     // accuracy.cpp: error vs time per quality knob (issue 5)
int runTable1(int argc, char** argv);       // table1.cpp: the paper's Table I, fill limit, CPU scaling (issue 7)
int runScheduling(int argc, char** argv);   // scheduling.cpp: 1000 effects, 10 in view; catch-up error (issue 6)
int runShadows(int argc, char** argv);      // shadows.cpp: Ebert & Parent 1990 Table 2, shadow tables vs tracing (issue 16)
int runShadowLights(const std::string& out, int frames, bool noPlots); // shadow_lights.cpp: shadows --lights (issue 27.1)
int runFog(int argc, char** argv);          // fog.cpp: Biri et al. 2002 Table 1, fog cost per pixel and per fog texture (issue 14)
int runClouds(int argc, char** argv);       // clouds.cpp: LOD volumes as projected tetrahedra, flight, popping (issue 17)
int runGroundFog(int argc, char** argv);    // groundfog.cpp: LOD ground fog over the Jacksboro DEM: count, time, error, popping (issue 17); --knobs vs the exact field (issue 24)
int runCut(int argc, char** argv);          // cut.cpp: splats cut by the host depth and the near plane: cost, accuracy, popping (issue 15)
int runSoak(int argc, char** argv);         // soak.cpp: every preset for an hour of scene time; finite, flat bounds and memory (issue 13)
int runTransparency(int argc, char** argv); // transparency.cpp: glass panes among the fire, fragment lists vs ordered blend (issue 15)
int runShadowTables(int argc, char** argv); // shadow_tables.cpp: shadow-table build time and error against tracing, CPU only
int runMsaa(int argc, char** argv);         // msaa.cpp: 1x to 8x MSAA host targets, ms per frame and error vs a 16-sample reference (issue 26)
int runLighting(int argc, char** argv);     // lighting.cpp: every lighting knob against the lit volume reference, Pareto (issue 24)
int runLodRefine(int argc, char** argv);    // lod_refine.cpp: LOD cloud refinement on the CPU: tetrahedra, update time, memory
int runGases(int argc, char** argv);        // gases.cpp: procedural gases' spacing, threshold, octaves vs the continuous gas (issue 24)
int runVdb(int argc, char** argv);          // vdb.cpp: VDB resampling block size and splat filter vs the file at full resolution (issue 24)
int runLattice(int argc, char** argv);      // lattice.cpp: how visible the voxel lattice is in the effect samples (issue 25)
int runParticles(int argc, char** argv);    // particles.cpp: splats at particle positions vs the same number of grid splats (issue 25)
int runEbert(int argc, char** argv);        // ebert.cpp: Ebert & Parent 1990 Table 1, the paper's scenes with and without their volumes
int runCloudLight(int argc, char** argv);   // cloudlight.cpp: cloud relight per sun move, per model and size; swept vs exact sun transmittance (issue 27)
int runObstacles(int argc, char** argv);    // obstacles.cpp: solver step cost with obstacles (bridge, moving locomotive, meshes) against none
int runDevice(int argc, char** argv);       // device.cpp: the GL context the benches get (SPLATFX_EGL_DEVICE), for tools/gpu-check.sh
int runEmitted(int argc, char** argv);      // emitted.cpp: a campfire as light: fitted lights vs the exact irradiance, fit and GLSL cost (issue 27.3)
int runCrossShadow(int argc, char** argv); // crossshadow.cpp: lit effects shadowing one another in a Scene, 1/2/4 effects, cost and error (issue 27.2)
int runHdr(int argc, char** argv);          // hdr.cpp: HDR lit colour and RGBA16F/32F targets against the 8-bit path (issues 26, 27)
int runCloudColour(int argc, char** argv);  // cloudcolour.cpp: a cloud under lights of different colours (RGB per vertex) vs one colour (issue 27)

// cloud_knobs.cpp, run by accuracy (--clouds-only alone): the LOD clouds' table size, c, C and
// max vs average Delta against the finest level integrated exactly (issue 17). Needs a current GL context.
int runCloudKnobs(glm::ivec3 dims, glm::ivec2 size, int reps);

struct BenchCommand {
    const char* name;
    const char* summary;
    int (*run)(int argc, char** argv);
};

inline constexpr BenchCommand kCommands[] = {
    {"accuracy", "error against the exact reference vs time per frame, for every quality knob", runAccuracy},
    {"table1", "King et al. 1999 Table I on this machine, fill limit, naive baseline, CPU scaling", runTable1},
    {"clouds", "LOD cloud volumes as tetrahedra: count vs full, frame rate and memory outside/inside, popping", runClouds},
    {"lodrefine", "LOD cloud refinement on the CPU: tetrahedra per frame vs full, update() time, memory, error vs finest", runLodRefine},
    {"groundfog", "LOD ground fog over the Jacksboro DEM: count vs full, ms/frame, error vs full, popping with/without morphing; --knobs: every knob vs the exact field, Pareto", runGroundFog},
    {"scheduling", "a level of 1000 effects with 10 in view vs those 10 alone; camera sweep; catch-up error", runScheduling},
    {"msaa", "a sample scene into 1x, 2x, 4x and 8x multisampled host targets: ms/frame, error vs a 16-sample anti-aliased reference, Pareto", runMsaa},
    {"lighting", "every lighting knob (self-shadow, table size, lobes, samples per voxel, 8-bit) vs the lit volume reference, Pareto", runLighting},
    {"shadows", "Ebert & Parent 1990 Table 2: steam from a glass, no/geometry/traced/table shadowing, table error", runShadows},
    {"ebert", "Ebert & Parent 1990 Table 1: the gallery, steam and chess-fog scenes at the paper's resolutions, with and without their volumes", runEbert},
    {"shadowtables", "shadow tables 16^3..128^3 vs tracing for a 1560-voxel effect: build and lookup time, error (CPU only)", runShadowTables},
    {"fog", "Biri et al. 2002 Table 1: no fog, per-pixel fog, reduced fog textures at 800x600; error vs per pixel", runFog},
    {"cut", "splats cut exactly by depth: cost vs plain on Table I rows, error per table size, popping of a moving wall and the cow", runCut},
    {"transparency", "glass panes among the 1560-voxel fire: fragment lists vs ordered blend vs opaque only, budget, memory", runTransparency},
    {"lattice", "the voxel lattice's visibility per effect sample: spectral peaks at the voxel spacing vs a turbulence control", runLattice},
    {"gases", "procedural gases: grid spacing, threshold, octaves against the continuous turbulence gas; Pareto plot", runGases},
    {"vdb", "OpenVDB import: voxels per cell and splat filter against the file's voxels at full resolution; Pareto plot", runVdb},
    {"particles", "splats at particle positions (host, emitter) vs the same number of grid splats: CPU frame, GL pass, error vs the exact reference", runParticles},
    {"cloudlight", "LOD cloud relit as the sun moves: ms per relight per model and size, skipped relight, table rebuild; transmittance vs exact", runCloudLight},
    {"cloudcolour", "a low-albedo cloud under lights of different colours (RGB per vertex) vs one colour: update and tetrahedra pass ms, ratio, bytes", runCloudColour},
    {"crossshadow", "lit effects shadowing one another in a Scene: 1, 2, 4 plumes with and without the cross-shadow, ms per frame, colour vs exact", runCrossShadow},
    {"obstacles", "solver step cost with obstacles (a bridge, a moving locomotive, as boxes or meshes, free or no slip) against none", runObstacles},
    {"device", "the OpenGL context the benches get (SPLATFX_EGL_DEVICE selects an EGL device): vendor, renderer, sample limits", runDevice},
    {"hdr", "HDR lit colour against the 8-bit path: RGBA8/16F/32F host targets, ms per frame, error vs the lit volume reference, Pareto", runHdr},
    {"emitted", "a campfire as light for the host: fitted point lights (1..8, occlusion on/off) vs the exact irradiance, fit ms, GLSL ns/pixel, Pareto", runEmitted},
    {"soak", "every preset stepped at 60 Hz for an hour of scene time: no NaN/Inf, bounds and memory flat", runSoak},
};
