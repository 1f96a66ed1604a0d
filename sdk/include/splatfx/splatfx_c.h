/* splatfx/splatfx_c.h: the C API of splatfx, for engines and languages that cannot call C++.
 *
 * A thin C layer over the C++ SDK, for a native plug-in of an engine written
 * in C, C#, Rust, Zig, Python (ctypes/cffi), Lua, ...: materials, preset
 * effects (fire, smoke, steam, dust, fire turning into smoke, ghosts),
 * texture-set folders and scene files, a scene that decides what is needed
 * and prepares a frame at a time t for a camera made from the host's
 * matrices, and gl::FrameRenderer drawing that frame into the host's
 * framebuffer against the host's depth texture. Plus a headless EGL context,
 * so a pure C program can render without a window.
 * It lives in its own shared library, splatfx::c (libsplatfx_c.so), which
 * exports only the splatfx_* functions below; find_package(splatfx
 * COMPONENTS c) finds it and asks for no other package.
 *
 * What it does NOT do: expose the whole C++ API (hand-shaped grids,
 * procedural motion, fog, lights, LOD volumes, the reference renderer and the
 * bare splat pass are C++ only; docs/c-api.md lists them), create a context
 * for a window, clear the host's framebuffer or write its depth.
 *
 *   splatfx_materials* m; splatfx_scene* s; uint32_t id;
 *   splatfx_materials_create(NULL, &m, err); splatfx_scene_create(&s, err);
 *   splatfx_scene_add_fire(s, m, NULL, NULL, &id, err);   then per frame: prepare, render
 *
 * Errors: every function that can fail returns a splatfx_status
 * (SPLATFX_OK = 0) and takes, as its last parameter, a splatfx_error* the
 * caller owns (or NULL when the caller only wants the status). On failure the
 * error object receives the status and a message naming the function, the
 * parameter or field and the value (e.g. "splatfx_scene_prepare: time_sec
 * is nan; expected a finite number of seconds"); on success it is cleared. There is no
 * global or thread-local error state: one error object per thread, reused.
 * No C++ exception crosses this header: each function catches everything and
 * reports SPLATFX_ERROR_OUT_OF_MEMORY or SPLATFX_ERROR_INTERNAL. NULL handles
 * and out-of-range arguments are errors (SPLATFX_ERROR_INVALID_ARGUMENT),
 * never a crash.
 *
 * Ownership: each *_create returns a handle the caller frees with the
 * matching *_destroy. A destroy ignores NULL, a handle destroyed already (a
 * double destroy), a handle of another type and any pointer the library did
 * not return: it looks the pointer up among the live handles and never reads
 * through it; such a pointer passed to another call is an
 * SPLATFX_ERROR_INVALID_ARGUMENT ("... it was destroyed ..."). (A new handle
 * may reuse a destroyed one's address; from then on the old pointer is the
 * new handle.) Handles are
 * independent: a scene does not keep its materials, a frame does not keep
 * its scene (though a scene is tied to the materials its effects were built
 * with, and a frame to those it was prepared with: others are refused); a
 * renderer is destroyed while its GL context is current, before the context.
 *
 * Threading: one thread at a time per handle; different handles on different
 * threads freely, except that the renderer and the headless context are used
 * on the thread where their GL context is current.
 *
 * Conventions: matrices are 16 floats, column-major (OpenGL's layout, glm's
 * value_ptr); camera conventions as camera.hpp (right-handed view space
 * looking down -z, clip z in [-w, w]); times in seconds, angles in radians,
 * lengths in world units. Desc structs are filled with their defaults by
 * the matching *_init function (a NULL desc pointer means all defaults);
 * zero is a meaningful value for many fields (wind, position), so a
 * zero-filled desc is NOT the defaults. Booleans are int (0 false, else true).
 */
#ifndef SPLATFX_SPLATFX_C_H
#define SPLATFX_SPLATFX_C_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#if defined(SPLATFX_C_BUILDING)
#define SPLATFX_C_API __declspec(dllexport)
#else
#define SPLATFX_C_API __declspec(dllimport)
#endif
#elif defined(__GNUC__)
#define SPLATFX_C_API __attribute__((visibility("default")))
#else
#define SPLATFX_C_API
#endif

/* Enums are 32-bit signed integers on both sides. In C++ they get that as a
 * fixed underlying type, so any value a C caller or an FFI passes (say 7 for
 * a 3-value enum) is a value of the type and the library can reject it
 * (without it, C++ may assume an enum holds only its enumerators' range); in
 * C each enum carries a 0x7fffffff enumerator, which keeps it int-sized under
 * -fshort-enums too. */
