/* The C API end to end in C11: a headless context from splatfx_c.h, the test's own framebuffer with a
 * depth texture (created with plain GL, as a host would), a fire prepared and drawn through
 * splatfx_renderer_render, pixels read back: the fire shows where the host depth is behind it and is
 * hidden exactly where the host depth is in front; plus the renderer's error paths. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <epoxy/gl.h>

#include "check.h"

enum { W = 64, H = 96, BAND = H / 3 };
static const float kBackground[4] = {0.05f, 0.1f, 0.2f, 1.0f};

/* What the opaque hook draws: the background, and each band of rows (bottom, middle, top) at its
 * own depth, as if a wall stood there. */
typedef struct Host {
    float band_depth[3];
    int opaque_calls, transparent_calls, transparent_after_opaque;
} Host;

static void draw_opaque(void* user) {
    Host* h = (Host*)user;
    ++h->opaque_calls;
    glDepthMask(GL_TRUE);
    glClearColor(kBackground[0], kBackground[1], kBackground[2], kBackground[3]);
    glClear(GL_COLOR_BUFFER_BIT);
    glEnable(GL_SCISSOR_TEST);
    for (int b = 0; b < 3; ++b) {
        glScissor(0, b * BAND, W, BAND);
        glClearDepth(h->band_depth[b]);
        glClear(GL_DEPTH_BUFFER_BIT);
    }
    glDisable(GL_SCISSOR_TEST);
}

static void draw_transparent(void* user) {
    Host* h = (Host*)user;
    ++h->transparent_calls;
    h->transparent_after_opaque = h->opaque_calls == 1;
}

/* Window depth (default glDepthRange) of a surface `dist` world units in front of the eye, from the
 * camera's own projection: z_ndc = (P[2][2] z + P[3][2]) / -z with z = -dist (column-major P[10], P[14]). */
static float depth_at(const splatfx_camera* cam, float dist) {
    const float zEye = -dist;
    const float ndc = (cam->proj[10] * zEye + cam->proj[14]) / dist;
    return 0.5f * ndc + 0.5f;
}

typedef struct Target {
    GLuint fbo, color, depth;
} Target;

static Target make_target(void) {
    Target t;
    glCreateTextures(GL_TEXTURE_2D, 1, &t.color);
    glTextureStorage2D(t.color, 1, GL_RGBA8, W, H);
    glCreateTextures(GL_TEXTURE_2D, 1, &t.depth);
    glTextureStorage2D(t.depth, 1, GL_DEPTH_COMPONENT32F, W, H);
    glCreateFramebuffers(1, &t.fbo);
    glNamedFramebufferTexture(t.fbo, GL_COLOR_ATTACHMENT0, t.color, 0);
    glNamedFramebufferTexture(t.fbo, GL_DEPTH_ATTACHMENT, t.depth, 0);
    CHECK(glCheckNamedFramebufferStatus(t.fbo, GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE, "incomplete framebuffer");
    return t;
}

static void read_pixels(const Target* t, unsigned char* out) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t->fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, out);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
}

static void write_ppm(const char* name, const unsigned char* rgba) {
    FILE* f = fopen(name, "wb");
    if (!f) return;
    fprintf(f, "P6\n%d %d\n255\n", W, H);
    for (int y = H - 1; y >= 0; --y)
        for (int x = 0; x < W; ++x) fwrite(rgba + 4 * (y * W + x), 1, 3, f);
    fclose(f);
    fprintf(stderr, "wrote %s\n", name);
}

/* In rows [y0, y1): pixels that differ from the background (as this framebuffer stores it), the
 * largest red increase over it, and the summed red and blue of those pixels. */
typedef struct BandStats {
    int changed, max_red_gain;
    long red, blue;
} BandStats;

static BandStats band_stats(const unsigned char* img, const unsigned char* bg, int y0, int y1) {
    BandStats s = {0, 0, 0, 0};
    for (int y = y0; y < y1; ++y)
        for (int x = 0; x < W; ++x) {
            const unsigned char* p = img + 4 * (y * W + x);
            if (memcmp(p, bg, 3) == 0) continue;
            ++s.changed;
            if (p[0] - bg[0] > s.max_red_gain) s.max_red_gain = p[0] - bg[0];
            s.red += p[0];
            s.blue += p[2];
        }
    return s;
}

static int rows_equal(const unsigned char* a, const unsigned char* b, int y0, int y1) {
    return memcmp(a + 4 * y0 * W, b + 4 * y0 * W, (size_t)4 * W * (y1 - y0)) == 0;
}

