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