#ifdef __cplusplus
#define SPLATFX_C_ENUM(name) enum name : int32_t
#else
#define SPLATFX_C_ENUM(name) enum name
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* The version of this header's API; splatfx_c_api_version() returns the
 * library's, so a binding can refuse a library it was not written for.
 * Versions only add: a program written for 1 runs unchanged on 2
 * (2 added splatfx_renderer_note_count and splatfx_renderer_note; 3 added
 * splatfx_embers_desc and splatfx_scene_add_embers; 4 added
 * splatfx_scene_set_hdr_lit and splatfx_scene_hdr_lit). */
#define SPLATFX_C_API_VERSION 4
SPLATFX_C_API uint32_t splatfx_c_api_version(void);

/* ---- [errors] ------------------------------------------------------------ */

typedef SPLATFX_C_ENUM(splatfx_status){SPLATFX_OK = 0,
                                       SPLATFX_ERROR_INVALID_ARGUMENT = 1, /* a NULL handle, a field out of range, a NaN */
                                       SPLATFX_ERROR_INVALID_STATE = 2,    /* e.g. rendering a frame that was never prepared */
                                       SPLATFX_ERROR_NOT_FOUND = 3,        /* an effect id the scene does not have */
                                       SPLATFX_ERROR_FILE = 4,             /* a scene file or texture-set folder could not be read or is invalid */
                                       SPLATFX_ERROR_GL = 5, /* no OpenGL 4.5 context, the wrong one current, no EGL display, a GL name that is not
                                                                what was asked, a GL error raised during the call */
                                       SPLATFX_ERROR_OUT_OF_MEMORY = 6,
                                       SPLATFX_ERROR_INTERNAL = 7, /* an unexpected C++ exception, caught at the boundary */
                                       SPLATFX_STATUS_MAX_ENUM = 0x7fffffff} splatfx_status;

/* A short constant name for a status ("SPLATFX_ERROR_FILE"); never NULL. */
SPLATFX_C_API const char* splatfx_status_name(splatfx_status status);

typedef struct splatfx_error splatfx_error;
/* Returns NULL only when out of memory (then pass NULL to the other calls). */
SPLATFX_C_API splatfx_error* splatfx_error_create(void);
SPLATFX_C_API void splatfx_error_destroy(splatfx_error* error);
/* The last failure's status; SPLATFX_OK after a success. NULL gives SPLATFX_ERROR_INVALID_ARGUMENT. */
SPLATFX_C_API splatfx_status splatfx_error_status(const splatfx_error* error);
/* The last failure's message; "" after a success. Valid until the next call
 * that takes this error object. Never NULL. */
SPLATFX_C_API const char* splatfx_error_message(const splatfx_error* error);

/* ---- [headless context] --------------------------------------------------- */

/* An OpenGL 4.5 core context without a window (EGL device, then Mesa's
 * surfaceless platform, then the default display; llvmpipe when there is no
 * GPU). Current on the creating thread after create. For hosts that have no
 * context of their own (tools, tests, servers); engines use theirs. */
typedef struct splatfx_headless_context splatfx_headless_context;
SPLATFX_C_API splatfx_status splatfx_headless_context_create(splatfx_headless_context** out, splatfx_error* error);
SPLATFX_C_API void splatfx_headless_context_destroy(splatfx_headless_context* context);
SPLATFX_C_API splatfx_status splatfx_headless_context_make_current(splatfx_headless_context* context, splatfx_error* error);
/* GL_RENDERER (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"); valid while the context lives. NULL for NULL. */
SPLATFX_C_API const char* splatfx_headless_context_renderer(const splatfx_headless_context* context);

/* ---- [materials and texture sets] ------------------------------------------ */

/* Every texture set and colour table a frame may use (materials.hpp). */
typedef struct splatfx_materials_desc {
    int32_t layer_size;       /* texels on a side of every texture layer, [4, 1024]; default 32 */
    int32_t color_table_size; /* entries per colour table, [2, 65536]; default 256 */
} splatfx_materials_desc;
SPLATFX_C_API void splatfx_materials_desc_init(splatfx_materials_desc* desc);

typedef struct splatfx_materials splatfx_materials;
SPLATFX_C_API splatfx_status splatfx_materials_create(const splatfx_materials_desc* desc, splatfx_materials** out, splatfx_error* error);
SPLATFX_C_API void splatfx_materials_destroy(splatfx_materials* materials);
/* Texture layers held (layer 0 is the plain footprint). 0 for NULL. */
SPLATFX_C_API uint32_t splatfx_materials_layer_count(const splatfx_materials* materials);