/* The fire against three walls, at a resolution scale. */
static void test_fire_against_host_depth(splatfx_error* err, int scale) {
    splatfx_materials* m = NULL;
    splatfx_scene* scene = NULL;
    splatfx_frame* frame = NULL;
    splatfx_renderer* r = NULL;
    CHECK_OK(splatfx_materials_create(NULL, &m, err), err);
    CHECK_OK(splatfx_scene_create(&scene, err), err);
    CHECK_OK(splatfx_frame_create(&frame, err), err);
    splatfx_renderer_desc rd;
    splatfx_renderer_desc_init(&rd);
    rd.resolution_scale = scale;
    CHECK_OK(splatfx_renderer_create(&rd, &r, err), err);

    /* A 7x12x5 fire (6 world units tall, 3.5 wide, 2.5 deep, base at the origin), seen from 12
     * units: its splats lie between ~10.75 - 1 and ~13.25 + 1 units from the eye (a splat reaches
     * at most about one voxel spacing, 0.5, beyond its centre; 1 is a margin over that). */
    splatfx_fire_desc fd;
    splatfx_fire_desc_init(&fd);
    fd.dims[1] = 12;
    CHECK_OK(splatfx_scene_add_fire(scene, m, &fd, NULL, NULL, err), err);
    const float eye[3] = {0.0f, 3.0f, 12.0f}, at[3] = {0.0f, 3.0f, 0.0f}, up[3] = {0.0f, 1.0f, 0.0f};
    splatfx_camera cam;
    CHECK_OK(splatfx_camera_look_at(eye, at, up, 0.6f, W, H, 0.1f, 100.0f, &cam, err), err);
    CHECK_OK(splatfx_scene_prepare(scene, 0.5, &cam, m, frame, err), err);
    splatfx_frame_stats fs;
    CHECK_OK(splatfx_frame_get_stats(frame, &fs, err), err);
    CHECK(fs.splats > 0, "the fire has no splats");

    Target t = make_target();
    splatfx_host_target target;
    splatfx_host_target_init(&target);
    target.framebuffer = t.fbo;
    target.depth_texture = t.depth;
    target.draw_opaque = draw_opaque;
    target.draw_transparent = draw_transparent;

    /* Reference: no wall anywhere (depth 1, the far plane). */
    Host open = {{1.0f, 1.0f, 1.0f}, 0, 0, 0};
    target.user_data = &open;
    CHECK_OK(splatfx_renderer_render(r, m, frame, &target, err), err);
    CHECK(open.opaque_calls == 1 && open.transparent_calls == 1 && open.transparent_after_opaque, "hooks: opaque %d, transparent %d, in order %d",
          open.opaque_calls, open.transparent_calls, open.transparent_after_opaque);
    splatfx_render_stats rs;
    CHECK_OK(splatfx_renderer_get_stats(r, &rs, err), err);
    CHECK(rs.splats == fs.splats && rs.resolution_scale == scale, "drew %llu of %llu splats at scale %d", (unsigned long long)rs.splats,
          (unsigned long long)fs.splats, rs.resolution_scale);
    static unsigned char reference[4 * W * H], walled[4 * W * H], background[4 * W * H];
    read_pixels(&t, reference);

    /* The background as this RGBA8 framebuffer stores it (the hook's clear colour, rounded). */
    glClearNamedFramebufferfv(t.fbo, GL_COLOR, 0, kBackground);
    read_pixels(&t, background);
    const unsigned char* bg = background;

    /* Walls: bottom band in front of the fire (5 units), middle band behind it (30), top open. */
    Host walls = {{depth_at(&cam, 5.0f), depth_at(&cam, 30.0f), 1.0f}, 0, 0, 0};
    target.user_data = &walls;
    CHECK_OK(splatfx_renderer_render(r, m, frame, &target, err), err);
    read_pixels(&t, walled);

    /* At full resolution every splat fragment is depth-tested exactly, so the bands are exact to
     * the row. At 1/scale per axis a reduced pixel covers scale rows and the depth-aware upsampling
     * reads one reduced pixel beyond, so rows within 2 * scale of a band edge may mix the bands:
     * they are left out. */
    const int margin = scale == 1 ? 0 : 2 * scale;
    const BandStats refA = band_stats(reference, bg, 0, BAND - margin);
    const BandStats refB = band_stats(reference, bg, BAND + margin, 2 * BAND - margin);
    /* The fire must be there to be hidden: clearly visible (a red gain of 0.2, about 51/255, as the
     * C++ frame-renderer test asks of a fire over a wall) and fire-coloured (more red than blue). */
    CHECK(refA.max_red_gain >= 51 && refA.red > refA.blue, "scale %d: no fire in the bottom band without a wall (gain %d)", scale, refA.max_red_gain);
    CHECK(refB.max_red_gain >= 51 && refB.red > refB.blue, "scale %d: no fire in the middle band without a wall (gain %d)", scale, refB.max_red_gain);
    const BandStats hidden = band_stats(walled, bg, 0, BAND - margin);
    CHECK(hidden.changed == 0, "scale %d: %d pixels of fire drawn over a wall in front of it", scale, hidden.changed);
    CHECK(rows_equal(walled, reference, BAND + margin, 2 * BAND - margin), "scale %d: a wall behind the fire changed the fire in front of it", scale);
    CHECK(rows_equal(walled, reference, 2 * BAND + margin, H), "scale %d: the open band differs from the reference", scale);
    if (g_failures) {
        char name[64];
        snprintf(name, sizeof name, "capi_gl_reference_scale%d.ppm", scale);
        write_ppm(name, reference);
        snprintf(name, sizeof name, "capi_gl_walled_scale%d.ppm", scale);
        write_ppm(name, walled);
    }
    printf("scale %d: %llu splats; reference bottom band %d changed pixels (red gain %d), middle %d; walled bottom %d\n", scale,
           (unsigned long long)fs.splats, refA.changed, refA.max_red_gain, refB.changed, hidden.changed);

    glDeleteFramebuffers(1, &t.fbo);
    glDeleteTextures(1, &t.color);
    glDeleteTextures(1, &t.depth);
    splatfx_renderer_destroy(r);
    splatfx_frame_destroy(frame);
    splatfx_scene_destroy(scene);
    splatfx_materials_destroy(m);
}

