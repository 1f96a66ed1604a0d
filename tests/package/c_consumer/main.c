/* A C program against an installed splatfx: a fire in a scene, prepared for a camera made from
 * host matrices (here, look_at's), with no GL and no C++ on its side. */
#include <math.h>
#include <stdio.h>

#include <splatfx/splatfx_c.h>

int main(void) {
    splatfx_error* err = splatfx_error_create();
    splatfx_materials* materials = NULL;
    splatfx_scene* scene = NULL;
    splatfx_frame* frame = NULL;
    splatfx_camera look, camera;
    splatfx_frame_stats stats;
    const float eye[3] = {0.0f, 5.0f, 20.0f}, target[3] = {0.0f, 5.0f, 0.0f}, up[3] = {0.0f, 1.0f, 0.0f};
    if (splatfx_materials_create(NULL, &materials, err) || splatfx_scene_create(&scene, err) || splatfx_frame_create(&frame, err) ||
        splatfx_scene_add_fire(scene, materials, NULL, NULL, NULL, err) ||
        splatfx_camera_look_at(eye, target, up, 0.8f, 64, 64, 0.1f, 100.0f, &look, err) ||
        splatfx_camera_from_matrices(look.view, look.proj, 64, 64, &camera, err) ||
        splatfx_scene_prepare(scene, 0.5, &camera, materials, frame, err) || splatfx_frame_get_stats(frame, &stats, err)) {
        fprintf(stderr, "c consumer: %s\n", splatfx_error_message(err));
        return 1;
    }
    if (stats.splats == 0) return fprintf(stderr, "c consumer: the fire has no splats\n"), 1;
    /* An error path through the installed library: a message, not a crash. */
    if (splatfx_scene_prepare(scene, NAN, &camera, materials, frame, err) != SPLATFX_ERROR_INVALID_ARGUMENT)
        return fprintf(stderr, "c consumer: a NaN time was accepted\n"), 1;
    printf("c consumer: %llu splats; NaN time: %s\nconsumer: ok\n", (unsigned long long)stats.splats, splatfx_error_message(err));
    splatfx_frame_destroy(frame);
    splatfx_scene_destroy(scene);
    splatfx_materials_destroy(materials);
    splatfx_error_destroy(err);
    return 0;
}