/* A texture set loaded from a folder (a manifest and its images,
 * docs/texpick.md), to give a preset its detail textures. */
typedef struct splatfx_texture_set splatfx_texture_set;
SPLATFX_C_API splatfx_status splatfx_texture_set_load(const char* folder, splatfx_texture_set** out, splatfx_error* error);
SPLATFX_C_API void splatfx_texture_set_destroy(splatfx_texture_set* set);
/* Textures in the set. 0 for NULL. */
SPLATFX_C_API uint32_t splatfx_texture_set_count(const splatfx_texture_set* set);

/* ---- [scene and presets] --------------------------------------------------- */

typedef struct splatfx_scene splatfx_scene;
SPLATFX_C_API splatfx_status splatfx_scene_create(splatfx_scene** out, splatfx_error* error);
SPLATFX_C_API void splatfx_scene_destroy(splatfx_scene* scene);

/* How the scene treats one effect (scene.hpp, EffectOptions). */
typedef struct splatfx_effect_options {
    const char* name;    /* for messages, copied; default NULL (no name) */
    float range_world;   /* skipped beyond this distance of its bounds from the camera, > 0; default INFINITY */
    int enabled;         /* default 1 */
    int textured;        /* 0: traditional splats (the plain footprint); default 1 */
    float opacity_scale; /* multiplies the effect's opacity, [0, 1000]; default 1 */
} splatfx_effect_options;
SPLATFX_C_API void splatfx_effect_options_init(splatfx_effect_options* options);

/* Object dynamics (motion.hpp; King et al. 1999 sec. 3.1): a keyframe track
 * of poses, interpolated between keys, holding the first before it and the
 * last after it. Given to a preset as a pointer and a count (copied at add
 * time); keys must have strictly increasing times. A grid preset's motion
 * moves it from where it was built: object to world at t is
 * motion(t) * translate(desc.position). A solver preset's source motion is
 * where its emitter is, in world space (the smoke trails it). */
typedef SPLATFX_C_ENUM(splatfx_easing){SPLATFX_EASING_LINEAR = 0, /* constant rate between keys */
                                       SPLATFX_EASING_SMOOTH = 1, /* smoothstep: eases in and out of each key */
                                       SPLATFX_EASING_STEP = 2,   /* holds the key until the next one */
                                       SPLATFX_EASING_MAX_ENUM = 0x7fffffff} splatfx_easing;

typedef struct splatfx_keyframe {
    double time_sec;       /* strictly increasing along the track; default 0 */
    float position[3];     /* world units; default 0 */
    float rotation[4];     /* unit quaternion w, x, y, z; default 1, 0, 0, 0 */
    float scale[3];        /* per axis, > 0; default 1 */
    float opacity;         /* multiplies the effect's opacity (fades), >= 0; default 1 */
    float growth;          /* fraction of the material present, [0, 1]; default 1 */
    splatfx_easing easing; /* of the segment from this key to the next; default SPLATFX_EASING_LINEAR */
} splatfx_keyframe;
SPLATFX_C_API void splatfx_keyframe_init(splatfx_keyframe* key);

/* The presets (presets.hpp; King et al. 1999's scenes). Each *_init fills
 * the C++ descriptor's defaults. texture_set: NULL for procedural
 * turbulence; otherwise copied at add time (the handle may be destroyed
 * after). The preset validates its fields; the message names the field. */
typedef struct splatfx_fire_desc {
    int32_t dims[3];                        /* lattice cells; default 7, 20, 5 (the paper's Fig. 1) */
    float spacing[3];                       /* world units between voxels; default 0.5 */
    float position[3];                      /* world position of the base centre; default 0 */
    const splatfx_texture_set* texture_set; /* default NULL (procedural) */
    int32_t texture_count;                  /* procedural textures; default 8 */
    float opacity;                          /* at the core of the base, (0, 1]; default 0.55 */
    float propagation_steps_per_sec;        /* cells per second the detail rises; default 8 */
    float textures_per_sec;                 /* texture cycling rate; default 6 */
    int crossfade;                          /* cross-fade consecutive textures; default 1 */
    const splatfx_keyframe* motion_keys;    /* object dynamics of the whole fire; default NULL (at rest) */
    uint32_t motion_key_count;              /* keys at motion_keys; default 0 */
    uint32_t seed;                          /* texture dynamics; default 1 */
    uint32_t texture_seed;                  /* procedural texture set; default 1 */
} splatfx_fire_desc;
SPLATFX_C_API void splatfx_fire_desc_init(splatfx_fire_desc* desc);