/* What render refuses, each with a message, and switching materials on one renderer. */
static void test_render_errors(splatfx_error* err) {
    splatfx_materials *m = NULL, *m2 = NULL;
    splatfx_scene* scene = NULL;
    splatfx_frame *frame = NULL, *fresh = NULL;
    splatfx_renderer* r = NULL;
    CHECK_OK(splatfx_materials_create(NULL, &m, err), err);
    CHECK_OK(splatfx_materials_create(NULL, &m2, err), err);
    CHECK_OK(splatfx_scene_create(&scene, err), err);
    CHECK_OK(splatfx_frame_create(&frame, err), err);
    CHECK_OK(splatfx_frame_create(&fresh, err), err);
    CHECK_OK(splatfx_renderer_create(NULL, &r, err), err);
    CHECK_OK(splatfx_scene_add_fire(scene, m, NULL, NULL, NULL, err), err);
    const float eye[3] = {0.0f, 5.0f, 20.0f}, at[3] = {0.0f, 5.0f, 0.0f}, up[3] = {0.0f, 1.0f, 0.0f};
    splatfx_camera cam;
    CHECK_OK(splatfx_camera_look_at(eye, at, up, 0.8f, W, H, 0.1f, 100.0f, &cam, err), err);
    CHECK_OK(splatfx_scene_prepare(scene, 0.25, &cam, m, frame, err), err);
    Target t = make_target();
    splatfx_host_target target;
    splatfx_host_target_init(&target);
    target.framebuffer = t.fbo;
    target.depth_texture = t.depth;

    CHECK_FAILS(splatfx_renderer_render(r, m, fresh, &target, err), err, SPLATFX_ERROR_INVALID_STATE, "frame has not been prepared");
    CHECK_FAILS(splatfx_renderer_render(r, m2, frame, &target, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "materials are not the ones the frame was prepared with");
    CHECK_FAILS(splatfx_renderer_render(r, m, frame, NULL, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "target is NULL");
    splatfx_host_target bad = target;
    bad.framebuffer = 12345;
    CHECK_FAILS(splatfx_renderer_render(r, m, frame, &bad, err), err, SPLATFX_ERROR_GL, "target->framebuffer 12345 is not a framebuffer object");
    bad = target;
    bad.depth_texture = t.color;
    CHECK_FAILS(splatfx_renderer_render(r, m, frame, &bad, err), err, SPLATFX_ERROR_GL, "has no depth component");
    bad = target;
    bad.depth_texture = 54321;
    CHECK_FAILS(splatfx_renderer_render(r, m, frame, &bad, err), err, SPLATFX_ERROR_GL, "is not a texture");
    bad = target;
    bad.width = W / 2;
    bad.height = H;
    CHECK_FAILS(splatfx_renderer_render(r, m, frame, &bad, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "but the frame's camera viewport is 64, 96");
    bad = target;
    bad.x = -1;
    CHECK_FAILS(splatfx_renderer_render(r, m, frame, &bad, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "target->x, y are -1, 0");

    /* One renderer, other materials: it uploads them in full (their layers, not the first ones'). */
    CHECK_OK(splatfx_renderer_render(r, m, frame, &target, err), err);
    splatfx_scene* scene2 = NULL;
    CHECK_OK(splatfx_scene_create(&scene2, err), err);
    CHECK_OK(splatfx_scene_add_steam(scene2, m2, NULL, NULL, NULL, err), err);
    CHECK_OK(splatfx_scene_prepare(scene2, 0.25, &cam, m2, fresh, err), err);
    glClearNamedFramebufferfv(t.fbo, GL_COLOR, 0, kBackground);
    {
        const float one = 1.0f;
        glClearNamedFramebufferfv(t.fbo, GL_DEPTH, 0, &one);
    }
    CHECK_OK(splatfx_renderer_render(r, m2, fresh, &target, err), err);
    static unsigned char img[4 * W * H], bgimg[4 * W * H];
    read_pixels(&t, img);
    glClearNamedFramebufferfv(t.fbo, GL_COLOR, 0, kBackground);
    read_pixels(&t, bgimg);
    const BandStats steam = band_stats(img, bgimg, 0, H);
    CHECK(steam.changed > 0, "steam drawn with the second materials left no pixel");

    /* Materials destroyed after prepare: render refuses the frame. */
    splatfx_materials_destroy(m2);
    CHECK_FAILS(splatfx_renderer_render(r, m, fresh, &target, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                "the materials the frame was prepared with were destroyed");

    CHECK(glGetError() == GL_NO_ERROR, "a GL error was raised");
    glDeleteFramebuffers(1, &t.fbo);
    glDeleteTextures(1, &t.color);
    glDeleteTextures(1, &t.depth);
    splatfx_renderer_destroy(r);
    splatfx_scene_destroy(scene2);
    splatfx_frame_destroy(fresh);
    splatfx_frame_destroy(frame);
    splatfx_scene_destroy(scene);
    splatfx_materials_destroy(m);
}

/* ---- handles destroyed during a render, misused contexts, GL errors ---- */

/* One fire, prepared, and a renderer, in the current context: what the tests below draw. */
typedef struct Drawn {
    splatfx_materials* m;
    splatfx_scene* scene;
    splatfx_frame* frame;
    splatfx_renderer* r;
    uint64_t splats;
} Drawn;

static Drawn make_drawn(splatfx_error* err) {
    Drawn d = {NULL, NULL, NULL, NULL, 0};
    CHECK_OK(splatfx_materials_create(NULL, &d.m, err), err);
    CHECK_OK(splatfx_scene_create(&d.scene, err), err);
    CHECK_OK(splatfx_frame_create(&d.frame, err), err);
    CHECK_OK(splatfx_renderer_create(NULL, &d.r, err), err);
    CHECK_OK(splatfx_scene_add_fire(d.scene, d.m, NULL, NULL, NULL, err), err);
    const float eye[3] = {0.0f, 5.0f, 20.0f}, at[3] = {0.0f, 5.0f, 0.0f}, up[3] = {0.0f, 1.0f, 0.0f};
    splatfx_camera cam;
    CHECK_OK(splatfx_camera_look_at(eye, at, up, 0.8f, W, H, 0.1f, 100.0f, &cam, err), err);
    CHECK_OK(splatfx_scene_prepare(d.scene, 0.25, &cam, d.m, d.frame, err), err);
    splatfx_frame_stats fs;
    CHECK_OK(splatfx_frame_get_stats(d.frame, &fs, err), err);
    d.splats = fs.splats;
    CHECK(d.splats > 0, "the fire has no splats");
    return d;
}

/* A target with nothing drawn in it yet: the background, and depth 1 (nothing hides the fire). */
static Target make_clear_target(void) {
    Target t = make_target();
    const float far_depth = 1.0f;
    glClearNamedFramebufferfv(t.fbo, GL_COLOR, 0, kBackground);
    glClearNamedFramebufferfv(t.fbo, GL_DEPTH, 0, &far_depth);
    return t;
}

/* Destroying what is left (each destroy ignores what a hook destroyed already). */
static void free_drawn(Drawn* d) {
    splatfx_renderer_destroy(d->r);
    splatfx_frame_destroy(d->frame);
    splatfx_scene_destroy(d->scene);
    splatfx_materials_destroy(d->m);
}

enum { KILL_NOTHING, KILL_FRAME, KILL_MATERIALS, KILL_RENDERER, KILL_SCENE, KILL_ERROR, KILL_CONTEXT, REENTER };

/* A host hook that destroys a handle of the render that called it (or calls back into it). */
typedef struct Killer {
    int what;
    Drawn* d;
    splatfx_error* error;              /* the render's own error object (KILL_ERROR) */
    splatfx_headless_context* context; /* the current context (KILL_CONTEXT) */
    const splatfx_host_target* target; /* for REENTER */
    splatfx_status nested_render, nested_prepare, nested_upload;
    char nested_message[3][512];
} Killer;

static void killing_hook(void* user) {
    Killer* k = (Killer*)user;
    switch (k->what) {
    case KILL_FRAME: splatfx_frame_destroy(k->d->frame); break;
    case KILL_MATERIALS: splatfx_materials_destroy(k->d->m); break;
    case KILL_RENDERER: splatfx_renderer_destroy(k->d->r); break;
    case KILL_SCENE: splatfx_scene_destroy(k->d->scene); break;
    case KILL_ERROR: splatfx_error_destroy(k->error); break;
    case KILL_CONTEXT:
        splatfx_renderer_destroy(k->d->r); /* the renderer first, as a host must; both deferred */
        splatfx_headless_context_destroy(k->context);
        break;
    case REENTER: {
        splatfx_error* e = splatfx_error_create();
        k->nested_render = splatfx_renderer_render(k->d->r, k->d->m, k->d->frame, k->target, e);
        snprintf(k->nested_message[0], sizeof k->nested_message[0], "%s", splatfx_error_message(e));
        splatfx_camera cam;
        const float eye[3] = {0.0f, 5.0f, 20.0f}, at[3] = {0.0f, 5.0f, 0.0f}, up[3] = {0.0f, 1.0f, 0.0f};
        splatfx_camera_look_at(eye, at, up, 0.8f, W, H, 0.1f, 100.0f, &cam, e);
        k->nested_prepare = splatfx_scene_prepare(k->d->scene, 0.5, &cam, k->d->m, k->d->frame, e);
        snprintf(k->nested_message[1], sizeof k->nested_message[1], "%s", splatfx_error_message(e));
        k->nested_upload = splatfx_renderer_upload(k->d->r, k->d->m, e);
        snprintf(k->nested_message[2], sizeof k->nested_message[2], "%s", splatfx_error_message(e));
        splatfx_error_destroy(e);
        break;
    }
    }
}

/* A hook that destroys the frame, materials, renderer or the render's error object: the destroy is
 * deferred to the end of the render (which finishes drawing with them), the render says so, and the
 * handle is gone after it. The scene is not drawn with: destroying it is fine. A hook calling back
 * into its own renderer, or preparing the frame being drawn, is refused. */
static void test_hooks_that_destroy(splatfx_error* err) {
    Target t = make_clear_target();
    splatfx_host_target target;
    splatfx_host_target_init(&target);
    target.framebuffer = t.fbo;
    target.depth_texture = t.depth;
    const char* names[] = {"frame (a splatfx_frame)", "materials (a splatfx_materials)", "renderer (a splatfx_renderer)"};
    for (int kill = KILL_FRAME; kill <= KILL_RENDERER; ++kill)
        for (int transparent = 0; transparent < 2; ++transparent) {
            Drawn d = make_drawn(err);
            Killer k = {kill, &d, NULL, NULL, NULL, SPLATFX_OK, SPLATFX_OK, SPLATFX_OK, {{0}}};
            target.draw_opaque = transparent ? NULL : killing_hook;
            target.draw_transparent = transparent ? killing_hook : NULL;
            target.user_data = &k;
            char want[256];
            snprintf(want, sizeof want, "splatfx_renderer_render: the %s hook destroyed %s while it was being drawn",
                     transparent ? "draw_transparent" : "draw_opaque", names[kill - KILL_FRAME]);
            if (kill == KILL_FRAME) {
                /* The renderer's stats show the frame was drawn in full after its destroy. */
                CHECK_FAILS(splatfx_renderer_render(d.r, d.m, d.frame, &target, err), err, SPLATFX_ERROR_INVALID_STATE, want);
                splatfx_render_stats rs;
                CHECK_OK(splatfx_renderer_get_stats(d.r, &rs, err), err);
                CHECK(rs.splats == d.splats && rs.draw_calls > 0, "the frame destroyed by a hook was not drawn in full: %llu of %llu splats",
                      (unsigned long long)rs.splats, (unsigned long long)d.splats);
                splatfx_frame_stats fs;
                CHECK_FAILS(splatfx_frame_get_stats(d.frame, &fs, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                            "frame is not a splatfx_frame (it was destroyed");
            } else if (kill == KILL_MATERIALS) {
                CHECK_FAILS(splatfx_renderer_render(d.r, d.m, d.frame, &target, err), err, SPLATFX_ERROR_INVALID_STATE, want);
                CHECK(splatfx_materials_layer_count(d.m) == 0, "materials destroyed by a hook are still there");
            } else {
                CHECK_FAILS(splatfx_renderer_render(d.r, d.m, d.frame, &target, err), err, SPLATFX_ERROR_INVALID_STATE, want);
                splatfx_render_stats rs;
                CHECK_FAILS(splatfx_renderer_get_stats(d.r, &rs, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                            "renderer is not a splatfx_renderer (it was destroyed");
            }
            free_drawn(&d);
        }
    target.draw_transparent = NULL;
    target.draw_opaque = killing_hook;

    /* The scene: the frame holds its splats, so the render is unaffected. */
    {
        Drawn d = make_drawn(err);
        Killer k = {KILL_SCENE, &d, NULL, NULL, NULL, SPLATFX_OK, SPLATFX_OK, SPLATFX_OK, {{0}}};
        target.user_data = &k;
        CHECK_OK(splatfx_renderer_render(d.r, d.m, d.frame, &target, err), err);
        CHECK(splatfx_scene_effect_count(d.scene) == 0, "a scene destroyed by a hook is still there");
        free_drawn(&d);
    }
    /* The render's own error object: the status still comes back; the object is gone after. */
    {
        Drawn d = make_drawn(err);
        splatfx_error* own = splatfx_error_create();
        Killer k = {KILL_ERROR, &d, own, NULL, NULL, SPLATFX_OK, SPLATFX_OK, SPLATFX_OK, {{0}}};
        target.user_data = &k;
        const splatfx_status s = splatfx_renderer_render(d.r, d.m, d.frame, &target, own);
        CHECK(s == SPLATFX_ERROR_INVALID_STATE, "a hook destroying the render's error object: %s", splatfx_status_name(s));
        CHECK(splatfx_error_status(own) == SPLATFX_ERROR_INVALID_ARGUMENT, "the error object destroyed by a hook is still there");
        free_drawn(&d);
    }
    /* Calls back into the render from its hook. */
    {
        Drawn d = make_drawn(err);
        Killer k = {REENTER, &d, NULL, NULL, &target, SPLATFX_OK, SPLATFX_OK, SPLATFX_OK, {{0}}};
        target.user_data = &k;
        CHECK_OK(splatfx_renderer_render(d.r, d.m, d.frame, &target, err), err);
        CHECK(k.nested_render == SPLATFX_ERROR_INVALID_STATE &&
                  strstr(k.nested_message[0], "renderer is drawing a frame (this call came from one of its hooks)"),
              "render from its own hook: %s: %s", splatfx_status_name(k.nested_render), k.nested_message[0]);
        CHECK(k.nested_prepare == SPLATFX_ERROR_INVALID_STATE &&
                  strstr(k.nested_message[1], "frame is being drawn by the render that called this hook"),
              "prepare of the frame being drawn: %s: %s", splatfx_status_name(k.nested_prepare), k.nested_message[1]);
        CHECK(k.nested_upload == SPLATFX_ERROR_INVALID_STATE && strstr(k.nested_message[2], "renderer is drawing a frame"),
              "upload from its own hook: %s: %s", splatfx_status_name(k.nested_upload), k.nested_message[2]);
        splatfx_render_stats rs;
        CHECK_OK(splatfx_renderer_get_stats(d.r, &rs, err), err);
        CHECK(rs.splats == d.splats, "the outer render drew %llu of %llu splats", (unsigned long long)rs.splats, (unsigned long long)d.splats);
        free_drawn(&d);
    }
    CHECK(glGetError() == GL_NO_ERROR, "a GL error was raised");
    glDeleteFramebuffers(1, &t.fbo);
    glDeleteTextures(1, &t.color);
    glDeleteTextures(1, &t.depth);
}

/* A hook that destroys the headless context being drawn in (and its renderer): both deferred, the
 * renderer deleted first while its context is still current. Another context (`main_ctx`) made
 * before is unaffected by that one's destruction. */
static void test_hook_destroys_its_context(splatfx_error* err, splatfx_headless_context* main_ctx) {
    splatfx_headless_context* ctx = NULL;
    CHECK_OK(splatfx_headless_context_create(&ctx, err), err); /* current now */
    Drawn d = make_drawn(err);
    Target t = make_clear_target();
    splatfx_host_target target;
    splatfx_host_target_init(&target);
    target.framebuffer = t.fbo;
    target.depth_texture = t.depth;
    Killer k = {KILL_CONTEXT, &d, NULL, ctx, NULL, SPLATFX_OK, SPLATFX_OK, SPLATFX_OK, {{0}}};
    target.draw_opaque = killing_hook;
    target.user_data = &k;
    CHECK_FAILS(splatfx_renderer_render(d.r, d.m, d.frame, &target, err), err, SPLATFX_ERROR_INVALID_STATE,
                "the draw_opaque hook destroyed renderer (a splatfx_renderer) while it was being drawn");
    CHECK(splatfx_headless_context_renderer(ctx) == NULL, "the context destroyed by a hook is still there");
    /* Its framebuffer and textures went with it. */
    CHECK_OK(splatfx_headless_context_make_current(main_ctx, err), err);
    CHECK(glGetError() == GL_NO_ERROR, "the first context was disturbed by the second's destruction");
    splatfx_render_stats rs;
    CHECK_FAILS(splatfx_renderer_get_stats(d.r, &rs, err), err, SPLATFX_ERROR_INVALID_ARGUMENT, "it was destroyed");
    free_drawn(&d);
}

static void switch_context(void* user) { splatfx_headless_context_make_current((splatfx_headless_context*)user, NULL); }

/* A renderer used while another context is current: SPLATFX_ERROR_GL, no GL call in that context;
 * destroyed there, it deletes nothing of that context (the same names are that context's objects). */
static void test_wrong_context(splatfx_error* err, splatfx_headless_context* main_ctx) {
    Drawn d = make_drawn(err); /* in main_ctx */
    splatfx_headless_context* other = NULL;
    CHECK_OK(splatfx_headless_context_create(&other, err), err); /* current now */
    Target t = make_clear_target();
    splatfx_host_target target;
    splatfx_host_target_init(&target);
    target.framebuffer = t.fbo;
    target.depth_texture = t.depth;
    /* Objects of this context whose names the renderer's objects also have in its own. */
    GLuint textures[64], buffers[64];
    glCreateTextures(GL_TEXTURE_2D, 64, textures);
    glCreateBuffers(64, buffers);
    glEnable(0x7fff); /* a GL error the host left pending (GL_INVALID_ENUM): not blamed on the renderer */
    CHECK_FAILS(splatfx_renderer_render(d.r, d.m, d.frame, &target, err), err, SPLATFX_ERROR_GL,
                "splatfx_renderer_render: splatfx::gl::FrameRenderer: the OpenGL context current on this thread is not the one it was created in");
    CHECK_FAILS(splatfx_renderer_upload(d.r, d.m, err), err, SPLATFX_ERROR_GL, "is not the one it was created in");
    CHECK(glGetError() == GL_INVALID_ENUM, "the host's own pending error was consumed by a refused call");
    CHECK(glGetError() == GL_NO_ERROR, "a refused render raised a GL error in the other context");
    /* Back in its own context, a hook that makes the other one current: the frame ends after it. */
    CHECK_OK(splatfx_headless_context_make_current(main_ctx, err), err);
    {
        Target own = make_clear_target();
        splatfx_host_target in_own;
        splatfx_host_target_init(&in_own);
        in_own.framebuffer = own.fbo;
        in_own.depth_texture = own.depth;
        in_own.draw_opaque = switch_context;
        in_own.user_data = other;
        CHECK_FAILS(splatfx_renderer_render(d.r, d.m, d.frame, &in_own, err), err, SPLATFX_ERROR_GL,
                    "the draw_opaque hook left another OpenGL context current (or none); the rest of the frame was not drawn");
        const uint32_t n = splatfx_renderer_note_count(d.r);
        const char* last = n ? splatfx_renderer_note(d.r, n - 1) : NULL;
        CHECK(last && strstr(last, "frame cut short after the host's opaque hook"), "the renderer's last note: %s", last ? last : "(none)");
        CHECK(glGetError() == GL_NO_ERROR, "the cut-short render raised a GL error in the other context");
        CHECK_OK(splatfx_headless_context_make_current(main_ctx, err), err);
        glDeleteFramebuffers(1, &own.fbo);
        glDeleteTextures(1, &own.color);
        glDeleteTextures(1, &own.depth);
        CHECK(glGetError() == GL_NO_ERROR, "the cut-short render left a GL error in its own context");
        CHECK_OK(splatfx_headless_context_make_current(other, err), err);
    }
    splatfx_renderer_destroy(d.r); /* here: its GL objects are left to its own context */
    int kept = 1;
    for (int i = 0; i < 64; ++i) kept = kept && glIsTexture(textures[i]) && glIsBuffer(buffers[i]);
    CHECK(kept, "destroying a renderer in another context deleted that context's objects");
    glDeleteTextures(64, textures);
    glDeleteBuffers(64, buffers);
    glDeleteFramebuffers(1, &t.fbo);
    glDeleteTextures(1, &t.color);
    glDeleteTextures(1, &t.depth);
    /* The other context destroyed while main_ctx is current: main_ctx stays current and usable. */
    CHECK_OK(splatfx_headless_context_make_current(main_ctx, err), err);
    splatfx_headless_context_destroy(other);
    splatfx_headless_context_destroy(other); /* twice: ignored */
    splatfx_renderer* r = NULL;
    CHECK_OK(splatfx_renderer_create(NULL, &r, err), err);
    splatfx_renderer_destroy(r);
    splatfx_renderer_destroy(r); /* twice: ignored */
    free_drawn(&d);
}

static void make_gl_error(void* user) {
    (void)user;
    glEnable(0x7fff); /* GL_INVALID_ENUM */
}

/* GL errors during a render: the host's pending ones are dropped (not splatfx's), the hooks' are
 * named as the host's, splatfx's own (here: an incomplete target framebuffer) are SPLATFX_ERROR_GL. */
static void test_gl_errors(splatfx_error* err) {
    Drawn d = make_drawn(err);
    Target t = make_clear_target();
    splatfx_host_target target;
    splatfx_host_target_init(&target);
    target.framebuffer = t.fbo;
    target.depth_texture = t.depth;
    glEnable(0x7fff);
    CHECK_OK(splatfx_renderer_render(d.r, d.m, d.frame, &target, err), err);
    CHECK(glGetError() == GL_NO_ERROR, "an error left after a render");
    target.draw_opaque = make_gl_error;
    CHECK_FAILS(splatfx_renderer_render(d.r, d.m, d.frame, &target, err), err, SPLATFX_ERROR_GL,
                "splatfx_renderer_render: the draw_opaque hook raised GL_INVALID_ENUM (the host's own GL calls; splatfx's raised none and the frame "
                "was drawn)");
    splatfx_render_stats rs;
    CHECK_OK(splatfx_renderer_get_stats(d.r, &rs, err), err);
    CHECK(rs.splats == d.splats, "a hook's error stopped the frame: %llu of %llu splats", (unsigned long long)rs.splats,
          (unsigned long long)d.splats);
    target.draw_opaque = NULL;
    GLuint empty = 0;
    glCreateFramebuffers(1, &empty); /* exists, no attachment: incomplete */
    target.framebuffer = empty;
    target.depth_texture = 0;
    char want[256];
    snprintf(want, sizeof want,
             "GL_INVALID_FRAMEBUFFER_OPERATION raised by splatfx's own GL calls during the render (target->framebuffer %u is incomplete: "
             "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT)",
             empty);
    CHECK_FAILS(splatfx_renderer_render(d.r, d.m, d.frame, &target, err), err, SPLATFX_ERROR_GL, want);
    CHECK(glGetError() == GL_NO_ERROR, "an error left after a render");
    glDeleteFramebuffers(1, &empty);
    glDeleteFramebuffers(1, &t.fbo);
    glDeleteTextures(1, &t.color);
    glDeleteTextures(1, &t.depth);
    free_drawn(&d);
}

/* The frame's notes: none on a single-sampled or a multisampled (4x, read per sample) depth texture; a
   context whose glClipControl disagrees with the camera's depth convention is one, and the renderer says so. */
static void test_notes(splatfx_error* err) {
    Drawn d = make_drawn(err);
    Target t = make_clear_target();
    splatfx_host_target target;
    splatfx_host_target_init(&target);
    target.framebuffer = t.fbo;
    target.depth_texture = t.depth;
    CHECK_OK(splatfx_renderer_render(d.r, d.m, d.frame, &target, err), err);
    CHECK(splatfx_renderer_note_count(d.r) == 0, "a single-sampled depth texture gave %u notes, the first: %s", splatfx_renderer_note_count(d.r),
          splatfx_renderer_note(d.r, 0));
    CHECK(splatfx_renderer_note(d.r, 0) == NULL, "note 0 of none");
    GLuint ms_color = 0, ms_depth = 0, ms_fbo = 0;
    glCreateTextures(GL_TEXTURE_2D_MULTISAMPLE, 1, &ms_color);
    glTextureStorage2DMultisample(ms_color, 4, GL_RGBA8, W, H, GL_TRUE);
    glCreateTextures(GL_TEXTURE_2D_MULTISAMPLE, 1, &ms_depth);
    glTextureStorage2DMultisample(ms_depth, 4, GL_DEPTH_COMPONENT32F, W, H, GL_TRUE);
    glCreateFramebuffers(1, &ms_fbo);
    glNamedFramebufferTexture(ms_fbo, GL_COLOR_ATTACHMENT0, ms_color, 0);
    glNamedFramebufferTexture(ms_fbo, GL_DEPTH_ATTACHMENT, ms_depth, 0);
    CHECK(glCheckNamedFramebufferStatus(ms_fbo, GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE, "incomplete multisampled framebuffer");
    const float far_depth = 1.0f;
    glClearNamedFramebufferfv(ms_fbo, GL_DEPTH, 0, &far_depth);
    target.framebuffer = ms_fbo;
    target.depth_texture = ms_depth;
    CHECK_OK(splatfx_renderer_render(d.r, d.m, d.frame, &target, err), err);
    CHECK(splatfx_renderer_note_count(d.r) == 0, "a multisampled depth texture gave %u notes, the first: %s", splatfx_renderer_note_count(d.r),
          splatfx_renderer_note(d.r, 0));
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    CHECK_OK(splatfx_renderer_render(d.r, d.m, d.frame, &target, err), err);
    glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    CHECK(splatfx_renderer_note_count(d.r) == 1, "a context whose clip depth is not the camera's gave %u notes", splatfx_renderer_note_count(d.r));
    const char* note = splatfx_renderer_note(d.r, 0);
    CHECK(note && strstr(note, "GL_ZERO_TO_ONE"), "note: %s", note ? note : "(NULL)");
    CHECK(splatfx_renderer_note(d.r, 1) == NULL, "note 1 of 1");
    printf("clip depth mismatch: %s\n", note ? note : "(no note)");
    CHECK(splatfx_renderer_note_count(NULL) == 0 && splatfx_renderer_note(NULL, 0) == NULL, "notes of NULL");
    CHECK(splatfx_renderer_note_count((const splatfx_renderer*)d.frame) == 0, "notes of a frame");
    CHECK(glGetError() == GL_NO_ERROR, "a GL error was raised");
    glDeleteFramebuffers(1, &ms_fbo);
    glDeleteTextures(1, &ms_color);
    glDeleteTextures(1, &ms_depth);
    glDeleteFramebuffers(1, &t.fbo);
    glDeleteTextures(1, &t.color);
    glDeleteTextures(1, &t.depth);
    free_drawn(&d);
}

/* ---- HDR lit colour into the host's float target ---------------------------------------------- */

/* A scene file for the HDR test: a 3x3x3 sphere of plain splats (no texture, no dynamics) of colour
 * (0.8, 0.7, 0.6), lit by one white sun of `intensity`, traced self-shadow, isotropic, no ambient or
 * emission, no scene-shadow table. The lit colour is then linear in the intensity. */
static void write_hdr_scene(const char* path, double intensity) {
    FILE* f = fopen(path, "w");
    CHECK(f != NULL, "cannot write %s", path);
    if (!f) return;
    fprintf(f, "{\"format\": \"splatfx-scene\", \"version\": 1, \"seed\": 3,\n"
               " \"lights\": [{\"type\": \"directional\", \"direction\": [0.6, -0.7, -0.4], \"color\": [1, 1, 1], \"intensity\": %.17g}],\n"
               " \"sceneShadow\": {\"enabled\": false},\n"
               " \"effects\": [{\"kind\": \"grid\", \"name\": \"blob\", \"dims\": [3, 3, 3], \"spacing\": 0.25, \"traditional\": true,\n"
               "   \"shapes\": [{\"type\": \"sphere\", \"center\": [1, 1, 1], \"radius\": 1.5}], \"opacity\": 0.7,\n"
               "   \"colorTable\": {\"constant\": [0.8, 0.7, 0.6, 1]}, \"propagation\": {\"mode\": \"none\"}, \"cycling\": {\"mode\": \"none\"},\n"
               "   \"lighting\": {\"albedo\": 0.9, \"selfShadow\": \"traced\"}}]}\n",
            intensity);
    fclose(f);
}

/* A colour target of `format` (GL_RGBA8, GL_RGBA16F, GL_RGBA32F) with a depth texture, cleared to 0 and depth 1. */
static Target make_colour_target(GLenum format) {
    Target t;
    glCreateTextures(GL_TEXTURE_2D, 1, &t.color);
    glTextureStorage2D(t.color, 1, format, W, H);
    glCreateTextures(GL_TEXTURE_2D, 1, &t.depth);
    glTextureStorage2D(t.depth, 1, GL_DEPTH_COMPONENT32F, W, H);
    glCreateFramebuffers(1, &t.fbo);
    glNamedFramebufferTexture(t.fbo, GL_COLOR_ATTACHMENT0, t.color, 0);
    glNamedFramebufferTexture(t.fbo, GL_DEPTH_ATTACHMENT, t.depth, 0);
    CHECK(glCheckNamedFramebufferStatus(t.fbo, GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE, "incomplete framebuffer");
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f}, far_depth = 1.0f;
    glClearNamedFramebufferfv(t.fbo, GL_COLOR, 0, zero);
    glClearNamedFramebufferfv(t.fbo, GL_DEPTH, 0, &far_depth);
    return t;
}

static void free_target(Target* t) {
    glDeleteFramebuffers(1, &t->fbo);
    glDeleteTextures(1, &t->color);
    glDeleteTextures(1, &t->depth);
}

/* The scene at `intensity`, HDR lit colour on or off, prepared and drawn into a new target of
 * `format`; its pixels as floats into `out` (W x H x 4). Returns the frame's splat count. */
static uint64_t draw_hdr_scene(splatfx_error* err, double intensity, int hdr, GLenum format, float* out) {
    const char* path = "capi_hdr_scene.json";
    write_hdr_scene(path, intensity);
    splatfx_materials* m = NULL;
    splatfx_scene* scene = NULL;
    splatfx_frame* frame = NULL;
    splatfx_renderer* r = NULL;
    CHECK_OK(splatfx_materials_create(NULL, &m, err), err);
    CHECK_OK(splatfx_scene_load_file(path, m, NULL, &scene, err), err);
    CHECK_OK(splatfx_scene_set_hdr_lit(scene, hdr, err), err);
    CHECK_OK(splatfx_frame_create(&frame, err), err);
    CHECK_OK(splatfx_renderer_create(NULL, &r, err), err);
    /* The lattice is centred on x and z and starts at y = 0: its centre is (0, 0.25, 0). */
    const float eye[3] = {0.9f, 0.75f, 2.4f}, at[3] = {0.0f, 0.25f, 0.0f}, up[3] = {0.0f, 1.0f, 0.0f};
    splatfx_camera cam;
    CHECK_OK(splatfx_camera_look_at(eye, at, up, 0.55f, W, H, 0.1f, 20.0f, &cam, err), err);
    CHECK_OK(splatfx_scene_prepare(scene, 0.0, &cam, m, frame, err), err);
    splatfx_frame_stats fs;
    CHECK_OK(splatfx_frame_get_stats(frame, &fs, err), err);
    Target t = make_colour_target(format);
    splatfx_host_target target;
    splatfx_host_target_init(&target);
    target.framebuffer = t.fbo;
    target.depth_texture = t.depth;
    CHECK_OK(splatfx_renderer_render(r, m, frame, &target, err), err);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, t.fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_FLOAT, out);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    free_target(&t);
    splatfx_renderer_destroy(r);
    splatfx_frame_destroy(frame);
    splatfx_scene_destroy(scene);
    splatfx_materials_destroy(m);
    return fs.splats;
}

static float max_rgb(const float* img) {
    float v = 0.0f;
    for (int i = 0; i < W * H * 4; ++i)
        if (i % 4 != 3 && img[i] > v) v = img[i];
    return v;
}

/* max over pixels and colour channels of |a - k b|; the alpha channel's largest |a - b| into *alpha_diff. */
static double max_diff_rgb(const float* a, const float* b, double k, double* alpha_diff) {
    double worst = 0.0, worst_alpha = 0.0;
    for (int i = 0; i < W * H * 4; ++i) {
        const double e = i % 4 == 3 ? fabs((double)a[i] - b[i]) : fabs((double)a[i] - k * b[i]);
        if (i % 4 == 3) worst_alpha = e > worst_alpha ? e : worst_alpha;
        else worst = e > worst ? e : worst;
    }
    if (alpha_diff) *alpha_diff = worst_alpha;
    return worst;
}

/* A lit colour above 1 reaches the host's float target through the C API: a scene file's gas under a
 * sun of 1 (every lit colour <= 1) and of 6, HDR lit colour on; the frame at 6 is 6x the frame at 1
 * up to each path's 8-bit colour rounding (the model is linear in the intensity, the alphas do not
 * depend on it). Without HDR the frame at 6 stops at 1 and fails that. An HDR frame into an 8-bit
 * target is refused, drawing nothing. */
static void test_hdr_lit(splatfx_error* err) {
    float* lo = malloc(sizeof(float) * W * H * 4);
    float* lo_ldr = malloc(sizeof(float) * W * H * 4);
    float* hi = malloc(sizeof(float) * W * H * 4);
    float* hi_half = malloc(sizeof(float) * W * H * 4);
    float* hi_ldr = malloc(sizeof(float) * W * H * 4);
    CHECK(lo && lo_ldr && hi && hi_half && hi_ldr, "out of memory");
    if (!lo || !lo_ldr || !hi || !hi_half || !hi_ldr) goto done;
    const uint64_t n = draw_hdr_scene(err, 1.0, 1, GL_RGBA32F, lo);
    CHECK(n > 0 && n <= 27, "splats %llu, expected 1..27 (one at most per voxel)", (unsigned long long)n);
    draw_hdr_scene(err, 1.0, 0, GL_RGBA32F, lo_ldr);
    draw_hdr_scene(err, 6.0, 1, GL_RGBA32F, hi);
    draw_hdr_scene(err, 6.0, 1, GL_RGBA16F, hi_half);
    draw_hdr_scene(err, 6.0, 0, GL_RGBA32F, hi_ldr);

    /* Colours <= 1 are packed bit for bit the same with HDR on or off: equal frames at 1 say every
     * lit colour there is <= 1, so at 6 every one is <= 6 (its brightest channel m <= 6). */
    CHECK(memcmp(lo, lo_ldr, sizeof(float) * W * H * 4) == 0, "at intensity 1 the HDR frame differs from the 8-bit one: a lit colour above 1");
    float alpha = 0.0f;
    for (int i = 3; i < W * H * 4; i += 4) alpha = lo[i] > alpha ? lo[i] : alpha;
    CHECK(alpha > 0.1f, "the gas is not in view (largest alpha %g)", alpha);
    /* GL at 6 against 6 x GL at 1, both RGBA32F, with a clear of 0: each pixel is sum_i w_i c_i with
     * the same weights (sum <= the pixel's alpha <= the largest alpha A), so they differ by at most A
     * times the largest difference of a splat's colour: 6 x the in-range colour's rounding (half an
     * 8-bit level, 6 x 0.5/255) plus the HDR chroma's (half a level of its brightest channel,
     * m x 0.5/255 <= 6 x 0.5/255); plus RGBA32F's rounding at each of its n + 1 writes (2^-24 of a
     * value <= 6, at 7x: 7 (n + 1) x 2^-24 x 6 < 1e-5 for n <= 27). The alphas are the same
     * computation on the same inputs: equal to F32's rounding (n + 1) x 2^-24. */
    double alpha_diff = 0.0;
    const double bound = alpha * (6.0 + 6.0) * 0.5 / 255.0 + 1e-5;
    const double e = max_diff_rgb(hi, lo, 6.0, &alpha_diff);
    CHECK(e <= bound, "|GL(6) - 6 GL(1)| = %g, over its bound %g", e, bound);
    CHECK(alpha_diff <= (double)(n + 1) * ldexp(1.0, -24), "the alphas at 6 and 1 differ by %g", alpha_diff);
    /* The frame at 6 keeps values above 1: the peak at 1 times 6, within the bound. */
    const float peak_lo = max_rgb(lo), peak = max_rgb(hi);
    CHECK(6.0 * peak_lo - bound > 1.5, "the peak at 1 is %g: too dim for this test to show values above 1", peak_lo);
    CHECK(peak > 1.5f, "the HDR frame's peak is %g; a lit colour above 1 did not reach the float target", peak);
    /* RGBA16F, the usual HDR target: the same frame but for the half float's rounding, half an ulp
     * (2^-11) of a value <= 6 at each of its n + 1 writes, each carried on scaled by <= 1. */
    const double half_bound = (double)(n + 1) * ldexp(1.0, -11) * 6.0;
    const double e_half = max_diff_rgb(hi_half, hi, 1.0, NULL);
    CHECK(e_half <= half_bound, "RGBA16F against RGBA32F: %g, over %g", e_half, half_bound);
    CHECK(max_rgb(hi_half) > 1.5f, "the RGBA16F frame's peak is %g", max_rgb(hi_half));
    /* Without HDR the frame at 6 stops at 1 (an over blend of colours <= 1 onto 0) and misses 6 x the
     * frame at 1 by far more than the bound: dropping the switch fails this test. */
    const double e_ldr = max_diff_rgb(hi_ldr, lo, 6.0, NULL);
    CHECK(max_rgb(hi_ldr) <= 1.0f + 1e-5f, "without HDR the peak is %g", max_rgb(hi_ldr));
    CHECK(e_ldr > 4.0 * bound, "without HDR the frame at 6 is within %g of 6x the frame at 1 (bound %g)", e_ldr, bound);
    printf("HDR lit colour: peak %.3f (6 x the peak at 1: %.3f; RGBA16F %.3f; without HDR %.3f); |GL(6) - 6 GL(1)| %.5f (bound %.5f), "
           "without HDR %.3f; RGBA16F - RGBA32F %.5f (bound %.5f)\n",
           peak, 6.0 * peak_lo, max_rgb(hi_half), max_rgb(hi_ldr), e, bound, e_ldr, e_half, half_bound);

    /* An HDR frame into an 8-bit target: refused before drawing (the target keeps its clear colour). */
    {
        splatfx_materials* m = NULL;
        splatfx_scene* scene = NULL;
        splatfx_frame* frame = NULL;
        splatfx_renderer* r = NULL;
        write_hdr_scene("capi_hdr_scene.json", 6.0);
        CHECK_OK(splatfx_materials_create(NULL, &m, err), err);
        CHECK_OK(splatfx_scene_load_file("capi_hdr_scene.json", m, NULL, &scene, err), err);
        CHECK_OK(splatfx_scene_set_hdr_lit(scene, 1, err), err);
        CHECK_OK(splatfx_frame_create(&frame, err), err);
        CHECK_OK(splatfx_renderer_create(NULL, &r, err), err);
        const float eye[3] = {0.9f, 0.75f, 2.4f}, at[3] = {0.0f, 0.25f, 0.0f}, up[3] = {0.0f, 1.0f, 0.0f};
        splatfx_camera cam;
        CHECK_OK(splatfx_camera_look_at(eye, at, up, 0.55f, W, H, 0.1f, 20.0f, &cam, err), err);
        CHECK_OK(splatfx_scene_prepare(scene, 0.0, &cam, m, frame, err), err);
        Target t = make_colour_target(GL_RGBA8);
        splatfx_host_target target;
        splatfx_host_target_init(&target);
        target.framebuffer = t.fbo;
        target.depth_texture = t.depth;
        CHECK_FAILS(splatfx_renderer_render(r, m, frame, &target, err), err, SPLATFX_ERROR_INVALID_ARGUMENT,
                    "GL_COLOR_ATTACHMENT0 is fixed-point (GL_UNSIGNED_NORMALIZED)");
        printf("HDR frame into RGBA8: %s\n", splatfx_error_message(err));
        unsigned char* px = malloc((size_t)W * H * 4);
        if (px) {
            read_pixels(&t, px);
            int drawn = 0;
            for (int i = 0; i < W * H * 4; ++i) drawn += px[i] != 0;
            CHECK(drawn == 0, "the refused render drew %d channel values", drawn);
            free(px);
        }
        /* The same frame into a float target draws. */
        free_target(&t);
        t = make_colour_target(GL_RGBA16F);
        target.framebuffer = t.fbo;
        target.depth_texture = t.depth;
        CHECK_OK(splatfx_renderer_render(r, m, frame, &target, err), err);
        CHECK(glGetError() == GL_NO_ERROR, "a GL error was raised");
        free_target(&t);
        splatfx_renderer_destroy(r);
        splatfx_frame_destroy(frame);
        splatfx_scene_destroy(scene);
        splatfx_materials_destroy(m);
    }
done:
    free(lo);
    free(lo_ldr);
    free(hi);
    free(hi_half);
    free(hi_ldr);
}

int main(void) {
    splatfx_error* err = splatfx_error_create();
    splatfx_headless_context* ctx = NULL;
    if (splatfx_headless_context_create(&ctx, err) != SPLATFX_OK) {
        fprintf(stderr, "capi_gl_test: headless OpenGL 4.5 is required: %s\n", splatfx_error_message(err));
        splatfx_error_destroy(err);
        return 1;
    }
    printf("capi_gl_test: %s\n", splatfx_headless_context_renderer(ctx));
    CHECK_OK(splatfx_headless_context_make_current(ctx, err), err);
    test_fire_against_host_depth(err, 1);
    test_fire_against_host_depth(err, 2);
    test_render_errors(err);
    test_hooks_that_destroy(err);
    test_wrong_context(err, ctx);
    test_gl_errors(err);
    test_notes(err);
    test_hdr_lit(err);
    test_hook_destroys_its_context(err, ctx);
    CHECK(glGetError() == GL_NO_ERROR, "a GL error was raised");
    /* A renderer outliving its context: destroying it then must not abort in the GL loader, and
     * GL calls through the API are refused with a message. */
    splatfx_renderer* orphan = NULL;
    splatfx_materials* m = NULL;
    CHECK_OK(splatfx_renderer_create(NULL, &orphan, err), err);
    CHECK_OK(splatfx_materials_create(NULL, &m, err), err);
    splatfx_headless_context_destroy(ctx);
    CHECK_FAILS(splatfx_renderer_upload(orphan, m, err), err, SPLATFX_ERROR_GL, "no OpenGL context is current");
    splatfx_renderer_destroy(orphan);
    splatfx_materials_destroy(m);
    splatfx_error_destroy(err);
    if (g_failures) {
        fprintf(stderr, "capi_gl_test: %d check(s) failed\n", g_failures);
        return 1;
    }
    printf("capi_gl_test: all checks passed\n");
    return 0;
}
