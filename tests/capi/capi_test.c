/* The C API without a GL context (C11): handles, presets, scene files, prepare, and every error path
 * a host can hit by mistake (NULL handles, wrong handle types, bad fields, NaN time, missing files). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "check.h"

/* A camera looking at the origin's effects from the front: every preset at
 * its default position is in view (their bases sit at the origin, at most
 * ~10 world units tall or 12 wide). */
static splatfx_camera front_camera(splatfx_error* err) {
    const float eye[3] = {0.0f, 4.0f, 30.0f}, target[3] = {0.0f, 4.0f, 0.0f}, up[3] = {0.0f, 1.0f, 0.0f};
    splatfx_camera cam;
    memset(&cam, 0, sizeof cam);
    CHECK_OK(splatfx_camera_look_at(eye, target, up, 0.9f, 160, 120, 0.1f, 500.0f, &cam, err), err);
    return cam;
}

static void test_version_and_error_object(void) {
    CHECK(splatfx_c_api_version() == SPLATFX_C_API_VERSION, "library %u, header %u", splatfx_c_api_version(), (unsigned)SPLATFX_C_API_VERSION);
    splatfx_error* err = splatfx_error_create();
    CHECK(err != NULL, "no error object");
    CHECK(splatfx_error_status(err) == SPLATFX_OK, "a new error object must be clear");
    CHECK(strcmp(splatfx_error_message(err), "") == 0, "a new error object has message \"%s\"", splatfx_error_message(err));
    /* A failure fills it, the next success clears it. */
    CHECK_FAILS(splatfx_scene_create(NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "splatfx_scene_create: out is NULL");
    splatfx_scene* scene = NULL;
    CHECK_OK(splatfx_scene_create(&scene, err), err);
    CHECK(strcmp(splatfx_error_message(err), "") == 0, "success left the message \"%s\"", splatfx_error_message(err));
    splatfx_scene_destroy(scene);
    /* NULL error objects: the status still comes back. */
    CHECK(splatfx_scene_create(NULL, NULL) == SPLATFX_ERROR_INVALID_ARGUMENT, "status without an error object");
    CHECK(splatfx_error_status(NULL) == SPLATFX_ERROR_INVALID_ARGUMENT, "status of a NULL error object");
    CHECK(strstr(splatfx_error_message(NULL), "NULL") != NULL, "message of a NULL error object");
    CHECK(strcmp(splatfx_status_name(SPLATFX_ERROR_FILE), "SPLATFX_ERROR_FILE") == 0, "status name");
    CHECK(strcmp(splatfx_status_name((splatfx_status)99), "SPLATFX_ERROR_UNKNOWN_STATUS") == 0, "unknown status name");
    /* Destroying NULL is a no-op. */
    splatfx_error_destroy(NULL);
    splatfx_materials_destroy(NULL);
    splatfx_scene_destroy(NULL);
    splatfx_frame_destroy(NULL);
    splatfx_texture_set_destroy(NULL);
    splatfx_renderer_destroy(NULL);
    splatfx_headless_context_destroy(NULL);
    splatfx_error_destroy(err);
}

/* A fire in a scene, prepared: the frame holds its splats and says what was needed. */
static void test_fire_prepares(void) {
    splatfx_error* err = splatfx_error_create();
    splatfx_materials* m = NULL;
    splatfx_scene* scene = NULL;
    splatfx_frame* frame = NULL;
    CHECK_OK(splatfx_materials_create(NULL, &m, err), err);
    CHECK(splatfx_materials_layer_count(m) == 1, "new materials hold the plain footprint only, got %u", splatfx_materials_layer_count(m));
    CHECK_OK(splatfx_scene_create(&scene, err), err);
    CHECK_OK(splatfx_frame_create(&frame, err), err);
    uint32_t id = 99;
    splatfx_effect_options options;
    splatfx_effect_options_init(&options);
    CHECK(isinf(options.range_world) && options.enabled == 1 && options.textured == 1 && options.opacity_scale == 1.0f, "effect option defaults");
    options.name = "campfire";
    CHECK_OK(splatfx_scene_add_fire(scene, m, NULL, &options, &id, err), err);
    CHECK(id == 0, "first effect id %u", id);
    CHECK(splatfx_scene_effect_count(scene) == 1, "effects %u", splatfx_scene_effect_count(scene));
    /* The default fire registers 8 procedural textures (FireDesc.textureCount). */
    CHECK(splatfx_materials_layer_count(m) == 1 + 8, "layers after a fire: %u", splatfx_materials_layer_count(m));
    splatfx_camera cam = front_camera(err);
    CHECK_OK(splatfx_scene_prepare(scene, 0.5, &cam, m, frame, err), err);
    splatfx_frame_stats st;
    CHECK_OK(splatfx_frame_get_stats(frame, &st, err), err);
    CHECK(st.declared == 1 && st.needed == 1 && st.drawn == 1, "declared %llu needed %llu drawn %llu", (unsigned long long)st.declared,
          (unsigned long long)st.needed, (unsigned long long)st.drawn);
    /* At most one splat per voxel of the 7x20x5 lattice; the fire's core voxels are never empty. */
    CHECK(st.splats > 0 && st.splats <= 7 * 20 * 5, "splats %llu", (unsigned long long)st.splats);
    CHECK(st.time_sec == 0.5, "time %g", st.time_sec);
    /* Disabled: not needed, nothing drawn. */
    CHECK_OK(splatfx_scene_set_effect_enabled(scene, id, 0, err), err);
    CHECK_OK(splatfx_scene_prepare(scene, 0.6, &cam, m, frame, err), err);
    CHECK_OK(splatfx_frame_get_stats(frame, &st, err), err);
    CHECK(st.needed == 0 && st.splats == 0, "disabled: needed %llu splats %llu", (unsigned long long)st.needed, (unsigned long long)st.splats);
    CHECK_FAILS(splatfx_scene_set_effect_enabled(scene, 1, 1, err), err, SPLATFX_ERROR_NOT_FOUND, "id 1 is not an effect of this scene (it has 1)");
    /* HDR lit colour: off by default, a host switch (capi_gl_test draws with it). */
    CHECK(splatfx_scene_hdr_lit(scene) == 0, "HDR lit colour is on by default");
    CHECK_OK(splatfx_scene_set_hdr_lit(scene, 7, err), err);
    CHECK(splatfx_scene_hdr_lit(scene) == 1, "HDR lit colour did not turn on");
    CHECK_OK(splatfx_scene_set_hdr_lit(scene, 0, err), err);
    CHECK(splatfx_scene_hdr_lit(scene) == 0, "HDR lit colour did not turn off");
    CHECK_FAILS(splatfx_scene_set_hdr_lit(NULL, 1, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "splatfx_scene_set_hdr_lit: scene is NULL");
    CHECK_FAILS(splatfx_scene_set_hdr_lit((splatfx_scene*)m, 1, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "scene is not a splatfx_scene (it is a splatfx_materials)");
    CHECK(splatfx_scene_hdr_lit(NULL) == 0 && splatfx_scene_hdr_lit((const splatfx_scene*)m) == 0, "HDR lit colour of a non-scene");
    /* Out of range: a range of 1 world unit from 30 units away skips it. */
    options.range_world = 1.0f;
    CHECK_OK(splatfx_scene_add_fire(scene, m, NULL, &options, &id, err), err);
    CHECK_OK(splatfx_scene_prepare(scene, 0.7, &cam, m, frame, err), err);
    CHECK_OK(splatfx_frame_get_stats(frame, &st, err), err);
    CHECK(st.declared == 2 && st.needed == 0, "out of range: declared %llu needed %llu", (unsigned long long)st.declared,
          (unsigned long long)st.needed);
    splatfx_frame_destroy(frame);
    splatfx_scene_destroy(scene);
    splatfx_materials_destroy(m);
    splatfx_error_destroy(err);
}

/* Every preset through its C desc: each one builds, adds and draws. */
static void test_every_preset(void) {
    splatfx_error* err = splatfx_error_create();
    splatfx_materials* m = NULL;
    splatfx_frame* frame = NULL;
    CHECK_OK(splatfx_materials_create(NULL, &m, err), err);
    CHECK_OK(splatfx_frame_create(&frame, err), err);
    splatfx_camera cam = front_camera(err);
    const char* names[7] = {"fire", "smoke", "steam", "dust", "fire_to_smoke", "ghosts", "embers"};
    for (int k = 0; k < 7; ++k) {
        splatfx_scene* scene = NULL;
        CHECK_OK(splatfx_scene_create(&scene, err), err);
        splatfx_status s = SPLATFX_ERROR_INTERNAL;
        switch (k) {
        case 0: {
            splatfx_fire_desc d;
            splatfx_fire_desc_init(&d);
            s = splatfx_scene_add_fire(scene, m, &d, NULL, NULL, err);
            break;
        }
        case 1: {
            splatfx_smoke_desc d;
            splatfx_smoke_desc_init(&d);
            s = splatfx_scene_add_smoke(scene, m, &d, NULL, NULL, err);
            break;
        }
        case 2: {
            splatfx_steam_desc d;
            splatfx_steam_desc_init(&d);
            s = splatfx_scene_add_steam(scene, m, &d, NULL, NULL, err);
            break;
        }
        case 3: {
            splatfx_dust_desc d;
            splatfx_dust_desc_init(&d);
            s = splatfx_scene_add_dust(scene, m, &d, NULL, NULL, err);
            break;
        }
        case 4: {
            splatfx_fire_to_smoke_desc d;
            splatfx_fire_to_smoke_desc_init(&d);
            s = splatfx_scene_add_fire_to_smoke(scene, m, &d, NULL, NULL, err);
            break;
        }
        case 5: {
            splatfx_ghosts_desc d;
            splatfx_ghosts_desc_init(&d);
            s = splatfx_scene_add_ghosts(scene, m, &d, NULL, NULL, err);
            break;
        }
        case 6: {
            splatfx_embers_desc d;
            splatfx_embers_desc_init(&d);
            s = splatfx_scene_add_embers(scene, m, &d, NULL, NULL, err);
            break;
        }
        }
        CHECK(s == SPLATFX_OK, "%s: %s", names[k], splatfx_error_message(err));
        /* Solver presets (smoke, dust) start empty and fill from their emitters: one second of
         * simulated time (30 steps at the default 1/30 s catch-up) gives them material. */
        CHECK_OK(splatfx_scene_prepare(scene, 0.0, &cam, m, frame, err), err);
        CHECK_OK(splatfx_scene_prepare(scene, 1.0, &cam, m, frame, err), err);
        splatfx_frame_stats st;
        CHECK_OK(splatfx_frame_get_stats(frame, &st, err), err);
        CHECK(st.needed == 1 && st.splats > 0, "%s: needed %llu splats %llu", names[k], (unsigned long long)st.needed, (unsigned long long)st.splats);
        /* Going back in time is allowed (stateless effects scrub; solvers hold their state). */
        CHECK_OK(splatfx_scene_prepare(scene, 0.5, &cam, m, frame, err), err);
        splatfx_scene_destroy(scene);
    }
    /* A desc field reaches the C++ preset: a 3x4x2 fire has at most 24 splats. */
    {
        splatfx_scene* scene = NULL;
        CHECK_OK(splatfx_scene_create(&scene, err), err);
        splatfx_fire_desc d;
        splatfx_fire_desc_init(&d);
        CHECK(d.dims[0] == 7 && d.dims[1] == 20 && d.dims[2] == 5 && d.opacity == 0.55f, "fire desc defaults");
        d.dims[0] = 3;
        d.dims[1] = 4;
        d.dims[2] = 2;
        CHECK_OK(splatfx_scene_add_fire(scene, m, &d, NULL, NULL, err), err);
        CHECK_OK(splatfx_scene_prepare(scene, 0.0, &cam, m, frame, err), err);
        splatfx_frame_stats st;
        CHECK_OK(splatfx_frame_get_stats(frame, &st, err), err);
        CHECK(st.splats > 0 && st.splats <= 3 * 4 * 2, "3x4x2 fire: %llu splats", (unsigned long long)st.splats);
        splatfx_scene_destroy(scene);
    }
    splatfx_frame_destroy(frame);
    splatfx_materials_destroy(m);
    splatfx_error_destroy(err);
}

/* Keyframed object dynamics through the C desc: a fire that crosses the view
 * is needed only while it is in it (the scene culls by its moving bounds). */
static void test_motion(void) {
    splatfx_error* err = splatfx_error_create();
    splatfx_materials* m = NULL;
    splatfx_scene* scene = NULL;
    splatfx_frame* frame = NULL;
    CHECK_OK(splatfx_materials_create(NULL, &m, err), err);
    CHECK_OK(splatfx_scene_create(&scene, err), err);
    CHECK_OK(splatfx_frame_create(&frame, err), err);
    splatfx_camera cam = front_camera(err);
    /* front_camera sees x in about [-19, 19] at the fire's depth (30 * tan(0.45) * 160 / 120);
     * keys at x = -60 and +60 put the fire (3.5 wide) well outside at t = 0 and t = 4. */
    splatfx_keyframe keys[2];
    splatfx_keyframe_init(&keys[0]);
    splatfx_keyframe_init(&keys[1]);
    CHECK(keys[0].rotation[0] == 1.0f && keys[0].scale[1] == 1.0f && keys[0].opacity == 1.0f && keys[0].growth == 1.0f &&
              keys[0].easing == SPLATFX_EASING_LINEAR,
          "keyframe defaults");
    keys[0].position[0] = -60.0f;
    keys[1].time_sec = 4.0;
    keys[1].position[0] = 60.0f;
    splatfx_fire_desc d;
    splatfx_fire_desc_init(&d);
    d.motion_keys = keys;
    d.motion_key_count = 2;
    CHECK_OK(splatfx_scene_add_fire(scene, m, &d, NULL, NULL, err), err);
    /* The scene culls by the bounds swept since the previous prepare (conservative: a fire that
     * crossed the view between two frames counts as in it), so t = 4 is asked twice: the first
     * sweeps [2, 4] through the view, the second [4, 4] only. -1: not asserted. */
    const double times[4] = {0.0, 2.0, 4.0, 4.0};
    const int needed[4] = {0, 1, -1, 0};
    for (int i = 0; i < 4; ++i) {
        CHECK_OK(splatfx_scene_prepare(scene, times[i], &cam, m, frame, err), err);
        splatfx_frame_stats st;
        CHECK_OK(splatfx_frame_get_stats(frame, &st, err), err);
        CHECK(needed[i] < 0 || st.needed == (uint64_t)needed[i], "prepare %d (t = %g): needed %llu, expected %d", i, times[i],
              (unsigned long long)st.needed, needed[i]);
    }
    /* Bad tracks: the key and the field are named, nothing is added. */
    keys[1].time_sec = 0.0;
    CHECK_FAILS(splatfx_scene_add_fire(scene, m, &d, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "desc.motion: keyframe 1: timeSec 0.000000 must be greater");
    keys[1].time_sec = 4.0;
    keys[1].scale[2] = 0.0f;
    CHECK_FAILS(splatfx_scene_add_fire(scene, m, &d, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "pose.scale must be positive");
    keys[1].scale[2] = 1.0f;
    keys[1].easing = (splatfx_easing)7;
    CHECK_FAILS(splatfx_scene_add_fire(scene, m, &d, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "desc.motion_keys[1].easing is 7");
    d.motion_keys = NULL;
    CHECK_FAILS(splatfx_scene_add_fire(scene, m, &d, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "desc.motion_keys is NULL but desc.motion_key_count is 2");
    splatfx_smoke_desc sd;
    splatfx_smoke_desc_init(&sd);
    sd.source_motion_keys = keys;
    sd.source_motion_key_count = 1;
    keys[0].time_sec = NAN;
    CHECK_FAILS(splatfx_scene_add_smoke(scene, m, &sd, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "desc.source_motion_keys[0].time_sec is nan");
    CHECK(splatfx_scene_effect_count(scene) == 1, "failed adds added effects: %u", splatfx_scene_effect_count(scene));
    splatfx_frame_destroy(frame);
    splatfx_scene_destroy(scene);
    splatfx_materials_destroy(m);
    splatfx_error_destroy(err);
}

/* Obstacles in a smoke solver (splatfx_scene_add_obstacle): a box and a
 * mesh are taken, a grid effect or a bad desc are refused by field. */
static void test_obstacles(void) {
    splatfx_error* err = splatfx_error_create();
    splatfx_materials* m = NULL;
    splatfx_scene* scene = NULL;
    CHECK_OK(splatfx_materials_create(NULL, &m, err), err);
    CHECK_OK(splatfx_scene_create(&scene, err), err);
    splatfx_smoke_desc sd;
    splatfx_smoke_desc_init(&sd);
    sd.dims[0] = sd.dims[1] = sd.dims[2] = 6;
    uint32_t smoke = 99, fire = 99;
    CHECK_OK(splatfx_scene_add_smoke(scene, m, &sd, NULL, &smoke, err), err);
    CHECK_OK(splatfx_scene_add_fire(scene, m, NULL, NULL, &fire, err), err);
    splatfx_obstacle_desc od;
    splatfx_obstacle_desc_init(&od);
    CHECK(od.shape == SPLATFX_OBSTACLE_BOX && od.size[1] == 1.0f && od.transform[0] == 1.0f && od.transform[1] == 0.0f && od.transform[15] == 1.0f &&
              od.no_slip == 0 && od.triangles == NULL,
          "obstacle desc defaults");
    od.transform[13] = 2.0f; /* a deck 2 units up */
    od.size[0] = 3.0f;
    od.no_slip = 1;
    CHECK_OK(splatfx_scene_add_obstacle(scene, smoke, &od, err), err);
    /* A tetrahedron as a mesh, moving. */
    const float tet[36] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 1, 0};
    splatfx_keyframe keys[2];
    splatfx_keyframe_init(&keys[0]);
    splatfx_keyframe_init(&keys[1]);
    keys[1].time_sec = 2.0;
    keys[1].position[0] = 1.0f;
    splatfx_obstacle_desc_init(&od);
    od.shape = SPLATFX_OBSTACLE_MESH;
    od.triangles = tet;
    od.triangle_count = 4;
    od.motion_keys = keys;
    od.motion_key_count = 2;
    CHECK_OK(splatfx_scene_add_obstacle(scene, smoke, &od, err), err);
    CHECK_FAILS(splatfx_scene_add_obstacle(scene, fire, &od, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "effect 1 has no solver");
    CHECK_FAILS(splatfx_scene_add_obstacle(scene, 7, &od, err), err, SPLATFX_ERROR_NOT_FOUND, "id 7 is not an effect of this scene");
    CHECK_FAILS(splatfx_scene_add_obstacle(scene, smoke, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "desc is NULL");
    float bad[36];
    memcpy(bad, tet, sizeof bad);
    bad[13] = NAN;
    od.triangles = bad;
    CHECK_FAILS(splatfx_scene_add_obstacle(scene, smoke, &od, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "desc.triangles[4] is not finite");
    od.triangles = NULL;
    CHECK_FAILS(splatfx_scene_add_obstacle(scene, smoke, &od, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "desc.triangles is NULL but desc.triangle_count is 4");
    od.triangle_count = 0;
    CHECK_FAILS(splatfx_scene_add_obstacle(scene, smoke, &od, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "desc.triangles must hold three vertices per triangle");
    od.shape = (splatfx_obstacle_shape)9;
    CHECK_FAILS(splatfx_scene_add_obstacle(scene, smoke, &od, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "desc.shape is 9");
    splatfx_obstacle_desc_init(&od);
    od.size[2] = -1.0f;
    CHECK_FAILS(splatfx_scene_add_obstacle(scene, smoke, &od, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "desc.size must be positive and finite");
    splatfx_scene_destroy(scene);
    splatfx_materials_destroy(m);
    splatfx_error_destroy(err);
}

/* A texture-set folder and a scene file, and their missing counterparts. */
static void test_files(void) {
    splatfx_error* err = splatfx_error_create();
    splatfx_materials* m = NULL;
    CHECK_OK(splatfx_materials_create(NULL, &m, err), err);

    splatfx_texture_set* set = NULL;
    CHECK_OK(splatfx_texture_set_load(SPLATFX_SOURCE_DIR "/textures/photo-fire-8x32", &set, err), err);
    CHECK(splatfx_texture_set_count(set) == 8, "photo-fire-8x32 holds %u textures", splatfx_texture_set_count(set));
    splatfx_scene* scene = NULL;
    CHECK_OK(splatfx_scene_create(&scene, err), err);
    splatfx_fire_desc d;
    splatfx_fire_desc_init(&d);
    d.texture_set = set;
    const uint32_t before = splatfx_materials_layer_count(m);
    CHECK_OK(splatfx_scene_add_fire(scene, m, &d, NULL, NULL, err), err);
    splatfx_texture_set_destroy(set); /* copied at add time */
    CHECK(splatfx_materials_layer_count(m) == before + 8, "the folder's 8 textures registered: %u -> %u", before, splatfx_materials_layer_count(m));
    splatfx_scene_destroy(scene);

    splatfx_texture_set* none = (splatfx_texture_set*)&err; /* must be overwritten with NULL */
    CHECK_FAILS(splatfx_texture_set_load("/nonexistent/textures", &none, err), err, SPLATFX_ERROR_FILE, "/nonexistent/textures");
    CHECK(none == NULL, "a failed load leaves *out NULL");

    /* Fig. 1's scene file: two fires, both in its camera's view. */
    scene = NULL;
    CHECK_OK(splatfx_scene_load_file(SPLATFX_SOURCE_DIR "/samples/02-fire-figure1/scene.json", m, NULL, &scene, err), err);
    CHECK(splatfx_scene_effect_count(scene) == 2, "figure 1 has %u effects", splatfx_scene_effect_count(scene));
    const float eye[3] = {0.0f, 4.6f, 16.0f}, target[3] = {0.0f, 4.4f, 0.0f}, up[3] = {0.0f, 1.0f, 0.0f};
    splatfx_camera cam;
    CHECK_OK(splatfx_camera_look_at(eye, target, up, 40.0f * 3.14159265f / 180.0f, 640, 400, 0.05f, 500.0f, &cam, err), err);
    splatfx_frame* frame = NULL;
    CHECK_OK(splatfx_frame_create(&frame, err), err);
    CHECK_OK(splatfx_scene_prepare(scene, 0.25, &cam, m, frame, err), err);
    splatfx_frame_stats st;
    CHECK_OK(splatfx_frame_get_stats(frame, &st, err), err);
    CHECK(st.needed == 2 && st.drawn == 2 && st.splats > 0, "figure 1: needed %llu drawn %llu splats %llu", (unsigned long long)st.needed,
          (unsigned long long)st.drawn, (unsigned long long)st.splats);
    splatfx_scene_destroy(scene);

    /* A file with one effect and one cloud volume: the C ids are the effects' alone (as before the
     * Scene held volumes in the same list); the frame's counts include the volume. */
    scene = NULL;
    CHECK_OK(splatfx_scene_load_file(SPLATFX_SOURCE_DIR "/samples/16-cloud-flight/scene.json", m, NULL, &scene, err), err);
    CHECK(splatfx_scene_effect_count(scene) == 1, "sample 16 has %u effects", splatfx_scene_effect_count(scene));
    CHECK_OK(splatfx_scene_set_effect_enabled(scene, 0, 1, err), err);
    CHECK_FAILS(splatfx_scene_set_effect_enabled(scene, 1, 0, err), err, SPLATFX_ERROR_NOT_FOUND, "id 1 is not an effect of this scene (it has 1)");
    CHECK_OK(splatfx_scene_prepare(scene, 0.0, &cam, m, frame, err), err);
    CHECK_OK(splatfx_frame_get_stats(frame, &st, err), err);
    CHECK(st.declared == 2, "sample 16: declared %llu (the effect and the cloud)", (unsigned long long)st.declared);
    splatfx_scene_destroy(scene);

    splatfx_scene* missing = (splatfx_scene*)&err;
    CHECK_FAILS(splatfx_scene_load_file("/nonexistent/scene.json", m, NULL, &missing, err), err, SPLATFX_ERROR_FILE, "/nonexistent/scene.json");
    CHECK(missing == NULL, "a failed load leaves *out NULL");
    /* A file that exists but is not a scene: the message names the field. */
    CHECK_FAILS(splatfx_scene_load_file(SPLATFX_SOURCE_DIR "/textures/photo-fire-8x32/manifest.json", m, NULL, &missing, err), err,
                SPLATFX_ERROR_FILE, "format");
    splatfx_frame_destroy(frame);
    splatfx_materials_destroy(m);
    splatfx_error_destroy(err);
}

/* NULL handles, handles of the wrong type, fields out of range, NaN: an error naming it, no crash. */
static void test_bad_input(void) {
    splatfx_error* err = splatfx_error_create();
    splatfx_materials* m = NULL;
    splatfx_scene* scene = NULL;
    splatfx_frame* frame = NULL;
    CHECK_OK(splatfx_materials_create(NULL, &m, err), err);
    CHECK_OK(splatfx_scene_create(&scene, err), err);
    CHECK_OK(splatfx_frame_create(&frame, err), err);
    splatfx_camera cam = front_camera(err);
    const uint32_t layers = splatfx_materials_layer_count(m);

    /* NULL handles. */
    CHECK_FAILS(splatfx_scene_prepare(NULL, 0.0, &cam, m, frame, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "splatfx_scene_prepare: scene is NULL");
    CHECK_FAILS(splatfx_scene_prepare(scene, 0.0, &cam, NULL, frame, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "materials is NULL");
    CHECK_FAILS(splatfx_scene_prepare(scene, 0.0, &cam, m, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "frame is NULL");
    CHECK_FAILS(splatfx_scene_prepare(scene, 0.0, NULL, m, frame, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "camera is NULL");
    CHECK_FAILS(splatfx_scene_add_fire(NULL, m, NULL, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "scene is NULL");
    CHECK_FAILS(splatfx_scene_add_smoke(scene, NULL, NULL, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "materials is NULL");
    CHECK_FAILS(splatfx_frame_get_stats(NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "out is NULL");
    splatfx_frame_stats st;
    CHECK_FAILS(splatfx_frame_get_stats(NULL, &st, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "frame is NULL");
    splatfx_scene* loaded = (splatfx_scene*)&err;
    CHECK_FAILS(splatfx_scene_load_file(NULL, m, NULL, &loaded, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "path is NULL");
    CHECK(loaded == NULL, "a failed load sets *out to NULL");
    CHECK_FAILS(splatfx_texture_set_load(NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "out is NULL");
    CHECK_FAILS(splatfx_headless_context_make_current(NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "context is NULL");
    CHECK(splatfx_headless_context_renderer(NULL) == NULL, "renderer string of NULL");
    CHECK(splatfx_scene_effect_count(NULL) == 0 && splatfx_materials_layer_count(NULL) == 0 && splatfx_texture_set_count(NULL) == 0,
          "counts of NULL handles");

    /* A handle of another type (through an FFI every handle is a void*). */
    CHECK_FAILS(splatfx_scene_prepare(scene, 0.0, &cam, (const splatfx_materials*)frame, frame, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "materials is not a splatfx_materials");
    CHECK_FAILS(splatfx_scene_add_fire((splatfx_scene*)m, m, NULL, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "scene is not a splatfx_scene");

    /* Time. */
    CHECK_FAILS(splatfx_scene_prepare(scene, NAN, &cam, m, frame, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "time_sec is nan");
    CHECK_FAILS(splatfx_scene_prepare(scene, INFINITY, &cam, m, frame, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "time_sec is inf");
    CHECK_FAILS(splatfx_scene_prepare(scene, -1.0, &cam, m, frame, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "time_sec is -1");
    /* Past what the dynamics hold exactly (kMaxTimeSec): a fire at 1e300 came back empty with SPLATFX_OK. */
    CHECK_FAILS(splatfx_scene_prepare(scene, 1e300, &cam, m, frame, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "splatfx_scene_prepare: time_sec is 1e+300; expected seconds <= 262144 (kMaxTimeSec");

    /* Cameras. */
    splatfx_camera bad = cam;
    bad.view[3] = NAN;
    CHECK_FAILS(splatfx_scene_prepare(scene, 0.0, &bad, m, frame, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "camera.view[3] is nan");
    bad = cam;
    bad.viewport[0] = 0;
    CHECK_FAILS(splatfx_scene_prepare(scene, 0.0, &bad, m, frame, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "camera.viewport[0] is 0");
    float zero[16];
    memset(zero, 0, sizeof zero);
    CHECK_FAILS(splatfx_camera_from_matrices(cam.view, zero, 64, 64, &bad, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "camera.proj is singular");
    CHECK_FAILS(splatfx_camera_from_matrices(cam.view, cam.proj, 64, -1, &bad, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "camera.viewport[1] is -1");
    CHECK_OK(splatfx_camera_from_matrices(cam.view, cam.proj, 160, 120, &bad, err), err);
    CHECK(memcmp(&bad, &cam, sizeof cam) == 0, "from_matrices copies the host's matrices as they are");
    const float p[3] = {1.0f, 2.0f, 3.0f}, up[3] = {0.0f, 1.0f, 0.0f}, upAlong[3] = {0.0f, 0.0f, 1.0f}, q[3] = {1.0f, 2.0f, 4.0f};
    CHECK_FAILS(splatfx_camera_look_at(p, p, up, 0.8f, 64, 64, 0.1f, 100.0f, &bad, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "eye and target are the same point");
    CHECK_FAILS(splatfx_camera_look_at(p, q, upAlong, 0.8f, 64, 64, 0.1f, 100.0f, &bad, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "up is zero or parallel");
    CHECK_FAILS(splatfx_camera_look_at(p, q, up, NAN, 64, 64, 0.1f, 100.0f, &bad, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "fov_y is nan");
    CHECK_FAILS(splatfx_camera_look_at(p, q, up, 0.8f, 64, 64, 0.0f, 100.0f, &bad, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "near_plane 0");

    /* Desc fields, and nothing added on failure. */
    splatfx_materials_desc md;
    splatfx_materials_desc_init(&md);
    CHECK(md.layer_size == 32 && md.color_table_size == 256, "materials desc defaults");
    md.layer_size = 2;
    splatfx_materials* m2 = (splatfx_materials*)&err;
    CHECK_FAILS(splatfx_materials_create(&md, &m2, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "desc.layer_size is 2");
    CHECK(m2 == NULL, "a failed create sets *out to NULL");
    splatfx_fire_desc fd;
    splatfx_fire_desc_init(&fd);
    fd.dims[1] = 0;
    CHECK_FAILS(splatfx_scene_add_fire(scene, m, &fd, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "FireDesc.dims");
    CHECK(splatfx_materials_layer_count(m) == layers, "a failed add registered layers: %u -> %u", layers, splatfx_materials_layer_count(m));
    splatfx_fire_desc_init(&fd);
    fd.dims[0] = fd.dims[1] = fd.dims[2] = 1 << 20; /* 2^60 voxels: refused before anything is allocated */
    CHECK_FAILS(splatfx_scene_add_fire(scene, m, &fd, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "FireDesc.dims");
    splatfx_fire_desc_init(&fd);
    fd.dims[2] = -5;
    CHECK_FAILS(splatfx_scene_add_fire(scene, m, &fd, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "FireDesc.dims");
    splatfx_fire_desc_init(&fd);
    fd.spacing[0] = 1e30f;
    {
        /* Huge but finite spacing: the C++ grid check decides; either way an answer, not a crash. */
        const splatfx_status s = splatfx_scene_add_fire(scene, m, &fd, NULL, NULL, err);
        CHECK(s == SPLATFX_OK || s == SPLATFX_ERROR_INVALID_ARGUMENT, "spacing 1e30: %s", splatfx_status_name(s));
        if (s == SPLATFX_OK) {
            CHECK_OK(splatfx_scene_prepare(scene, 0.0, &cam, m, frame, err), err);
            CHECK_OK(splatfx_scene_set_effect_enabled(scene, splatfx_scene_effect_count(scene) - 1, 0, err), err);
        }
    }
    CHECK(splatfx_scene_effect_count(scene) <= 1, "failed adds added effects");
    const uint32_t effectsBefore = splatfx_scene_effect_count(scene);
    splatfx_fire_desc_init(&fd);
    fd.opacity = NAN;
    CHECK_FAILS(splatfx_scene_add_fire(scene, m, &fd, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "desc.opacity is nan");
    splatfx_fire_desc_init(&fd);
    fd.texture_count = 0;
    CHECK_FAILS(splatfx_scene_add_fire(scene, m, &fd, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "FireDesc.textureCount must be in [1, 256], got 0");
    splatfx_fire_desc_init(&fd);
    fd.texture_set = (const splatfx_texture_set*)scene;
    CHECK_FAILS(splatfx_scene_add_fire(scene, m, &fd, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "desc.texture_set is not a splatfx_texture_set");
    splatfx_smoke_desc sd;
    splatfx_smoke_desc_init(&sd);
    sd.wind_world[2] = INFINITY;
    CHECK_FAILS(splatfx_scene_add_smoke(scene, m, &sd, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "desc.wind_world[2] is inf");
    splatfx_effect_options o;
    splatfx_effect_options_init(&o);
    o.range_world = 0.0f;
    CHECK_FAILS(splatfx_scene_add_steam(scene, m, NULL, &o, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "options.range_world is 0");
    splatfx_effect_options_init(&o);
    o.opacity_scale = NAN;
    CHECK_FAILS(splatfx_scene_add_ghosts(scene, m, NULL, &o, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "options.opacity_scale is nan");
    splatfx_embers_desc ed;
    splatfx_embers_desc_init(&ed);
    ed.rate_per_sec = -1.0f;
    CHECK_FAILS(splatfx_scene_add_embers(scene, m, &ed, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "EmbersDesc.ratePerSec must be in [0, 1e9], got -1");
    splatfx_embers_desc_init(&ed);
    ed.rate_per_sec = 1e9f; /* a particle memory bomb: refused against the particle budget */
    CHECK_FAILS(splatfx_scene_add_embers(scene, m, &ed, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "exceeds maxParticles");
    splatfx_embers_desc_init(&ed);
    ed.velocity[1] = NAN;
    CHECK_FAILS(splatfx_scene_add_embers(scene, m, &ed, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "desc.velocity[1] is nan");
    CHECK(splatfx_scene_effect_count(scene) == effectsBefore, "failed adds added %u effects", splatfx_scene_effect_count(scene) - effectsBefore);

    /* A scene's effects index the materials they were built with. */
    {
        splatfx_scene* own = NULL;
        splatfx_materials* other = NULL;
        CHECK_OK(splatfx_scene_create(&own, err), err);
        CHECK_OK(splatfx_materials_create(NULL, &other, err), err);
        CHECK_OK(splatfx_scene_add_fire(own, m, NULL, NULL, NULL, err), err);
        CHECK_FAILS(splatfx_scene_prepare(own, 0.0, &cam, other, frame, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                    "materials are not the ones this scene's effects were built with");
        CHECK_FAILS(splatfx_scene_add_steam(own, other, NULL, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                    "materials are not the ones this scene's effects were built with");
        CHECK(splatfx_scene_effect_count(own) == 1, "an add with other materials added an effect");
        splatfx_materials_destroy(other);
        splatfx_scene_destroy(own);
    }

    /* GL calls without a current context: an error, not the loader's abort. */
    splatfx_renderer* r = (splatfx_renderer*)&err;
    CHECK_FAILS(splatfx_renderer_create(NULL, &r, err), err, SPLATFX_ERROR_GL, "no OpenGL context is current");
    CHECK(r == NULL, "a failed create sets *out to NULL");
    splatfx_renderer_desc rd;
    splatfx_renderer_desc_init(&rd);
    rd.resolution_scale = 3;
    CHECK_FAILS(splatfx_renderer_create(&rd, &r, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "desc.resolution_scale is 3; expected 1, 2 or 4");
    splatfx_host_target target;
    splatfx_host_target_init(&target);
    CHECK_FAILS(splatfx_renderer_render(NULL, m, frame, &target, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "renderer is NULL");
    CHECK_FAILS(splatfx_renderer_upload((splatfx_renderer*)scene, m, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "renderer is not a splatfx_renderer");

    splatfx_frame_destroy(frame);
    splatfx_scene_destroy(scene);
    splatfx_materials_destroy(m);
    splatfx_error_destroy(err);
}

/* Every handle type destroyed twice, destroyed through a pointer of another handle type, and
 * destroyed as a stray pointer: each ignored, never read through (a double free before, for the
 * error object); a destroyed handle passed to a call is an error naming it, not a read of freed
 * memory. Under ASan any read of a freed handle fails this test. */
static void test_destroy_twice(void) {
    splatfx_error* err = splatfx_error_create();
    splatfx_materials* m = NULL;
    splatfx_scene* scene = NULL;
    splatfx_frame* frame = NULL;
    splatfx_texture_set* set = NULL;
    CHECK_OK(splatfx_materials_create(NULL, &m, err), err);
    CHECK_OK(splatfx_scene_create(&scene, err), err);
    CHECK_OK(splatfx_frame_create(&frame, err), err);
    CHECK_OK(splatfx_texture_set_load(SPLATFX_SOURCE_DIR "/textures/photo-fire-8x32", &set, err), err);

    /* A destroy through the wrong type leaves the handle alive and usable. */
    splatfx_scene_destroy((splatfx_scene*)m);
    splatfx_materials_destroy((splatfx_materials*)err);
    splatfx_error_destroy((splatfx_error*)frame);
    splatfx_frame_destroy((splatfx_frame*)set);
    splatfx_texture_set_destroy((splatfx_texture_set*)scene);
    CHECK(splatfx_materials_layer_count(m) == 1, "materials destroyed as a scene: %u layers", splatfx_materials_layer_count(m));
    CHECK(splatfx_texture_set_count(set) == 8, "a texture set destroyed as a frame: %u textures", splatfx_texture_set_count(set));
    CHECK_OK(splatfx_scene_add_fire(scene, m, NULL, NULL, NULL, err), err); /* the scene, materials and error object still work */
    splatfx_camera cam = front_camera(err);
    CHECK_OK(splatfx_scene_prepare(scene, 0.5, &cam, m, frame, err), err);
    /* A stray pointer (not a handle the library returned) is ignored too, as is NULL. */
    uint64_t stray[8] = {0};
    splatfx_scene_destroy((splatfx_scene*)stray);
    splatfx_error_destroy((splatfx_error*)stray);
    splatfx_error_destroy(NULL);

    /* Each type destroyed twice; then used: an error that says it was destroyed. */
    splatfx_texture_set_destroy(set);
    splatfx_texture_set_destroy(set);
    CHECK(splatfx_texture_set_count(set) == 0, "a destroyed texture set counts %u textures", splatfx_texture_set_count(set));
    splatfx_fire_desc fd;
    splatfx_fire_desc_init(&fd);
    fd.texture_set = set;
    CHECK_FAILS(splatfx_scene_add_fire(scene, m, &fd, NULL, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "desc.texture_set is not a splatfx_texture_set (it was destroyed, or is not a handle this library returned)");
    splatfx_frame_destroy(frame);
    splatfx_frame_destroy(frame);
    CHECK_FAILS(splatfx_scene_prepare(scene, 0.5, &cam, m, frame, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "splatfx_scene_prepare: frame is not a splatfx_frame (it was destroyed");
    splatfx_scene_destroy(scene);
    splatfx_scene_destroy(scene);
    CHECK(splatfx_scene_effect_count(scene) == 0, "a destroyed scene has %u effects", splatfx_scene_effect_count(scene));
    CHECK_FAILS(splatfx_scene_set_effect_enabled(scene, 0, 0, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "scene is not a splatfx_scene (it was destroyed");
    CHECK_FAILS(splatfx_scene_set_hdr_lit(scene, 1, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "scene is not a splatfx_scene (it was destroyed");
    CHECK(splatfx_scene_hdr_lit(scene) == 0, "HDR lit colour of a destroyed scene");
    splatfx_materials_destroy(m);
    splatfx_materials_destroy(m);
    CHECK(splatfx_materials_layer_count(m) == 0, "destroyed materials have %u layers", splatfx_materials_layer_count(m));

    /* The error object: destroyed twice, then read and passed to a call (which must not write into it). */
    splatfx_error_destroy(err);
    splatfx_error_destroy(err);
    CHECK(splatfx_error_status(err) == SPLATFX_ERROR_INVALID_ARGUMENT, "status of a destroyed error object: %s",
          splatfx_status_name(splatfx_error_status(err)));
    CHECK(strstr(splatfx_error_message(err), "error is not a splatfx_error (it was destroyed") != NULL, "message of a destroyed error object: %s",
          splatfx_error_message(err));
    CHECK(splatfx_scene_create(NULL, err) == SPLATFX_ERROR_INVALID_ARGUMENT, "a call given a destroyed error object still returns its status");
}

int main(void) {
    test_version_and_error_object();
    test_fire_prepares();
    test_every_preset();
    test_motion();
    test_obstacles();
    test_files();
    test_bad_input();
    test_destroy_twice();
    if (g_failures) {
        fprintf(stderr, "capi_test: %d check(s) failed\n", g_failures);
        return 1;
    }
    printf("capi_test: all checks passed\n");
    return 0;
}