typedef struct splatfx_smoke_desc {
    int32_t dims[3];                            /* solver cells; default 10, 20, 10 */
    float spacing[3];                           /* world units per cell; default 0.5 */
    float position[3];                          /* world position of the domain's base centre; default 0 */
    float source_offset[3];                     /* emitter centre above the position; default 0, 0.5, 0 */
    float source_radius;                        /* emitter radius, world units; default 0.75 */
    float wind_world[3];                        /* world units per second; default 1, 0, 0 */
    float dissipation;                          /* 1/s; default 0.15 */
    const splatfx_texture_set* texture_set;     /* default NULL (procedural) */
    int32_t texture_count;                      /* default 8 */
    float textures_per_sec;                     /* default 3 */
    int32_t substeps;                           /* solver substeps per step; default 1 */
    const splatfx_keyframe* source_motion_keys; /* the object the chimney sits on; default NULL (at rest at position) */
    uint32_t source_motion_key_count;           /* default 0 */
    uint32_t seed;                              /* default 1 */
    uint32_t texture_seed;                      /* default 1 */
} splatfx_smoke_desc;
SPLATFX_C_API void splatfx_smoke_desc_init(splatfx_smoke_desc* desc);

typedef struct splatfx_steam_desc {
    int32_t dims[3];                        /* lattice; default 2, 20, 2 (the paper's Fig. 5) */
    float spacing[3];                       /* default 0.25 */
    float position[3];                      /* the spout; default 0 */
    const splatfx_texture_set* texture_set; /* default NULL (procedural) */
    int32_t texture_count;                  /* default 16 */
    float opacity;                          /* at the spout; default 0.35 */
    float propagation_steps_per_sec;        /* default 10 */
    float textures_per_sec;                 /* default 4 */
    const splatfx_keyframe* motion_keys;    /* default NULL (at rest) */
    uint32_t motion_key_count;              /* default 0 */
    uint32_t seed;                          /* default 1 */
    uint32_t texture_seed;                  /* default 1 */
} splatfx_steam_desc;
SPLATFX_C_API void splatfx_steam_desc_init(splatfx_steam_desc* desc);

typedef struct splatfx_dust_desc {
    int32_t dims[3];                            /* solver cells; default 24, 6, 12 */
    float spacing[3];                           /* default 0.5 */
    float position[3];                          /* default 0 */
    float source_offset[3];                     /* default 0, 0.25, 0 */
    float source_radius;                        /* default 0.8 */
    float wind_world[3];                        /* default 0 */
    float settle;                               /* downward pull per unit density, world units/s^2; default 0.6 */
    float dissipation;                          /* 1/s; default 0.3 */
    const splatfx_texture_set* texture_set;     /* default NULL (procedural) */
    int32_t texture_count;                      /* default 8 */
    const splatfx_keyframe* source_motion_keys; /* the animal kicking up dust; default NULL (at rest at position) */
    uint32_t source_motion_key_count;           /* default 0 */
    uint32_t seed;                              /* default 1 */
    uint32_t texture_seed;                      /* default 1 */
} splatfx_dust_desc;
SPLATFX_C_API void splatfx_dust_desc_init(splatfx_dust_desc* desc);

typedef struct splatfx_fire_to_smoke_desc {
    int32_t dims[3];                              /* default 7, 32, 5 */
    float spacing[3];                             /* default 0.5 */
    float position[3];                            /* default 0 */
    float split;                                  /* normalized height where smoke takes over, (0, 1); default 0.45 */
    float blend;                                  /* overlap of the two layers; default 0.15 */
    const splatfx_texture_set* fire_texture_set;  /* default NULL (procedural) */
    const splatfx_texture_set* smoke_texture_set; /* default NULL (procedural) */
    float propagation_steps_per_sec;              /* default 8 */
    float textures_per_sec;                       /* default 5 */
    const splatfx_keyframe* motion_keys;          /* default NULL (at rest) */
    uint32_t motion_key_count;                    /* default 0 */
    uint32_t seed;                                /* default 1 */
    uint32_t texture_seed;                        /* default 1 */
} splatfx_fire_to_smoke_desc;
SPLATFX_C_API void splatfx_fire_to_smoke_desc_init(splatfx_fire_to_smoke_desc* desc);

typedef struct splatfx_ghosts_desc {
    float head_radius_cells;                /* default 3 */
    int32_t plume_cells;                    /* default 8 */
    float spacing[3];                       /* default 0.3 */
    float position[3];                      /* default 0 */
    const splatfx_texture_set* texture_set; /* face images; default NULL (procedural faces) */
    int32_t texture_count;                  /* default 12 */
    float opacity;                          /* default 0.4 */
    float textures_per_sec;                 /* default 5 */
    float propagation_steps_per_sec;        /* default 4 */
    uint32_t seed;                          /* default 1 */
    uint32_t texture_seed;                  /* default 1 */
} splatfx_ghosts_desc;
SPLATFX_C_API void splatfx_ghosts_desc_init(splatfx_ghosts_desc* desc);

/* Embers: splats at particle positions (King et al. 1999, sec. 6;
 * presets::EmbersDesc, Effect::fromParticles): sparks rising over a fire. */
typedef struct splatfx_embers_desc {
    float position[3];                      /* emitter box centre, world; default 0, 3.2, 0 */
    float half_extent[3];                   /* >= 0; default 1, 1.6, 0.7 */
    float rate_per_sec;                     /* births per second, >= 0; default 45 */
    float warm_up_sec;                      /* births start this long before t = 0, >= 0; default 5 */
    float lifetime_sec;                     /* >= 0; default 4.2 */
    float lifetime_jitter;                  /* [0, 1]; default 0.5 */
    float velocity[3];                      /* world units per second; default 0, 2.6, 0 */
    float velocity_spread[3];               /* + - per axis, >= 0; default 1.6, 1.4, 1.6 */
    float acceleration[3];                  /* buoyancy, world units per second^2; default 0, 0.8, 0 */
    float drag_per_sec;                     /* towards the wind, >= 0; default 0.4 */
    float wind[3];                          /* world units per second; default 1.1, 0, 0.3 */
    float size_world;                       /* kernel unit at birth, > 0; default 0.065 */
    float size_end_world;                   /* ... at death, > 0; default 0.03 */
    float opacity;                          /* [0, 1]; default 1 */
    float stretch_per_speed;                /* streaks along the flight, seconds, >= 0; default 0.4 */
    float textures_per_sec;                 /* texture cycling rate; default 8 */
    const splatfx_texture_set* texture_set; /* default NULL (procedural) */
    int32_t texture_count;                  /* procedural textures; default 8 */
    const splatfx_keyframe* motion_keys;    /* moves the emitter (particles trail); default NULL (at rest) */
    uint32_t motion_key_count;              /* keys at motion_keys; default 0 */
    uint32_t seed;                          /* default 1 */
    uint32_t texture_seed;                  /* procedural texture set; default 1 */
} splatfx_embers_desc;
SPLATFX_C_API void splatfx_embers_desc_init(splatfx_embers_desc* desc);
/* Solids a solver effect's gas flows around (obstacle.hpp; King et al.
 * 1999 Fig. 9: smoke under a bridge). The shape is in its object's frame,
 * placed in the world by motion(t) * transform like the scene file's
 * geometry; the solver voxelizes it every substep. */
typedef SPLATFX_C_ENUM(splatfx_obstacle_shape){SPLATFX_OBSTACLE_BOX = 0,      /* centred on the origin, size = full extents */
                                               SPLATFX_OBSTACLE_PLANE = 1,    /* the xz square (size x by z) and all below it */
                                               SPLATFX_OBSTACLE_SPHERE = 2,   /* radius size[0] / 2 */
                                               SPLATFX_OBSTACLE_CYLINDER = 3, /* along +y from 0 to size[1], radius size[0] / 2 */
                                               SPLATFX_OBSTACLE_MESH = 4,     /* a closed triangle list */
                                               SPLATFX_OBSTACLE_MAX_ENUM = 0x7fffffff} splatfx_obstacle_shape;

typedef struct splatfx_obstacle_desc {
    splatfx_obstacle_shape shape;        /* default SPLATFX_OBSTACLE_BOX */
    float size[3];                       /* object units, > 0; default 1, 1, 1 */
    float transform[16];                 /* static placement in the object, column-major; default identity */
    const float* triangles;              /* MESH: 9 floats a triangle (three x, y, z vertices), copied; default NULL */
    uint32_t triangle_count;             /* default 0 */
    int no_slip;                         /* 1: the gas beside it moves with it; 0: it slides along (free slip); default 0 */
    const splatfx_keyframe* motion_keys; /* the object it belongs to; default NULL (at rest) */
    uint32_t motion_key_count;           /* default 0 */
} splatfx_obstacle_desc;
SPLATFX_C_API void splatfx_obstacle_desc_init(splatfx_obstacle_desc* desc);

/* Adds an obstacle to the solver of effect `id` (smoke or dust). Fails,
 * adding nothing, when the effect has no solver or the desc is bad (the
 * message names the field: "desc.triangles[4] is not finite" for the
 * fifth vertex, floats 12..14). */
SPLATFX_C_API splatfx_status splatfx_scene_add_obstacle(splatfx_scene* scene, uint32_t id, const splatfx_obstacle_desc* desc, splatfx_error* error);

/* Builds the preset (registering its texture sets and colour tables in
 * `materials`) and adds it to the scene; *out_id (may be NULL) receives its
 * id. desc and options may be NULL (defaults). On failure nothing is added.
 * A scene's effects are built with one materials handle: the first add (or
 * the load) fixes it, and adding or preparing with another is an error. */
SPLATFX_C_API splatfx_status splatfx_scene_add_fire(splatfx_scene* scene, splatfx_materials* materials, const splatfx_fire_desc* desc,
                                                    const splatfx_effect_options* options, uint32_t* out_id, splatfx_error* error);
SPLATFX_C_API splatfx_status splatfx_scene_add_smoke(splatfx_scene* scene, splatfx_materials* materials, const splatfx_smoke_desc* desc,
                                                     const splatfx_effect_options* options, uint32_t* out_id, splatfx_error* error);
SPLATFX_C_API splatfx_status splatfx_scene_add_steam(splatfx_scene* scene, splatfx_materials* materials, const splatfx_steam_desc* desc,
                                                     const splatfx_effect_options* options, uint32_t* out_id, splatfx_error* error);
SPLATFX_C_API splatfx_status splatfx_scene_add_dust(splatfx_scene* scene, splatfx_materials* materials, const splatfx_dust_desc* desc,
                                                    const splatfx_effect_options* options, uint32_t* out_id, splatfx_error* error);
SPLATFX_C_API splatfx_status splatfx_scene_add_fire_to_smoke(splatfx_scene* scene, splatfx_materials* materials,
                                                             const splatfx_fire_to_smoke_desc* desc, const splatfx_effect_options* options,
                                                             uint32_t* out_id, splatfx_error* error);
SPLATFX_C_API splatfx_status splatfx_scene_add_ghosts(splatfx_scene* scene, splatfx_materials* materials, const splatfx_ghosts_desc* desc,
                                                      const splatfx_effect_options* options, uint32_t* out_id, splatfx_error* error);
SPLATFX_C_API splatfx_status splatfx_scene_add_embers(splatfx_scene* scene, splatfx_materials* materials, const splatfx_embers_desc* desc,
                                                      const splatfx_effect_options* options, uint32_t* out_id, splatfx_error* error);

/* Reads a scene file (docs/scene-format.md) into a new scene, registering its
 * texture sets and colour tables in `materials`. seed: NULL keeps the file's
 * seed. The file's geometry, camera path and output settings are not
 * exposed here (C++: loadSceneFile); its effects are. On failure the message
 * names the file, the field (as a JSON path) and what was expected. */
SPLATFX_C_API splatfx_status splatfx_scene_load_file(const char* path, splatfx_materials* materials, const uint32_t* seed, splatfx_scene** out,
                                                     splatfx_error* error);

/* Effects added (splatfx_scene_add_*) or loaded (a scene file's "effects";
 * its "volumes" have no id here): their ids are 0 .. count - 1. 0 for NULL. */
SPLATFX_C_API uint32_t splatfx_scene_effect_count(const splatfx_scene* scene);
SPLATFX_C_API splatfx_status splatfx_scene_set_effect_enabled(splatfx_scene* scene, uint32_t id, int enabled, splatfx_error* error);

/* HDR lit colour (Scene::setHdrLit; docs/lighting.md, "HDR lit colour"), for
 * a host whose colour target is floating point (GL_RGBA16F, GL_RGBA32F):
 * on, a lit or emissive colour brighter than 1 keeps its brightness through
 * to the target, exposure and tone mapping left to the host; off (the
 * default), it is scaled down to 1 keeping its hue, for 8-bit targets.
 * Colours at or below 1 are drawn the same either way. A host option, not a
 * scene-file key: it depends on the host's target, which the file does not
 * know. Takes effect at the next prepare; the frame remembers it, and
 * splatfx_renderer_render refuses to draw such a frame into a fixed-point
 * colour target (it would clamp each channel at 1, shifting the hue). */
SPLATFX_C_API splatfx_status splatfx_scene_set_hdr_lit(splatfx_scene* scene, int on, splatfx_error* error);
/* 1 when on, 0 when off or for a NULL or destroyed scene. */
SPLATFX_C_API int splatfx_scene_hdr_lit(const splatfx_scene* scene);

/* ---- [camera] ---------------------------------------------------------------- */

/* The host's camera, a plain value (camera.hpp). */
typedef struct splatfx_camera {
    float view[16];      /* world to view, column-major */
    float proj[16];      /* view to clip, column-major, OpenGL clip z in [-w, w] */
    int32_t viewport[2]; /* width, height in pixels, each in [1, 16384] */
} splatfx_camera;

/* From the host's matrices (copied; checked finite and the viewport in range). */
SPLATFX_C_API splatfx_status splatfx_camera_from_matrices(const float view[16], const float proj[16], int32_t width, int32_t height,
                                                          splatfx_camera* out, splatfx_error* error);
/* A perspective camera at eye looking at target (Camera::lookAt); fov_y in
 * (0, pi) radians, 0 < near_plane < far_plane. */
SPLATFX_C_API splatfx_status splatfx_camera_look_at(const float eye[3], const float target[3], const float up[3], float fov_y, int32_t width,
                                                    int32_t height, float near_plane, float far_plane, splatfx_camera* out, splatfx_error* error);

/* ---- [frame] ------------------------------------------------------------------ */

/* Everything one frame draws (frame.hpp); keep it between frames, it reuses its memory. */
typedef struct splatfx_frame splatfx_frame;
SPLATFX_C_API splatfx_status splatfx_frame_create(splatfx_frame** out, splatfx_error* error);
SPLATFX_C_API void splatfx_frame_destroy(splatfx_frame* frame);

typedef struct splatfx_frame_stats {
    uint64_t declared;  /* effects in the scene, the volumes of a scene file (clouds, ground fog) included */
    uint64_t needed;    /* in view, in range, alive and enabled (= simulated and drawn) */
    uint64_t simulated; /* effects that did dynamics work for this frame */
    uint64_t drawn;     /* effects that emitted at least one splat or tetrahedron */
    uint64_t splats;    /* splats in the frame */
    double time_sec;    /* the time it was prepared at */
} splatfx_frame_stats;
SPLATFX_C_API splatfx_status splatfx_frame_get_stats(const splatfx_frame* frame, splatfx_frame_stats* out, splatfx_error* error);

/* One frame at time_sec (finite, in [0, 262144] seconds: kMaxTimeSec, the
 * latest time the dynamics hold exactly; restart the clock before it) for the camera: decides which effects
 * are needed, brings exactly those to time_sec, builds and sorts their
 * splats into `frame` (Scene::prepare). GL-free: any thread that owns these
 * handles. Times should not decrease across calls (solver effects do not run
 * backwards; stateless effects may be scrubbed freely). A lighting or shadow
 * failure of a loaded scene (a shadow table over Budgets::lightingBytes, a
 * sceneShadow light it does not have: Scene::lightingError) is
 * SPLATFX_ERROR_INVALID_ARGUMENT naming it, with the frame still prepared
 * (those effects unlit, no scene shadow): render it or not, but it is not
 * what the file asked for. */
SPLATFX_C_API splatfx_status splatfx_scene_prepare(splatfx_scene* scene, double time_sec, const splatfx_camera* camera,
                                                   const splatfx_materials* materials, splatfx_frame* frame, splatfx_error* error);

/* ---- [renderer] --------------------------------------------------------------- */

typedef struct splatfx_renderer_desc {
    int32_t resolution_scale; /* 1: full resolution; 2 or 4: volumes at 1/scale per axis, depth-aware upsampling; default 1 */
} splatfx_renderer_desc;
SPLATFX_C_API void splatfx_renderer_desc_init(splatfx_renderer_desc* desc);

/* What the host hands over for one frame (gl::HostTarget). */
typedef struct splatfx_host_target {
    uint32_t framebuffer;   /* the host's framebuffer object (0: the default framebuffer); it must exist
                               (glCreateFramebuffers, or glGenFramebuffers and bound once); default 0 */
    int32_t x, y;           /* viewport origin, >= 0; default 0, 0 */
    int32_t width, height;  /* viewport size; 0, 0: the frame camera's viewport; otherwise must equal it; default 0, 0 */
    uint32_t depth_texture; /* the host's depth as a GL texture (0: the framebuffer's depth attachment if a texture); default 0 */
    /* Called with the host framebuffer bound and the viewport set, before the
     * volumes (opaque geometry, depth writes on) and after them (transparent
     * surfaces). NULL: none. They must return normally (no longjmp, no
     * exception through the C frames) with the same context current. A
     * renderer, frame, materials, error object or headless context the hook
     * destroys is deleted when the render returns (which then fails with
     * SPLATFX_ERROR_INVALID_STATE naming it); calling the same renderer, or
     * preparing the frame being drawn, from a hook is refused. */
    void (*draw_opaque)(void* user_data);      /* default NULL */
    void (*draw_transparent)(void* user_data); /* default NULL */
    void* user_data;                           /* passed to both; default NULL */
} splatfx_host_target;
SPLATFX_C_API void splatfx_host_target_init(splatfx_host_target* target);

typedef struct splatfx_render_stats {
    uint64_t splats;          /* splats drawn */
    uint64_t draw_calls;      /* draw calls of the volume passes */
    int32_t resolution_scale; /* the scale the volumes were drawn at */
} splatfx_render_stats;

/* gl::FrameRenderer: owns the order of the frame's passes. Needs a current
 * OpenGL 4.5 context at create, render and destroy: at upload, render and
 * destroy the one it was created in (its GL objects are names in that
 * context). Another one current is SPLATFX_ERROR_GL and no GL call is made.
 * GL errors: those the host left pending before create, upload or render
 * are taken and dropped (read glGetError first to keep them); errors raised
 * inside a hook are reported as the hook's (SPLATFX_ERROR_GL, "the
 * draw_opaque hook raised ..."); errors raised by splatfx's own calls are
 * SPLATFX_ERROR_GL ("... raised by splatfx's own GL calls during the
 * render"). A call refused before its GL work leaves pending errors alone. */
typedef struct splatfx_renderer splatfx_renderer;
SPLATFX_C_API splatfx_status splatfx_renderer_create(const splatfx_renderer_desc* desc, splatfx_renderer** out, splatfx_error* error);
/* Call with its context current. Without it (none, or another one) its GL
 * objects cannot be deleted (GL would abort, or delete the other context's
 * objects of the same names): they are left to the context's own destruction
 * (and its CPU-side memory is not freed) rather than crash. */
SPLATFX_C_API void splatfx_renderer_destroy(splatfx_renderer* renderer);
/* Uploads the materials' texture layers (only when they changed since the
 * last upload of these materials). Optional: render uploads too; call it to
 * take the upload's cost at a time of your choosing. */
SPLATFX_C_API splatfx_status splatfx_renderer_upload(splatfx_renderer* renderer, const splatfx_materials* materials, splatfx_error* error);
/* Draws the frame into the host target: the opaque hook, the volumes tested
 * against the host depth, the transparent hook (gl::FrameRenderer::render).
 * `materials` must be those the frame was prepared with. Never clears, never
 * writes depth; restores the GL state it touches. A frame prepared with HDR
 * lit colour (splatfx_scene_set_hdr_lit) needs a floating-point colour
 * target (the framebuffer's GL_COLOR_ATTACHMENT0, or the default
 * framebuffer's back buffer): a fixed-point one is
 * SPLATFX_ERROR_INVALID_ARGUMENT and nothing is drawn. */
SPLATFX_C_API splatfx_status splatfx_renderer_render(splatfx_renderer* renderer, const splatfx_materials* materials, const splatfx_frame* frame,
                                                     const splatfx_host_target* target, splatfx_error* error);
SPLATFX_C_API splatfx_status splatfx_renderer_get_stats(const splatfx_renderer* renderer, splatfx_render_stats* out, splatfx_error* error);
/* The last render's notes: one line for each pass that could not run as
 * asked and what it did instead (e.g. "depth cut off ... the host depth is
 * multisampled (4 samples) ..."). 0 when every pass ran as asked, or for a
 * NULL or destroyed renderer. */
SPLATFX_C_API uint32_t splatfx_renderer_note_count(const splatfx_renderer* renderer);
/* Note `index` (< note_count), UTF-8, valid until the renderer's next render
 * or destroy; NULL for an index out of range or a NULL or destroyed renderer. */
SPLATFX_C_API const char* splatfx_renderer_note(const splatfx_renderer* renderer, uint32_t index);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* SPLATFX_SPLATFX_C_H */
